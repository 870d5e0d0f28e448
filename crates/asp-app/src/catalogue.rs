//! The catalogue: the one place where each named part ordering, objective, rollout policy and
//! robot meets its implementation and its one line of help. The command line's `--help`, its
//! accepted values, Python's `order_names()` and the error messages all read these tables, so a
//! new ordering is its implementation plus one entry in [`ORDERINGS`]:
//!
//! ```text
//! OrderingEntry {
//!     name: "widest-first",
//!     help: "parts by decreasing width",
//!     bookkeeping: |_checker| false,
//!     takes_model: false,
//!     build: |_model, _checker| Ok(Arc::new(my_crate::WidestFirst)),
//! },
//! ```

use crate::error::{AppError, Result};
use asp_search::{BuiltinOrder, Mdp, OrderingSource, Policy};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Builds an ordering from the model file (when it takes one and one is given) for a run whose
/// removals `checker` decides.
pub type BuildOrdering = fn(model: Option<&Path>, checker: asp_learn::Checker) -> Result<Arc<dyn OrderingSource>>;

/// A named part ordering of the depth-first search (`order`).
#[derive(Clone, Copy, Debug)]
pub struct OrderingEntry {
    /// The name `order` takes.
    pub name: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Whether the name implies bookkeeping on top of the ordering, for a search whose removals
    /// the checker decides.
    pub bookkeeping: fn(asp_learn::Checker) -> bool,
    /// Whether it reads a model file (`model`).
    pub takes_model: bool,
    /// Builds the ordering (with the model file, when it takes one and one is given) for a run
    /// whose removals the `checker` decides (a learned ordering needs a model of that checker).
    pub build: BuildOrdering,
}

/// The part orderings, in the order the docs list them; the first is the default.
pub const ORDERINGS: &[OrderingEntry] = &[
    OrderingEntry {
        name: "auto",
        help: "by what a removal test costs: `given` where tests are cheap (the default checker), `gnn` with bookkeeping where they are expensive (`stability` physics, or a `robot` checking the arm)",
        bookkeeping: auto_is_learned,
        takes_model: true,
        build: |model, checker| match auto_is_learned(checker) {
            true => gnn(model, checker),
            false => Ok(Arc::new(BuiltinOrder::Given)),
        },
    },
    OrderingEntry {
        name: "given",
        help: "the model's part order",
        bookkeeping: |_| false,
        takes_model: false,
        build: |_, _| Ok(Arc::new(BuiltinOrder::Given)),
    },
    OrderingEntry {
        name: "shuffled",
        help: "one random order drawn from the seed at the start and kept (the thesis' vanilla AbD)",
        bookkeeping: |_| false,
        takes_model: false,
        build: |_, _| Ok(Arc::new(BuiltinOrder::Shuffled)),
    },
    OrderingEntry {
        name: "random",
        help: "a fresh random order in every state (from the seed and the state)",
        bookkeeping: |_| false,
        takes_model: false,
        build: |_, _| Ok(Arc::new(BuiltinOrder::Random)),
    },
    OrderingEntry {
        name: "bookkeeping",
        help: "the given order with bookkeeping: a blocked part is retested only after a blocker is gone",
        bookkeeping: |_| true,
        takes_model: false,
        build: |_, _| Ok(Arc::new(BuiltinOrder::Given)),
    },
    OrderingEntry {
        name: "gnn",
        help: "parts in order of the removability a graph neural network predicts (`model`), predicted again after each removal (thesis 3.5.3)",
        bookkeeping: |_| false,
        takes_model: true,
        build: gnn,
    },
];

/// The `gnn` ordering of `model`, or of the shipped model, for a run under `checker`: without a
/// file, the shipped model trained on that checker's labels (the default checker's where none is
/// shipped, [`asp_learn::shipped_model`]); a file trained on another checker's labels (its
/// `asp.checker`; a file without it counts as `default`) is an error naming it and both checkers.
pub fn gnn(model: Option<&Path>, checker: asp_learn::Checker) -> Result<Arc<dyn OrderingSource>> {
    Ok(Arc::new(gnn_source(model, checker)?))
}

/// Whether `auto` is the learned ordering with bookkeeping (else `given`) for a search whose
/// removals `checker` decides: where a test is expensive (the physics simulation, 30-160 ms; the
/// arm's grasp and path, 20-100 ms) one inference (a fraction of a millisecond) pays as soon as it
/// saves a test; the default checker answers from cached rows in microseconds, where it cannot.
/// Decided from the checker, never from a clock, so one seed gives one plan (ARCHITECTURE.md,
/// "Cost-aware default ordering").
pub fn auto_is_learned(checker: asp_learn::Checker) -> bool {
    checker != asp_learn::Checker::Default
}

/// The source [`gnn`] orders with: `model`, or the shipped model of `checker`.
pub fn gnn_source(model: Option<&Path>, checker: asp_learn::Checker) -> Result<asp_learn::GnnSource> {
    Ok(match model {
        Some(p) => asp_learn::GnnSource::load_for(p, asp_geom::graph::GraphConfig::default(), checker)?,
        None => asp_learn::GnnSource::shipped_for(checker)?,
    })
}

