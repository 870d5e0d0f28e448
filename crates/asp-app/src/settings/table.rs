//! The settings, one entry each (`settings!`; `docs/plan-request.md` and
//! ARCHITECTURE.md, "Adding a setting").

use super::{choices, orderings, settings, Applies::*, Flag::*, Group::*, Kind::*, Setting};
use crate::catalogue::DEFAULT_EPSILON;
use crate::pipeline::{PlanSettings, DEFAULT_TIMEOUT};
use crate::values::{Choice as _, Stability, Subassemblies};
use asp_geom::distmap::Support;
use asp_geom::OverlapPolicy as Overlaps;
use asp_search::mcts::{DEFAULT_BUDGET, DEFAULT_EPISODES, DEFAULT_EXPLORATION, DEFAULT_POLISH};
use asp_search::QUse;
use serde_json::json;
use std::path::PathBuf;

settings! {
    // --- loading (the CLI and batches; Python's `asp.load`) ---
    unit: Option<String> {
        help: "The unit of the model's coordinates: `m`, `cm`, `mm`, `in`, `ft` or metres per unit; an error for STEP, which names its own.",
        applies: Load, group: Model, derived: "what the file says, else m",
    }
    up: Option<String> {
        help: "The up axis: `x`, `y`, `z`, `-x`, `-y`, `-z` (STEP has none: +z is assumed, with a warning).",
        applies: Load, group: Model, derived: "what the file says, else +y for glTF, +z for STEP, OBJ and STL",
    }
    fixed: Vec<String> {
        help: "Base parts that stay in place, by name, on top of those the file marks as fixed. Without any, a ground plane under the lowest point is the base.",
        applies: Load, group: Model, flag: Many, value_name: "NAME", default: || json!([]), python: "Sequence[str]",
    }
    max_triangles: Option<usize> {
        help: "Most triangles a model may have over all its parts, checked against the file's header counts before memory is taken (docs/security.md).",
        applies: Load, group: Model, kind: Int, value_name: "N", default: || json!(asp_geom::io::DEFAULT_MAX_TRIANGLES), python: "int",
    }
    max_parts: Option<usize> {
        help: "Most parts a model may have, checked the same way.",
        applies: Load, group: Model, kind: Int, value_name: "N", default: || json!(asp_geom::io::DEFAULT_MAX_PARTS), python: "int",
    }
    tessellation: Option<f64> {
        help: "STEP files only: the chord tolerance of each edge and face relative to its own size (OpenCASCADE's relative deflection; recorded per part in the plan); an error for other files.",
        applies: Load, group: Model, kind: Float, value_name: "RELATIVE", default: || json!(asp_geom::io::step::DEFAULT_RELATIVE), python: "float",
    }
    split_bodies: Option<bool> {
        help: "Make each separate body of a part's mesh (pieces that do not touch, such as shelf pins stored in a shelf's mesh) a part of its own, `NAME#1`, `NAME#2`, ...; without it a warning names such a part, which moves as one.",
        applies: Load, group: Model, kind: Bool, flag: On, default: || json!(false), python: "bool",
    }
    allow_outside_files: Option<bool> {
        help: "Let the model and the robot's URDF read files outside their folders: absolute paths, `..` that climbs out, symlinks that point out (docs/security.md).",
        applies: Both, group: Model, kind: Bool, flag: On, default: || json!(false), python: "bool",
    }

    // --- the removal test ---
    tolerance: Option<f64> {
        help: "Contact tolerance: motions may push a part this deep into another.",
        applies: Both, group: Model, kind: Float, derived: "1e-4 × the model's diagonal", python: "float",
    }
    contact_distance: Option<f64> {
        help: "Parts closer than this are in contact, for stability.",
        applies: Both, group: Model, kind: Float, derived: "1e-3 × the model's diagonal", python: "float",
    }
    normals: Option<usize> {
        help: "Clustered surface-normal directions tried besides the six axes (each with its opposite).",
        group: Model, kind: Int, default: || json!(PlanSettings::default().normals), python: "int",
    }
    sphere_directions: Option<usize> {
        help: "Extra removal directions sampled evenly on the sphere.",
        group: Model, kind: Int, default: || json!(PlanSettings::default().sphere_directions), python: "int",
    }
    #[serde(with = "crate::values::choice")]
    overlaps: Option<Overlaps> {
        help: "Parts that overlap in the input (press fits, dowels, screws, slop; warned once per pair with the measured depth, listed in the plan's `overlaps`).",
        applies: Both, group: Model, kind: Choice, choices: choices::<Overlaps>, default: || json!(Overlaps::default().name()), python: "Overlaps",
    }
    #[serde(with = "crate::values::choice")]
    stability: Option<Stability> {
        help: "The feasibility search's stability criterion.",
        instead: "the optimiser's gravity check is `support`",
        group: Model, kind: Choice, choices: choices::<Stability>, default: || json!(Stability::Contact.name()), python: "Stability",
    }
    physics_threshold: Option<f64> {
        help: "Physics stability: how far (a fraction of the model's diagonal) a part may move in the simulation before the state counts as unstable.",
        needs: "`stability` physics", group: Model, kind: Float, default: || json!(crate::resolve::default_physics_threshold()), derived: "0.01", python: "float",
    }
    path_planner: Option<bool> {
        help: "Try the path planner (RRT-Connect) when no straight line works; off: straight lines only.",
        group: Model, kind: Bool, flag: Off, default: || json!(PlanSettings::default().path_planner), python: "bool",
    }
    #[serde(deserialize_with = "crate::values::subassemblies")]
    subassemblies: Option<Subassemblies> {
        help: "Let groups of parts leave together as one rigid subassembly when no single part can; off: single parts only. `from-file` follows the file's product tree: each subassembly of the file (STEP assembly instances, named glTF nodes with children) is planned on its own base, then the level above with each as one unit (the plan's `file_subassemblies`); it does not combine with `unit_group`.",
        group: Model, kind: Bool, flag: OffOrMode(Subassemblies::FROM_FILE), value_name: "MODE",
        default: || json!(PlanSettings::default().subassemblies), python: "bool | Literal[\"from-file\"]",
    }
    grid: Option<bool> {
        help: "Plan voxel models by grid moves (interlocking puzzles whose parts must slide in turn before anything can leave).",
        group: Model, kind: Bool, flag: Off, default: || json!(PlanSettings::default().grid), python: "bool",
    }
    rrt_iterations: Option<usize> {
        help: "Path planner iterations per call.",
        group: Model, kind: Int, default: || json!(PlanSettings::default().rrt_iterations), python: "int",
    }
    rrt_time: Option<f64> {
        help: "Path planner wall-time safety cap per call, seconds (the iteration budget keeps runs reproducible; this only guards against pathological models).",
        group: Model, kind: Float, default: || json!(PlanSettings::default().rrt_time), python: "float",
    }

    // --- the feasibility search ---
    order: Option<String> {
        help: "The part ordering of the depth-first search.",
        kind: Choice, choices: orderings, default: || json!(crate::catalogue::ORDERINGS[0].name), python: "Order",
    }
    model: Option<PathBuf> {
        help: "The removability model (ONNX, docs/learning.md) of `order` gnn, and of `order` auto where it is learned.",
        needs: "`order` gnn, or auto under physics or a `robot`", value_name: "FILE", derived: "the shipped model of the run's checker", python: "PathLike",
    }
    bookkeeping: Option<bool> {
        help: "Bookkeeping on top of any ordering: a blocked part is retested only after one of its blockers is gone (implied by `order` bookkeeping).",
        kind: Bool, flag: On, default: || json!(false), python: "bool",
    }
    precedence: Option<bool> {
        help: "Add the precedence graph of a found plan to the plan JSON: which steps must go in before which (blocking and, conservatively, support), the levels of steps that may go in in parallel and the critical path (docs/plan-format.md, \"Precedence\").",
        kind: Bool, flag: On, default: || json!(false), python: "bool",
    }
    seed: Option<u64> {
        help: "Seed of every random choice (random order, path planner, optimisation).",
        applies: Both, kind: Int, default: || json!(0), python: "int",
    }
    max_tests: Option<u64> {
        help: "Stop after this many removal tests (status `budget_exhausted`).",
        kind: Int, python: "int",
    }
    timeout: Option<f64> {
        help: "Stop after this many seconds with the best partial plan (0: no limit).",
        instead: "the optimiser's limit is `time_limit`",
        kind: Float, default: || json!(DEFAULT_TIMEOUT), python: "float",
    }
    #[serde(deserialize_with = "crate::values::groups")]
    unit_group: Vec<Vec<String>> {
        help: "Parts planned as one part each, on purpose (a purchased motor, a pressed-in bearing): a list of groups, each a comma-separated string or a list of part names (one string is one group; on the command line repeat the flag). A unit goes in whole, as a subassembly step whose status is `unit`, and the plan is still `found`; a unit with a fixed part is part of the base. At least two parts each, no part in two.",
        needs: "`subassemblies`", flag: Repeat, value_name: "NAME,NAME...", default: || json!([]), python: "str | Sequence[str | Sequence[str]]",
    }

    // --- the optimiser (present when `objective` is) ---
    #[serde(deserialize_with = "crate::values::names")]
    objective: Option<Vec<String>> {
        help: "Optimise the sequence for these objectives (comma-separated or a list): `access` (accessibility of each part, thesis 6.15), `dirchange` (shared removal directions, fewer direction changes, 6.16), `pathlen` (straight-line removal path length, minimised), `robot-path` (the arm's path, with `robot`). One objective runs MCTS; several need `pareto`.",
        applies: Optimiser, group: Optimisation, value_name: "LIST", python: "str | Sequence[str]",
    }
    pareto: Option<bool> {
        help: "Search the Pareto front of the objectives (Pareto-MCTS) and write every non-dominated sequence to `pareto_front`.",
        applies: Optimiser, group: Optimisation, kind: Bool, flag: On, default: || json!(false), python: "bool",
    }
    episodes: Option<usize> {
        help: "MCTS episodes (each walks from the assembled state to a complete sequence).",
        applies: Optimiser, group: Optimisation, kind: Int, default: || json!(DEFAULT_EPISODES), python: "int",
    }
    budget: Option<usize> {
        help: "Search budget: MCTS iterations per step of an episode (the thesis uses 5).",
        applies: Optimiser, group: Optimisation, kind: Int, default: || json!(DEFAULT_BUDGET), python: "int",
    }
    threads: Option<usize> {
        help: "Optimiser threads, each growing its own tree. The same seed and thread count give the same answer.",
        applies: Optimiser, group: Optimisation, kind: Int, derived: "all cores", python: "int",
    }
    time_limit: Option<f64> {
        help: "Stop the optimiser after this many seconds (the answer then depends on timing).",
        instead: "the feasibility search's limit is `timeout`",
        applies: Optimiser, group: Optimisation, kind: Float, value_name: "SECONDS", python: "float",
    }
    exploration: Option<f64> {
        help: "Exploration constant c of UCT / MOUCB.",
        applies: Optimiser, group: Optimisation, kind: Float, default: || json!(DEFAULT_EXPLORATION), derived: "1/√2", python: "float",
    }
    polish: Option<f64> {
        help: "Local search over the answer's sequences: block moves of 1-3 removals around every sequence the search finds, taking at most this share of the search's work (0: off).",
        applies: Optimiser, group: Optimisation, kind: Float, value_name: "SHARE", default: || json!(DEFAULT_POLISH), python: "float",
    }
    resolution: Option<usize> {
        help: "Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the half sphere.",
        applies: Optimiser, group: Optimisation, kind: Int, default: || json!(asp_geom::distmap::DEFAULT_RESOLUTION), python: "int",
    }
    d_max: Option<f64> {
        help: "Cap d_max of the distance maps.",
        applies: Optimiser, group: Optimisation, kind: Float, derived: "the model's diagonal", python: "float",
    }
    #[serde(with = "crate::values::choice")]
    support: Option<Support> {
        help: "The optimiser's gravity check on the distance maps.",
        instead: "the feasibility search's criterion is `stability`",
        applies: Optimiser, group: Optimisation, kind: Choice, choices: choices::<Support>, default: || json!(Support::default().name()), python: "Support",
    }
    #[serde(deserialize_with = "crate::values::paths")]
    q: Option<Vec<PathBuf>> {
        help: "Learned Q-functions (ONNX, `python -m asp.train q`), one per objective in `objective`'s order (comma-separated or a list), or `shipped`: the Q-functions shipped with asp for `access`, `dirchange` and `pathlen` (in place of one model or, alone, of all), or `none`: no learned guidance. Where `q_use` says, rollouts take the removal with the largest Q-value (the product of the values for several objectives) instead of a random one, except with probability `epsilon` (thesis 5.4.5, 6.4.4). Without `q`, an optimisation whose objectives all have a shipped Q, on maps of resolution 9, starts from the shipped Q-functions' greedy sequences and then searches as vanilla does (`q_use` `seed`; docs/benchmarks.md, \"Guidance at equal wall time\"); `q` none turns that off.",
        applies: Optimiser, group: Optimisation, value_name: "MODELS", python: "PathLike | Sequence[PathLike]",
        derived: "`shipped` with `q_use` `seed` for access, dirchange and pathlen at resolution 9; none otherwise",
    }
    epsilon: Option<f64> {
        help: "The probability of a random removal in a rollout (or expansion) guided by `q`.",
        needs: "`q`", applies: Optimiser, group: Optimisation, kind: Float, default: || json!(DEFAULT_EPSILON), python: "float",
    }
    #[serde(with = "crate::values::choice")]
    q_use: Option<QUse> {
        help: "Where `q` guides.",
        needs: "`q`", applies: Optimiser, group: Optimisation, kind: Choice, choices: choices::<QUse>, default: || json!(QUse::default().name()), python: "QUse",
    }

    // --- the robot (both searches) ---
    robot: Option<String> {
        help: "A robot arm that must carry every removal out: `panda` (the shipped Franka-Panda-like arm) or a URDF file. A part counts as removable only when the arm can grasp it, lift it 5 cm along its removal direction and carry it to the drop-off without collision (thesis 5.3).",
        applies: Both, group: Robot, value_name: "panda|FILE.urdf",
    }
    #[serde(deserialize_with = "crate::values::point")]
    robot_base: Option<[f64; 3]> {
        help: "The robot base's position `x,y,z` (a list or a comma-separated string), model frame.",
        needs: "`robot`", applies: Both, group: Robot, value_name: "X,Y,Z",
        derived: "on the floor, 0.3 m in front of the model's -x side, centred on it", python: "str | Sequence[float]",
    }
    #[serde(deserialize_with = "crate::values::point")]
    drop_off: Option<[f64; 3]> {
        help: "Where the gripper puts removed parts down, `x,y,z` (a list or a comma-separated string), model frame.",
        needs: "`robot`", applies: Both, group: Robot, value_name: "X,Y,Z",
        derived: "0.5 m to the robot's side, 0.4 m above the floor", python: "str | Sequence[float]",
    }
    replans: Option<usize> {
        help: "`k`: path plans per grasp, the shortest kept (simulation steps of the optimiser plan once).",
        needs: "`robot`", applies: Both, group: Robot, kind: Int, default: || json!(asp_robot::RemovalConfig::default().replans), python: "int",
    }
    grippers: Option<usize> {
        help: "Grippers in all: up to N-1 parts already in place may be held (by a second gripper or a fixture) while the next part goes in, so states that stand only while held are allowed (the plan's steps say which parts are held).",
        group: Robot, kind: Int, value_name: "N", default: || json!(1), python: "int",
    }
    package_path: Vec<String> {
        help: "Where a URDF's `package://NAME/` meshes lie, `NAME=DIR` each (on the command line repeat the flag).",
        needs: "`robot`", applies: Both, group: Robot, flag: Repeat, value_name: "NAME=DIR", default: || json!([]), python: "Sequence[str]",
    }
}
