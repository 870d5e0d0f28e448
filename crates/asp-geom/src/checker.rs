//! The default [`FeasibilityChecker`]: straight-line removal tests on the collision world,
//! RRT-Connect paths as the slow test, and a stability check of what remains.

use crate::feasibility::{CounterSnapshot, Counters, FeasibilityChecker, MotionKind, Outcome, Stability};
use crate::partset::PartSet;
use crate::physics::{PhysicsConfig, PhysicsStability};
use crate::rrt::{plan_removal_path, RrtConfig};
use crate::world::World;

/// How the stability of a state is judged.
#[derive(Clone, Debug, Default)]
pub enum StabilityMode {
    /// Every present part is linked through the contact graph to a fixed part (thesis 3.3).
    #[default]
    ContactGraph,
    /// The present parts are simulated under gravity with rapier3d (fixed parts static); the
    /// state is unstable when any part moves more than a threshold (see [`crate::physics`]).
    Physics(PhysicsConfig),
}

/// Settings of the [`Checker`].
#[derive(Clone, Debug, Default)]
pub struct CheckerConfig {
    /// The stability criterion.
    pub stability: StabilityMode,
    /// The path planner's budget.
    pub rrt: RrtConfig,
}

/// Removal tests and stability on a [`World`], counting every test.
pub struct Checker {
    world: World,
    config: CheckerConfig,
    counters: Counters,
    /// The physics check, when the stability mode asks for it (its shapes are cached lazily).
    physics: Option<PhysicsStability>,
}

impl Checker {
    /// A checker over `world`. A physics stability mode with out-of-range settings falls back to
    /// the default physics settings; validate them first with [`PhysicsConfig::validate`].
    pub fn new(world: World, config: CheckerConfig) -> Self {
        let physics = match &config.stability {
            StabilityMode::ContactGraph => None,
            StabilityMode::Physics(physics) => Some(PhysicsStability::new(&world, physics)),
        };
        Checker { world, config, counters: Counters::default(), physics }
    }

    /// The collision world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Whether `state` stands with the `held` parts (present, not fixed) held in place by a
    /// gripper or a fixture: they count as fixed. Not counted as a removal test.
    pub fn stability_holding(&self, state: &PartSet, held: &PartSet) -> Stability {
        match &self.physics {
            None => {
                let mut base = self.world.contacts().fixed().clone();
                base.union_with(held);
                self.world.contacts().stability_among(&self.world.contacts().with_fixed(state), &base)
            }
            Some(physics) => physics.stability_holding(&self.world, state, held),
        }
    }
}

impl FeasibilityChecker for Checker {
    fn num_parts(&self) -> usize {
        self.world.num_parts()
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.world.contacts().fixed().contains(part)
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let motion = match kind {
            MotionKind::Linear => self.world.removal().linear(part, state),
            // two straight moves in turn first (exact and cheap), then random sampling
            MotionKind::Path { seed } => match self.world.removal().two_step(part, state) {
                Some(motion) => Ok(motion),
                None => plan_removal_path(&self.world, part, state, &self.config.rrt, seed),
            },
        };
        self.finish(kind, motion, &state.without(part))
    }

    fn stability(&self, state: &PartSet) -> Stability {
        match &self.physics {
            None => self.world.contacts().stability(state),
            Some(physics) => physics.stability(&self.world, state),
        }
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }

    fn group_candidates(&self, state: &PartSet) -> Vec<PartSet> {
        group_candidates(&self.world, state, self.world.contacts().fixed())
    }

    fn in_movable_group(&self, part: usize, state: &PartSet) -> bool {
        in_movable_group(&self.world, part, state, self.world.contacts().fixed())
    }

    fn test_group_removal(&self, group: &PartSet, state: &PartSet) -> Outcome {
        let motion = self.world.removal().group_among(group, state, &self.world.contacts().with_fixed(state));
        self.finish(MotionKind::Linear, motion, &without(state, group))
    }

    fn subassembly(&self, group: &PartSet) -> Option<(usize, Box<dyn FeasibilityChecker + '_>)> {
        let base = subassembly_base(&self.world, group)?;
        let fixed = PartSet::from_indices(self.world.num_parts() + 1, [base]);
        Some((base, Box::new(OnBase { world: &self.world, fixed, counters: Counters::default() })))
    }
}

