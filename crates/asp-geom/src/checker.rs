//! The default [`FeasibilityChecker`]: straight-line removal tests on the collision world,
//! RRT-Connect paths as the slow test, and a stability check of what remains.

use crate::feasibility::{
    CounterSnapshot, Counters, FeasibilityChecker, MotionKind, Outcome, Stability,
};
use crate::partset::PartSet;
use crate::physics::{PhysicsConfig, PhysicsStability};
use crate::rrt::{plan_removal_path, RrtConfig};
use crate::world::World;

/// How the stability of a state is judged.
#[derive(Clone, Debug, Default)]
pub enum StabilityMode {
    /// Every present part is linked through the contact graph to a fixed part (seed 3.3).
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

    /// The physics stability check, when the stability mode is [`StabilityMode::Physics`] (e.g. to
    /// [`PhysicsStability::prepare`] its shapes up front).
    pub fn physics(&self) -> Option<&PhysicsStability> {
        self.physics.as_ref()
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
        match &self.physics {
            None => self.world.contact_stability(state),
            Some(physics) => physics.stability(&self.world, state),
        }
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }
}
