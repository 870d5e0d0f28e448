//! Why each locked core is locked (format 1.9): the overlapping pairs inside it, which of its
//! parts block which along how many candidate directions, whether the grid planner tried it, and
//! what `--overlaps lenient` would free ([`CoreWhy`], `locked_cores[].why` in the plan JSON).

use super::{CoreGridReason, LenientStatus};
use crate::problem::{PlanOutcome, Status, Step};
use asp_geom::overlap::OverlapHandling;
use asp_geom::{PartSet, World};
use serde::{Deserialize, Serialize};

/// Overlaps deeper than this fraction of the model's diagonal are modelling artefacts, not fits:
/// 0.5 % (50 default tolerances; 2.5 mm on a 500 mm stool, 1.3 mm on a 260 mm pump). A press or
/// shrink fit interferes by a few thousandths of the fitted diameter, which is at most the
/// model's size; two panels drawn into each other, a dowel in a board with no hole, overlap far
/// more.
pub const ARTEFACT_RELATIVE_DEPTH: f64 = 5e-3;

/// Why a locked core is locked (format 1.9).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreWhy {
    /// The pairs of the core that overlap in the input beyond the tolerance (from the plan's
    /// `overlaps`), each judged against `artefact_depth`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overlaps: Vec<CoreOverlap>,
    /// The depth (model units) beyond which an overlap is a modelling artefact, not a fit:
    /// [`ARTEFACT_RELATIVE_DEPTH`] of the model's diagonal.
    pub artefact_depth: f64,
    /// The candidate removal directions of the model (each part's counts below are out of these).
    pub directions: usize,
    /// Each part of the core but its base: along how many directions it is free of the core's
    /// other parts, and which of them block it along how many (straight lines from the assembled
    /// pose, among the core's parts only, as its own plan on its base tests them).
    pub blocks: Vec<CoreBlocks>,
    /// Whether the grid planner was tried, and why not.
    pub grid: CoreGrid,
    /// What the core's own plan gives under `--overlaps lenient`.
    pub lenient: CoreLenient,
}

/// A pair of parts of a core that overlap in the input.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreOverlap {
    /// The two part indices (low, high).
    pub parts: [usize; 2],
    /// Their names.
    pub names: [String; 2],
    /// The measured depth in model units (as the top-level `overlaps`).
    pub depth: f64,
    /// `depth` is a lower bound (as the top-level `overlaps`). Only when true.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub depth_bound: bool,
    /// No shrinking of either part up to 40 % of its thickness separates them.
    pub gross: bool,
    /// What the pair is by the shape of its overlap (as the top-level `overlaps`). Since 1.13.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class: Option<asp_geom::overlap::OverlapClass>,
    /// A modelling artefact, not an interlock or a fit: `gross`, or deeper than
    /// `artefact_depth`.
    pub artefact: bool,
}

/// What holds one part of a core.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreBlocks {
    /// The part index.
    pub part: usize,
    /// Its name.
    pub name: String,
    /// Candidate directions along which no other part of the core blocks it (when more than 0,
    /// the core's `explanation` says what else keeps it: support, or a dead end after it).
    pub free: usize,
    /// The parts of the core that block it, most directions first.
    pub by: Vec<CoreBlocker>,
}

/// A part of a core that blocks another.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreBlocker {
    /// The blocking part's index.
    pub part: usize,
    /// Its name.
    pub name: String,
    /// Candidate directions along which it blocks the part.
    pub directions: usize,
    /// Of those, the directions along which it is the part's only blocker in the core.
    pub only: usize,
}

/// Whether the grid planner was tried on a core.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreGrid {
    /// Whether the grid planner ran on the model (and so on the core).
    pub tried: bool,
    /// Why it did not take the core apart, or why it was not tried.
    pub reason: CoreGridReason,
    /// When not tried because of the model (`not_on_grid`, `too_many_parts`): whether the
    /// core's own parts are unions of cells of one common grid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core_on_grid: Option<bool>,
}

/// What `--overlaps lenient` would do to a core: its own plan on its base, rerun with the
/// lenient policy (the same planner, ordering, seed and directions).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoreLenient {
    /// How the rerun ended, or `unchanged` when it was not needed.
    pub status: LenientStatus,
    /// Parts of the core (its base not counted) that the rerun gives their own motion.
    pub frees: usize,
}

impl CoreLenient {
    /// The lenient rerun of a core of `parts` parts (its base among them) that ended in `plan`.
    pub fn of(plan: &PlanOutcome, parts: usize) -> CoreLenient {
        let frees = own_motions(&plan.removals).min(parts.saturating_sub(1));
        let status = match plan.status {
            Status::Found if frees + 1 >= parts => LenientStatus::Found,
            Status::Found => LenientStatus::Partial,
            Status::NoPlan { .. } => LenientStatus::NoPlan,
            Status::BudgetExhausted => LenientStatus::BudgetExhausted,
        };
        CoreLenient { status, frees }
    }
}

/// The parts that `removals` give a motion of their own: each single part, and each
/// subassembly's base with what its own plan (found or not) takes off it.
pub fn own_motions(removals: &[Step]) -> usize {
    removals.iter().map(|s| 1 + s.group.as_ref().and_then(|g| g.plan.as_ref()).map_or(0, |p| own_motions(&p.removals))).sum()
}

