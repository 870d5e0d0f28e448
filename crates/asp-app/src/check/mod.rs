//! Checking a given assembly sequence (`asp check`, `asp.Assembly.check`; docs/check-format.md).
//!
//! A sequence names the parts in assembly order, one step per line: a part, or a rigid
//! subassembly as a bracketed group (`[a, b]`), each with an optional *assembly* (insertion)
//! direction (`bolt1 -z`, `bolt1 0,0,-1`); the part is then removed along the opposite direction.
//! A plan JSON (`asp plan --out`) is a sequence too: its `assembly_sequence`, with each linear or
//! screw step's insertion direction.
//!
//! Every step is tested in disassembly order with the planner's own collision world and checker
//! ([`crate::pipeline::checker`], the request's settings): the state before step `i` is removed
//! is the base parts plus steps `0..=i`, so each step's test depends only on the sequence, never
//! on whether another step passed. A step passes when its part (group) leaves that state along
//! some candidate direction (or along the given one) — the path planner after straight lines when
//! the settings allow it — and what remains is stable. The first failing step in assembly order
//! is reported with its reason (blocked: by which parts along which directions; no path; unstable:
//! which parts would float), and a *repair*: the feasible sequence found by a depth-first search
//! that at every state tries the given steps in the given order (latest placed first, the given
//! sequence's own disassembly order), so a feasible sequence is its own repair. The repair's
//! distance to the given sequence is measured twice, over steps: the steps moved (`n − LCS`, the
//! length of the longest common subsequence) and the Kendall tau distance (pairs of steps in the
//! other order). The search is greedy, so the repair is near, not proven nearest.

use crate::error::{AppError, Result};
use crate::pipeline::{self, PlanSettings};
use asp_geom::math::Vec3;
use asp_geom::{Assembly, Checker, FeasibilityChecker, Motion, MotionKind, Outcome, PartSet, Stability, World};
use asp_search::report::{insertion, MotionEntry, NamedPart, RobotEntry, RobotStepEntry};
use asp_search::{Budget, PlanOutcome, Stats, Status, Step, Subassembly};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::time::Instant;

/// The version of the check report this build writes (docs/check-format.md). Minor bumps add
/// keys; major bumps change or remove them.
pub const CHECK_FORMAT_VERSION: &str = "1.1";

mod parse;
mod repair;
mod report;

pub use parse::*;
pub use repair::*;
pub use report::*;

/// The tests of one unit in one state, on the planner's checker: `checker` answers (the
/// collision world's, or the robot's decorating it), `mesh` names blockers and motions.
struct Tester<'a> {
    mesh: &'a Checker,
    checker: &'a dyn FeasibilityChecker,
    /// Whether `checker` decorates `mesh` (a robot, held parts).
    decorated: bool,
    settings: &'a PlanSettings,
}

