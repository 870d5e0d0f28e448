//! The default [`FeasibilityChecker`]: straight-line removal tests on the collision world,
//! RRT-Connect paths as the slow test, and a stability check of what remains.

use crate::feasibility::{
    CounterSnapshot, Counters, FeasibilityChecker, MotionKind, Outcome, Stability,
};
use crate::partset::PartSet;
use crate::rrt::{plan_removal_path, RrtConfig};
use crate::world::World;

/// How the stability of a state is judged.
#[derive(Clone, Debug, Default)]
pub enum StabilityMode {
    /// Every present part is linked through the contact graph to a fixed part (seed 3.3).
    #[default]
    ContactGraph,
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
}

impl Checker {
    /// A checker over `world`.
    pub fn new(world: World, config: CheckerConfig) -> Self {
        Checker { world, config, counters: Counters::default() }
    }

    /// The collision world.
    pub fn world(&self) -> &World {
        &self.world
    }
}

impl FeasibilityChecker for Checker {
    fn num_parts(&self) -> usize {
        self.world.num_parts()
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.world.fixed().contains(part)
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let motion = match kind {
            MotionKind::Linear => self.world.linear_removal(part, state),
            MotionKind::Path { seed } => {
                plan_removal_path(&self.world, part, state, &self.config.rrt, seed)
            }
        };
        let outcome = match motion {
            Err(blockers) => Outcome::Collision { blockers },
            Ok(motion) => match self.stability(&state.without(part)) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(kind, &outcome);
        outcome
    }

    fn stability(&self, state: &PartSet) -> Stability {
        match &self.config.stability {
            StabilityMode::ContactGraph => self.world.contact_stability(state),
        }
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }
}