/// The ordering called `name`, or an error listing the names.
pub fn ordering(name: &str) -> Result<&'static OrderingEntry> {
    ORDERINGS.iter().find(|o| o.name == name).ok_or_else(|| {
        AppError::setting(
            "order",
            format!("unknown order '{name}' (use {})", ORDERINGS.iter().map(|o| o.name).collect::<Vec<_>>().join(", ")),
        )
    })
}

/// Where an objective comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjectiveSource {
    /// Built into the optimiser (`asp_search::objective::objective_by_name`).
    BuiltIn,
    /// Provided by the robot's extension (`asp_robot::RobotExtension`): needs `robot`.
    Robot,
}

/// A named objective of the optimiser (`objective`).
#[derive(Clone, Copy, Debug)]
pub struct ObjectiveEntry {
    /// The name `objective` takes.
    pub name: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Where its implementation comes from.
    pub source: ObjectiveSource,
}

/// The objectives, in the order the docs list them.
pub const OBJECTIVES: &[ObjectiveEntry] = &[
    ObjectiveEntry {
        name: "access",
        help: "accessibility of each part as it leaves (thesis 6.15), maximised",
        source: ObjectiveSource::BuiltIn,
    },
    ObjectiveEntry {
        name: "dirchange",
        help: "shared removal directions: fewer direction changes (thesis 6.16)",
        source: ObjectiveSource::BuiltIn,
    },
    ObjectiveEntry { name: "pathlen", help: "straight-line removal path length, minimised", source: ObjectiveSource::BuiltIn },
    ObjectiveEntry {
        name: asp_robot::ROBOT_PATH,
        help: "the robot arm's total joint-space path (thesis 5.3), minimised; needs `robot`",
        source: ObjectiveSource::Robot,
    },
];

/// A robot the catalogue names (`robot`; any other value is a URDF file).
#[derive(Clone, Copy, Debug)]
pub struct RobotEntry {
    /// The name `robot` takes.
    pub name: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Builds the robot.
    pub build: fn() -> asp_robot::Robot,
}

/// The shipped robots.
pub const ROBOTS: &[RobotEntry] =
    &[RobotEntry { name: "panda", help: "the shipped Franka-Panda-like arm", build: asp_robot::Robot::panda }];

/// The robot `name` stands for: a catalogue robot, else a URDF file whose meshes are found
/// under `files`' rules.
pub fn robot(name: &str, files: &asp_robot::RobotFiles) -> Result<asp_robot::Robot> {
    match ROBOTS.iter().find(|r| r.name == name) {
        Some(r) => Ok((r.build)()),
        None => Ok(asp_robot::Robot::from_urdf_file_checked(Path::new(name), &asp_robot::ChainSpec::default(), files)?),
    }
}

/// A rollout and expansion policy of the optimiser, made for one problem: the problem tells
/// what a policy must know of it (the learned Q-functions' direction count is the maps').
pub trait PolicySource: Send + Sync + std::fmt::Debug {
    /// A short name for reports (`random`, `q`).
    fn name(&self) -> &str;
    /// The policy for `mdp`.
    fn prepare(&self, mdp: &Mdp) -> Result<Arc<dyn Policy>>;
    /// The learned guidance this policy is, as the plan JSON states it (default `None`: no
    /// learned guidance).
    fn guidance(&self) -> Option<asp_search::report::GuidanceEntry> {
        None
    }
}

/// A named rollout policy (`q` selects the learned one).
#[derive(Clone, Copy, Debug)]
pub struct PolicyEntry {
    /// The name.
    pub name: &'static str,
    /// One line of help.
    pub help: &'static str,
}

/// The rollout policies, in the order the docs list them; the first is the default.
pub const POLICIES: &[PolicyEntry] = &[
    PolicyEntry { name: "random", help: "uniformly random rollouts and expansions (the thesis' vanilla MCTS)" },
    PolicyEntry {
        name: "q",
        help: "ε-greedy over learned Q-functions (`q`, one ONNX file per objective; thesis 5.4.5, 6.4.4), where `q_use` says",
    },
];

/// The probability of a random removal where learned Q-functions guide (thesis 5.4.5: 0.2).
pub const DEFAULT_EPSILON: f64 = 0.2;

/// The word of `q` that turns learned guidance off (the search without Q-functions, also
/// where [`default_guidance`] would guide).
pub const NO_Q: &str = "none";