impl Tester<'_> {
    fn world(&self) -> &World {
        self.mesh.world()
    }

    fn group(&self, parts: &[usize]) -> PartSet {
        PartSet::from_indices(self.world().num_parts() + 1, parts.iter().copied())
    }

    fn rest(state: &PartSet, parts: &[usize]) -> PartSet {
        let mut rest = state.clone();
        for &p in parts {
            rest.remove(p);
        }
        rest
    }

    /// Removing `unit` from `state` along any motion the settings allow: straight lines (a
    /// group's together), then the path planner for a single part.
    fn any(&self, parts: &[usize], state: &PartSet) -> Outcome {
        let outcome = self.straight(parts, state);
        if let ([p], true) = (parts, matches!(outcome, Outcome::Collision { .. })) {
            if let Some(path) = self.path(*p, state).filter(|o| !matches!(o, Outcome::Collision { .. })) {
                return path;
            }
        }
        outcome
    }

    /// Removing `parts` from `state` along a straight line (a group's together).
    fn straight(&self, parts: &[usize], state: &PartSet) -> Outcome {
        Self::straight_on(self.checker, &self.group(parts), parts, state)
    }

    fn straight_on(checker: &dyn FeasibilityChecker, group: &PartSet, parts: &[usize], state: &PartSet) -> Outcome {
        match parts {
            [p] => checker.test_removal(*p, state, MotionKind::Linear),
            _ => checker.test_group_removal(group, state),
        }
    }

    /// Removing part `p` from `state` along a path, when the settings allow the path planner.
    fn path(&self, p: usize, state: &PartSet) -> Option<Outcome> {
        self.settings.path_planner.then(|| self.checker.test_removal(p, state, MotionKind::Path { seed: self.settings.seed }))
    }

    /// When the decorating checker refused what the collision world admits: the world's free
    /// removal motion and the decorator's reason.
    fn refusal(&self, parts: &[usize], state: &PartSet) -> Option<(Motion, String)> {
        if !self.decorated {
            return None;
        }
        let motion = match Self::straight_on(self.mesh, &self.group(parts), parts, state) {
            Outcome::Removed(m) | Outcome::Unstable { motion: m, .. } => m,
            Outcome::Collision { .. } => return None,
        };
        let reason = match parts {
            [p] => self.checker.refusal_reason(*p, state).unwrap_or("refused").to_string(),
            _ => "a group: the robot carries one part at a time".to_string(),
        };
        Some((motion, reason))
    }

    /// The parts of `state` (and the base) blocking `parts` removed along `dir` (unit).
    fn blockers_along(&self, parts: &[usize], state: &PartSet, dir: Vec3) -> PartSet {
        let world = self.world();
        let present = world.contacts().with_fixed(state);
        let group = self.group(parts);
        if let Some(k) = world.blocking().directions().iter().position(|d| d.dot(dir) > 0.99999) {
            return world.blocking().group_blockers(&group, k, &present);
        }
        let mut blockers = PartSet::empty(world.num_parts() + 1);
        for &p in parts {
            for q in present.iter().filter(|q| !group.contains(*q)) {
                if world.blocking().pair_blocks(p, q, dir) {
                    blockers.insert(q);
                }
            }
        }
        blockers
    }

    /// Removing `parts` from `state` along `dir` only (unit removal direction). With a robot
    /// (or held parts), the decorating checker's verdict on the step follows: the arm plans its
    /// own lift, as in `asp plan`, and a refusal or the held parts' stability is its answer.
    fn along(&self, parts: &[usize], state: &PartSet, dir: Vec3) -> std::result::Result<Outcome, PartSet> {
        let world = self.world();
        let blockers = self.blockers_along(parts, state, dir);
        if !blockers.is_empty() {
            return Err(blockers);
        }
        let group = self.group(parts);
        let distance = match parts {
            [p] => world.removal().clearance(*p, state, dir),
            _ => world.removal().group_clearance(&group, state, dir),
        };
        let motion = match parts {
            [p] => {
                let partner =
                    world.contacts().with_fixed(state).iter().filter(|&q| q != *p).find_map(|q| world.overlaps().fits().thread(*p, q));
                match partner.filter(|t| t.axis.direction.dot(dir).abs() > 0.9999) {
                    Some(t) => Motion::Screw { axis_point: t.axis.point, direction: dir, distance },
                    None => Motion::Linear { direction: dir, distance },
                }
            }
            _ => Motion::Linear { direction: dir, distance },
        };
        if self.decorated {
            match self.straight(parts, state) {
                Outcome::Removed(_) => return Ok(Outcome::Removed(motion)),
                Outcome::Unstable { floating, .. } => return Ok(Outcome::Unstable { floating, motion }),
                // refused (the caller asks why), or no candidate direction is free although
                // the given one is: the collision world's stability below
                Outcome::Collision { blockers } if self.refusal(parts, state).is_some() => return Ok(Outcome::Collision { blockers }),
                Outcome::Collision { .. } => {}
            }
        }
        Ok(match self.checker.stability(&Self::rest(state, parts)) {
            Stability::Stable => Outcome::Removed(motion),
            Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
        })
    }

    /// Per candidate direction, the blockers of `parts` in `state` (removal directions).
    fn per_direction(&self, parts: &[usize], state: &PartSet) -> Vec<(Vec3, PartSet)> {
        let world = self.world();
        let present = world.contacts().with_fixed(state);
        let group = self.group(parts);
        world.blocking().directions().iter().enumerate().map(|(k, d)| (*d, world.blocking().group_blockers(&group, k, &present))).collect()
    }
}