impl CoreWhy {
    /// Why the core of `parts` on `base` is locked, in `world` (the plan's collision world).
    /// `grid` says whether the grid planner ran on it; `lenient` reruns the core's own plan on its
    /// base with the lenient policy, and is called only when a pair of the core overlaps and the
    /// world's policy tests it strictly (otherwise the lenient tests are the same: `unchanged`).
    pub fn of(
        world: &World,
        base: usize,
        parts: &[usize],
        grid: CoreGrid,
        lenient: &mut dyn FnMut(usize, &[usize]) -> CoreLenient,
    ) -> CoreWhy {
        let units = &world.assembly().units;
        let artefact_depth = units.from_metres(ARTEFACT_RELATIVE_DEPTH * world.assembly().diagonal() as f64);
        let n = world.num_parts();
        let core = PartSet::from_indices(n + 1, parts.iter().copied().filter(|&p| p < n));
        let notes: Vec<_> = world.overlaps().notes().iter().filter(|o| core.contains(o.parts.0) && core.contains(o.parts.1)).collect();
        let overlaps = notes
            .iter()
            .map(|o| {
                let depth = units.from_metres(o.depth as f64);
                CoreOverlap {
                    parts: [o.parts.0, o.parts.1],
                    names: [world.name(o.parts.0).to_string(), world.name(o.parts.1).to_string()],
                    depth,
                    depth_bound: o.bound,
                    gross: o.gross,
                    class: Some(o.class),
                    artefact: o.gross || depth > artefact_depth,
                }
            })
            .collect();
        let directions = world.blocking().directions().len();
        let blocks = core.iter().filter(|&p| p != base).map(|p| blocks_of(world, p, &core)).collect();
        let lenient = if notes.iter().any(|o| o.handling == OverlapHandling::Strict) {
            lenient(base, parts)
        } else {
            CoreLenient { status: LenientStatus::Unchanged, frees: 0 }
        };
        CoreWhy { overlaps, artefact_depth, directions, blocks, grid, lenient }
    }
}

/// What blocks part `p` among the `core`'s other parts, direction by direction.
fn blocks_of(world: &World, p: usize, core: &PartSet) -> CoreBlocks {
    let mut counts: Vec<(usize, usize, usize)> = Vec::new(); // (part, directions, only)
    let mut free = 0;
    for row in world.blocking().row(p) {
        let mut blockers = row.intersection(core);
        blockers.remove(p);
        let alone = blockers.len() == 1;
        if blockers.is_empty() {
            free += 1;
        }
        for q in blockers.iter() {
            match counts.iter_mut().find(|c| c.0 == q) {
                Some(c) => {
                    c.1 += 1;
                    c.2 += usize::from(alone);
                }
                None => counts.push((q, 1, usize::from(alone))),
            }
        }
    }
    counts.sort_by_key(|&(q, d, o)| (std::cmp::Reverse(d), std::cmp::Reverse(o), q));
    let by = counts
        .into_iter()
        .map(|(q, directions, only)| CoreBlocker { part: q, name: world.name(q).to_string(), directions, only })
        .collect();
    CoreBlocks { part: p, name: world.name(p).to_string(), free, by }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::{Stats, Subassembly};
    use asp_geom::math::Vec3;
    use asp_geom::Motion;

    fn single(part: usize) -> Step {
        Step::single(part, Motion::Linear { direction: Vec3::Z, distance: 1.0 })
    }

    fn outcome(status: Status, removals: Vec<Step>) -> PlanOutcome {
        PlanOutcome { status, removals, stats: Stats::default() }
    }

    /// What a lenient rerun frees: each part with its own motion, a subassembly's base with what
    /// its own plan takes off it, a declared unit's base alone; the status from the rerun's end.
    #[test]
    fn a_rerun_frees_the_parts_it_gives_their_own_motion() {
        let all = outcome(Status::Found, vec![single(1), single(2), single(3)]);
        assert_eq!(CoreLenient::of(&all, 4), CoreLenient { status: LenientStatus::Found, frees: 3 });
        // a group of 2 and 3 whose own plan is stuck: 3 comes off the group's base 2 or not at all
        let stuck = outcome(Status::NoPlan { stuck: Vec::new(), state: PartSet::empty(4) }, Vec::new());
        let group = |plan: Option<PlanOutcome>, unit: bool| Step {
            group: Some(Box::new(Subassembly { parts: PartSet::from_indices(4, [2, 3]), plan, unit })),
            ..single(2)
        };
        let locked = outcome(Status::Found, vec![single(1), group(Some(stuck.clone()), false)]);
        assert_eq!(CoreLenient::of(&locked, 4), CoreLenient { status: LenientStatus::Partial, frees: 2 });
        let opened = outcome(Status::Found, vec![single(1), group(Some(outcome(Status::Found, vec![single(3)])), false)]);
        assert_eq!(CoreLenient::of(&opened, 4), CoreLenient { status: LenientStatus::Found, frees: 3 });
        assert_eq!(own_motions(&[group(None, true)]), 1, "a unit moves as one part");
        // stuck after one part, or out of budget after one: what came off, a lower bound
        let partial = outcome(Status::NoPlan { stuck: Vec::new(), state: PartSet::empty(4) }, vec![single(1)]);
        assert_eq!(CoreLenient::of(&partial, 4), CoreLenient { status: LenientStatus::NoPlan, frees: 1 });
        let spent = outcome(Status::BudgetExhausted, vec![single(1)]);
        assert_eq!(CoreLenient::of(&spent, 4), CoreLenient { status: LenientStatus::BudgetExhausted, frees: 1 });
        assert_eq!(CoreLenient::of(&stuck, 4).frees, 0);
    }
}