impl Checker {
    /// The outcome of a removal whose motion test gave `motion`: the stability of `rest`, then
    /// counted.
    fn finish(&self, kind: MotionKind, motion: std::result::Result<crate::Motion, PartSet>, rest: &PartSet) -> Outcome {
        let outcome = match motion {
            Err(blockers) => Outcome::Collision { blockers },
            Ok(motion) => match self.stability(rest) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(kind, &outcome);
        outcome
    }
}

/// `state` without the parts of `group`.
fn without(state: &PartSet, group: &PartSet) -> PartSet {
    let mut rest = state.clone();
    for p in group.iter() {
        rest.remove(p);
    }
    rest
}

/// The closures of single parts under blocking, per candidate direction, that hold no fixed part
/// and at least two parts: smallest first, then by their lowest part, without duplicates.
fn group_candidates(world: &World, state: &PartSet, fixed: &PartSet) -> Vec<PartSet> {
    let mut present = state.clone();
    present.union_with(fixed);
    let mut found: Vec<PartSet> = Vec::new();
    for k in 0..world.blocking().directions().len() {
        for p in state.iter().filter(|&p| !fixed.contains(p)) {
            let closure = world.blocking().group_closure(&PartSet::from_indices(world.num_parts() + 1, [p]), k, &present);
            if closure.len() >= 2 && !closure.intersects(fixed) && !found.contains(&closure) {
                found.push(closure);
            }
        }
    }
    found.sort_by_key(|g| (g.len(), g.iter().next()));
    found
}

/// Whether the closure of `part` along some candidate direction reaches no fixed part.
fn in_movable_group(world: &World, part: usize, state: &PartSet, fixed: &PartSet) -> bool {
    let mut present = state.clone();
    present.union_with(fixed);
    let seed = PartSet::from_indices(world.num_parts() + 1, [part]);
    (0..world.blocking().directions().len()).any(|k| !world.blocking().group_closure(&seed, k, &present).intersects(fixed))
}

/// The base of a subassembly planned on its own: its largest part (by the volume of its
/// bounds; the lowest index among equals), which the others are put onto.
fn subassembly_base(world: &World, group: &PartSet) -> Option<usize> {
    let volume = |p: usize| {
        let b = world.shapes().aabb(p);
        (b.maxs - b.mins).as_dvec3().element_product()
    };
    group.iter().filter(|&p| p < world.num_parts()).fold(None, |best: Option<usize>, p| match best {
        Some(b) if volume(b) >= volume(p) => Some(b),
        _ => Some(p),
    })
}

/// A subassembly taken out of the model and planned on its own base: `fixed` are the only fixed
/// parts (no virtual ground), straight-line removals and groups only (the path planner searches
/// the whole model's space), contact-graph stability on the base.
struct OnBase<'w> {
    world: &'w World,
    fixed: PartSet,
    counters: Counters,
}

impl OnBase<'_> {
    fn present(&self, state: &PartSet) -> PartSet {
        let mut present = state.clone();
        present.union_with(&self.fixed);
        present
    }

    fn finish(&self, motion: std::result::Result<crate::Motion, PartSet>, rest: &PartSet) -> Outcome {
        let outcome = match motion {
            Err(blockers) => Outcome::Collision { blockers },
            Ok(motion) => match self.stability(rest) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(MotionKind::Linear, &outcome);
        outcome
    }
}

impl FeasibilityChecker for OnBase<'_> {
    fn num_parts(&self) -> usize {
        self.world.num_parts()
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.fixed.contains(part)
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let motion = match kind {
            MotionKind::Linear => self.world.removal().linear_among(part, state, &self.present(state)),
            // no path planner inside a subassembly: a failed test that names no blocker
            MotionKind::Path { .. } => Err(PartSet::empty(self.world.num_parts() + 1)),
        };
        self.finish(motion, &state.without(part))
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.world.contacts().stability_among(&self.present(state), &self.fixed)
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }

    fn group_candidates(&self, state: &PartSet) -> Vec<PartSet> {
        group_candidates(self.world, state, &self.fixed)
    }

    fn in_movable_group(&self, part: usize, state: &PartSet) -> bool {
        in_movable_group(self.world, part, state, &self.fixed)
    }

    fn test_group_removal(&self, group: &PartSet, state: &PartSet) -> Outcome {
        let motion = self.world.removal().group_among(group, state, &self.present(state));
        self.finish(motion, &without(state, group))
    }

    fn subassembly(&self, group: &PartSet) -> Option<(usize, Box<dyn FeasibilityChecker + '_>)> {
        let base = subassembly_base(self.world, group)?;
        let fixed = PartSet::from_indices(self.world.num_parts() + 1, [base]);
        Some((base, Box::new(OnBase { world: self.world, fixed, counters: Counters::default() })))
    }
}