/// Checks `steps` on the model at `path` with `settings` (the request's, as `asp plan` resolves
/// them).
pub fn check_file(path: &std::path::Path, steps: &[GivenStep], settings: &PlanSettings) -> Result<CheckReport> {
    let started = Instant::now();
    let assembly = pipeline::load(path, settings)?;
    let mut report = check_assembly(assembly, steps, settings)?;
    report.stats.seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// What the check of every step and the repair found, before the robot's annotations.
struct Checked {
    steps: Vec<CheckStep>,
    first_failure: Option<usize>,
    repair: Option<Repair>,
    /// The feasible sequence (the given one, or the repair) in disassembly order, for the
    /// decorating checker to describe.
    removals: Vec<Step>,
}

/// Checks `steps` on `assembly` with `settings`: every step's removal in disassembly order on
/// the planner's checker (with a robot, the robot's decorating it), the first failure, and a
/// repair when one fails.
pub fn check_assembly(assembly: Assembly, steps: &[GivenStep], settings: &PlanSettings) -> Result<CheckReport> {
    let started = Instant::now();
    if settings.optimise.is_some() {
        return Err(AppError::setting("objective", "does not apply to checking a sequence (the check tests feasibility)"));
    }
    let mut notes = Vec::new();
    let units = resolve_units(&assembly, steps, &mut notes)?;
    let budget = pipeline::budget(settings)?;
    let checker = pipeline::checker(assembly, settings)?;
    let world = checker.world();
    let assembly = world.assembly();
    let named = |s: &mut dyn Iterator<Item = usize>| -> Vec<NamedPart> {
        s.map(|p| NamedPart { part: p, name: world.name(p).to_string() }).collect()
    };
    let mut checked = None;
    let mut run = |c: &dyn FeasibilityChecker| -> asp_search::Result<PlanOutcome> {
        let tester = Tester { mesh: &checker, checker: c, decorated: settings.checker_extension.is_some(), settings };
        let found = check_units(&tester, &units, &budget);
        let status = if found.removals.is_empty() { Status::BudgetExhausted } else { Status::Found };
        let outcome = PlanOutcome { status, removals: found.removals.clone(), stats: Stats::default() };
        checked = Some(found);
        Ok(outcome)
    };
    let robot = match &settings.checker_extension {
        Some(e) => e.solve(&checker, settings.seed, &mut run)?.1,
        None => {
            run(&checker)?;
            None
        }
    };
    let mut found = checked.expect("the check ran");
    if let Some(r) = &robot {
        // the decorator describes the feasible sequence's removals, in disassembly order
        // (`steps` is empty without a robot, `held` may be shorter than the removals)
        let robot_step = |k: usize| r.steps.get(k).cloned().flatten();
        let held = |k: usize| named(&mut r.held.get(k).into_iter().flatten().copied());
        let m = found.removals.len();
        if found.first_failure.is_none() {
            for (i, s) in found.steps.iter_mut().enumerate() {
                (s.robot, s.held) = (robot_step(m - 1 - i), held(m - 1 - i));
            }
        } else if let Some(rep) = found.repair.as_mut() {
            for (i, s) in rep.sequence.iter_mut().enumerate() {
                (s.robot, s.held) = (robot_step(m - 1 - i), held(m - 1 - i));
            }
        }
    }
    let base_parts = named(&mut world.contacts().fixed().iter());
    Ok(CheckReport {
        format_version: CHECK_FORMAT_VERSION.into(),
        model: assembly.source.display().to_string(),
        units: assembly.units.name.clone(),
        up: assembly.up.to_string(),
        status: if found.first_failure.is_none() { CheckStatus::Feasible } else { CheckStatus::Infeasible },
        base: base_parts,
        steps: found.steps,
        first_failure: found.first_failure,
        repair: found.repair,
        robot: robot.and_then(|r| r.entry),
        notes,
        warnings: world.warnings().to_vec(),
        stats: CheckStats { removal_tests: checker.counters().removal_tests, seconds: started.elapsed().as_secs_f64() },
    })
}

/// Every unit's test in its state, the first failure, the repair, and the feasible sequence as
/// removals.
fn check_units(tester: &Tester<'_>, units: &[Unit], budget: &Budget) -> Checked {
    let world = tester.world();
    let assembly = world.assembly();
    let n = world.num_parts();
    let u = |m: f32| assembly.units.from_metres(m as f64);
    let named = |s: &mut dyn Iterator<Item = usize>| -> Vec<NamedPart> {
        s.map(|p| NamedPart { part: p, name: world.name(p).to_string() }).collect()
    };
    let v3 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let full = PartSet::full(n);
    // the state before step i is removed: the base and steps 0..=i
    let mut base = PartSet::from_indices(n, (0..n).filter(|&p| world.contacts().fixed().contains(p)));
    let mut states = Vec::with_capacity(units.len());
    for unit in units {
        for &p in &unit.parts {
            base.insert(p);
        }
        states.push(base.clone());
    }
    let step_of = |unit: &Unit, motion: Motion| -> Step {
        match unit.parts.as_slice() {
            [p] => Step::single(*p, motion),
            parts => Step {
                part: parts[0],
                motion,
                group: Some(Box::new(Subassembly { parts: PartSet::from_indices(n + 1, parts.iter().copied()), plan: None, unit: false })),
                moves: Vec::new(),
            },
        }
    };
    let mut checked = Vec::with_capacity(units.len());
    let mut removals = Vec::with_capacity(units.len());
    for (i, unit) in units.iter().enumerate() {
        let state = &states[i];
        let outcome = match unit.direction {
            Some(d) => tester.along(&unit.parts, state, -d),
            None => Ok(tester.any(&unit.parts, state)),
        };
        let (motion, failure) = match outcome {
            Ok(Outcome::Removed(m)) => {
                let entry = insertion(&m, &u);
                removals.push(step_of(unit, m));
                (Some(entry), None)
            }
            Ok(Outcome::Unstable { floating, motion }) => {
                (None, Some(Failure::Unstable { floating: named(&mut floating.iter()), motion: insertion(&motion, &u) }))
            }
            Ok(Outcome::Collision { .. }) => match tester.refusal(&unit.parts, state) {
                Some((m, robot_reason)) => (None, Some(Failure::Robot { robot_reason, motion: insertion(&m, &u) })),
                None => {
                    let dirs = tester.per_direction(&unit.parts, state);
                    let mut all = PartSet::empty(n + 1);
                    for (_, b) in &dirs {
                        all.union_with(b);
                    }
                    let directions =
                        dirs.iter().map(|(d, b)| DirectionBlockers { direction: v3(-*d), blockers: named(&mut b.iter()) }).collect();
                    let blockers = named(&mut all.iter());
                    let tried_path = tester.settings.path_planner && unit.parts.len() == 1;
                    (
                        None,
                        Some(if tried_path {
                            Failure::NoPath { directions, blockers }
                        } else {
                            Failure::Blocked { along_given: false, directions, blockers, free_directions: Vec::new() }
                        }),
                    )
                }
            },
            Err(blockers) => {
                let d = unit.direction.expect("a direction was given");
                let free_directions =
                    tester.per_direction(&unit.parts, state).into_iter().filter(|(_, b)| b.is_empty()).map(|(d, _)| v3(-d)).collect();
                let names = named(&mut blockers.iter());
                (
                    None,
                    Some(Failure::Blocked {
                        along_given: true,
                        directions: vec![DirectionBlockers { direction: v3(d), blockers: names.clone() }],
                        blockers: names,
                        free_directions,
                    }),
                )
            }
        };
        checked.push(CheckStep {
            step: i,
            parts: named(&mut unit.parts.iter().copied()),
            given_direction: unit.direction.map(v3),
            feasible: failure.is_none(),
            motion,
            failure,
            robot: None,
            held: Vec::new(),
        });
    }
    let first_failure = checked.iter().position(|s| !s.feasible);
    removals.reverse();
    if first_failure.is_some() {
        removals.clear();
    }
    let repair = first_failure.map(|_| {
        let found = repair_search(tester, units, &full, budget);
        match found.sequence {
            Some(seq) => {
                let order: Vec<usize> = seq.iter().map(|(k, _)| *k).collect();
                let (moved, kept) = moved_steps(&order);
                removals = seq.iter().rev().map(|(k, m)| step_of(&units[*k], m.clone())).collect();
                Repair {
                    status: RepairStatus::Found,
                    sequence: seq
                        .iter()
                        .zip(kept)
                        .map(|((k, m), kept)| RepairStep {
                            parts: named(&mut units[*k].parts.iter().copied()),
                            given_step: *k,
                            moved: !kept,
                            motion: insertion(m, &u),
                            robot: None,
                            held: Vec::new(),
                        })
                        .collect(),
                    moved,
                    kendall_tau: kendall_tau(&order),
                    removal_tests: found.tests,
                }
            }
            None => Repair {
                status: if found.exhausted { RepairStatus::BudgetExhausted } else { RepairStatus::None },
                sequence: Vec::new(),
                moved: 0,
                kendall_tau: 0,
                removal_tests: found.tests,
            },
        }
    });
    Checked { steps: checked, first_failure, repair, removals }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_groups_directions_and_comments_parse() {
        let steps = parse_sequence("# base first\nbase\n[a, b] -z  # a pair\nbolt 1 0,0,-1\nnut#1\n  \nwasher +x\n").unwrap();
        assert_eq!(steps.len(), 5);
        assert_eq!(steps[1].names, vec!["a", "b"]);
        assert_eq!(steps[1].direction, Some([0.0, 0.0, -1.0]));
        assert_eq!(steps[2].names, vec!["bolt 1"]);
        assert_eq!(steps[2].direction, Some([0.0, 0.0, -1.0]));
        assert_eq!(steps[3].names, vec!["nut#1"]);
        assert_eq!(steps[4].direction, Some([1.0, 0.0, 0.0]));
        assert!(parse_sequence("[a, b\n").is_err());
        assert!(parse_sequence("[a] sideways\n").is_err());
        assert!(parse_sequence("# nothing\n").is_err());
    }

    #[test]
    fn distances_count_moved_steps_and_swapped_pairs() {
        assert_eq!(moved_steps(&[0, 1, 2, 3]).0, 0);
        assert_eq!(kendall_tau(&[0, 1, 2, 3]), 0);
        let (moved, kept) = moved_steps(&[0, 2, 1, 3]);
        assert_eq!(moved, 1);
        assert_eq!(kept.iter().filter(|k| !**k).count(), 1);
        assert_eq!(kendall_tau(&[0, 2, 1, 3]), 1);
        assert_eq!(moved_steps(&[3, 2, 1, 0]).0, 3);
        assert_eq!(kendall_tau(&[3, 2, 1, 0]), 6);
        assert_eq!(moved_steps(&[1, 2, 3, 0]).0, 1);
        assert_eq!(kendall_tau(&[1, 2, 3, 0]), 3);
    }

    #[test]
    fn edit_distance_and_nearest_names() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(nearest_names("stik", ["receptacle", "stick", "handle", "cap"].into_iter())[0], "stick");
    }
}