/// The guidance an optimisation without `q` gets: greedy seeds on the shipped Q-functions
/// ([`asp_search::QUse::Seed`]: before the first episode, then the vanilla search) when every
/// objective has one (`access`, `dirchange`, `pathlen`) and the maps have the resolution they
/// were trained on (9); otherwise none. The seeds leave the tree search as vanilla's of the same
/// seed (they draw no random numbers and do not move the tree's bounds); they join the archive
/// and the local search (`polish`), which shares its work among them and vanilla's sequences,
/// at the cost of a few greedy sequences of forward passes. The
/// rule comes from measurement, not from timings at run time (docs/benchmarks.md, "Guidance at
/// equal wall time"): PUCT priors, guided rollouts and online learning lost to vanilla at equal
/// time on held-out 41- to 106-part assemblies, seeds did not.
pub fn default_guidance(objectives: &[&str], resolution: usize) -> Result<Option<QPolicy>> {
    let shipped = |o: &&str| asp_learn::SHIPPED_Q.iter().any(|(name, _, _)| name == o);
    if resolution != asp_geom::distmap::DEFAULT_RESOLUTION || objectives.is_empty() || !objectives.iter().all(shipped) {
        return Ok(None);
    }
    QPolicy::new(&[PathBuf::from(asp_learn::SHIPPED_Q_NAME)], objectives, DEFAULT_EPSILON, asp_search::QUse::Seed).map(Some)
}

/// The ε-greedy policy over learned Q-functions, one per objective of the problem in its order.
/// The files are opened and checked to be Q models when it is made; their objectives and
/// direction counts are checked against the problem in [`PolicySource::prepare`].
#[derive(Clone, Debug)]
pub struct QPolicy {
    /// The Q models, one per objective.
    models: Vec<Arc<asp_learn::GraphModel>>,
    /// The probability of a random removal.
    epsilon: f64,
    /// Where the Q-values guide.
    uses: asp_search::QUse,
}

impl QPolicy {
    /// A policy over the Q models at `paths`, one per objective of `objectives` in their order,
    /// with ε checked to be in [0, 1].
    pub fn new(paths: &[PathBuf], objectives: &[&str], epsilon: f64, uses: asp_search::QUse) -> Result<Self> {
        if !(0.0..=1.0).contains(&epsilon) {
            return Err(AppError::setting("epsilon", format!("must be in [0, 1], got {epsilon}")));
        }
        let models = asp_learn::open_q_models(paths, objectives).map_err(|e| AppError::setting("q", e.to_string()))?;
        Ok(QPolicy { models, epsilon, uses })
    }
}

impl PolicySource for QPolicy {
    fn name(&self) -> &str {
        "q"
    }

    fn prepare(&self, mdp: &Mdp) -> Result<Arc<dyn Policy>> {
        let names = mdp.objective_names();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let directions = mdp.maps().num_directions();
        asp_learn::epsilon_greedy_models(&self.models, &names, self.epsilon, directions, self.uses)
            .map_err(|e| AppError::setting("q", e.to_string()))
    }

    fn guidance(&self) -> Option<asp_search::report::GuidanceEntry> {
        let rollouts = matches!(self.uses, asp_search::QUse::Rollouts | asp_search::QUse::Both);
        Some(asp_search::report::GuidanceEntry {
            kind: "q".into(),
            models: self.models.iter().map(|m| m.path().to_string()).collect(),
            q_use: self.uses.name().into(),
            epsilon: rollouts.then_some(self.epsilon),
        })
    }
}

/// A policy that is the same for every problem (a caller's own).
#[derive(Clone, Debug)]
pub struct FixedPolicy(pub Arc<dyn Policy>);

impl PolicySource for FixedPolicy {
    fn name(&self) -> &str {
        "fixed"
    }

    fn prepare(&self, _mdp: &Mdp) -> Result<Arc<dyn Policy>> {
        Ok(self.0.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_objective_is_catalogued_and_every_entry_resolves() {
        for name in asp_search::objective::OBJECTIVE_NAMES {
            assert!(OBJECTIVES.iter().any(|o| o.name == name && o.source == ObjectiveSource::BuiltIn), "{name}");
        }
        let robot = asp_robot::RobotExtension::new(asp_robot::RobotSetup::panda());
        let provided = asp_search::MdpExtension::objective_names(&robot);
        for o in OBJECTIVES {
            match o.source {
                ObjectiveSource::BuiltIn => assert!(asp_search::objective::objective_by_name(o.name).is_ok(), "{}", o.name),
                ObjectiveSource::Robot => assert!(provided.iter().any(|p| p == o.name), "{}", o.name),
            }
        }
    }

    #[test]
    fn orderings_build_by_name_and_unknown_names_list_the_known() {
        for o in ORDERINGS.iter().filter(|o| !o.takes_model) {
            let source = (o.build)(None, asp_learn::Checker::Default).unwrap();
            assert_eq!(source.name(), if o.name == "bookkeeping" { "given" } else { o.name });
        }
        let gnn = ordering("gnn").unwrap();
        assert_eq!((gnn.build)(None, asp_learn::Checker::Default).unwrap().name(), "gnn");
        let e = ordering("sideways").unwrap_err().to_string();
        assert_eq!(e, "order: unknown order 'sideways' (use auto, given, shuffled, random, bookkeeping, gnn)");
        let files = asp_robot::RobotFiles::default();
        assert!(robot("panda", &files).is_ok());
        assert!(robot("/no/such/robot.urdf", &files).unwrap_err().to_string().contains("/no/such/robot.urdf"));
    }
}
