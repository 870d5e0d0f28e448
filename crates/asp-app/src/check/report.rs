//! The check report (docs/check-format.md): the JSON contract `asp check` and
//! `asp.Assembly.check` write, and its text table. Kept apart from the checking itself so the
//! format's types and their rendering change together, in one file.

use asp_search::report::{MotionEntry, NamedPart, RobotEntry, RobotStepEntry};
use serde::{Deserialize, Serialize};

/// The version of the check report this build writes (docs/check-format.md). Minor bumps add
/// keys; major bumps change or remove them.
pub const CHECK_FORMAT_VERSION: &str = "1.1";

/// Whether the check found the sequence feasible.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckStatus {
    /// Every step goes in.
    Feasible,
    /// Some step does not.
    Infeasible,
}

/// The check report (docs/check-format.md).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CheckReport {
    /// [`CHECK_FORMAT_VERSION`].
    pub format_version: String,
    /// The model file or folder, as given.
    pub model: String,
    /// The model's unit; lengths below are in it.
    pub units: String,
    /// The up axis.
    pub up: String,
    /// `feasible` or `infeasible`.
    pub status: CheckStatus,
    /// The base parts: in place before the first step (the ground too when no part is fixed).
    pub base: Vec<NamedPart>,
    /// Every step in assembly order, tested.
    pub steps: Vec<CheckStep>,
    /// The first failing step's index in `steps` (assembly order), when infeasible.
    pub first_failure: Option<usize>,
    /// When infeasible: the nearest feasible sequence found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repair: Option<Repair>,
    /// The robot the steps were checked for (`--robot`), as the plan JSON's. Since 1.1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotEntry>,
    /// Remarks about the input (base parts listed as steps).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Warnings about the model (as the plan's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Effort.
    pub stats: CheckStats,
}

/// One tested step.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CheckStep {
    /// Its index in assembly order (0 goes in first).
    pub step: usize,
    /// Its parts (several: a rigid subassembly, built beforehand).
    pub parts: Vec<NamedPart>,
    /// The insertion direction given with it (unit, model frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub given_direction: Option<[f64; 3]>,
    /// Whether it goes in.
    pub feasible: bool,
    /// How it goes in (the insertion motion, as the plan JSON's), when feasible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionEntry>,
    /// Why it does not, when infeasible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<Failure>,
    /// How the robot takes it out (`--robot`), when every step is feasible: grasp, gripper path,
    /// joint trajectory, as the plan JSON's step `robot`. Since 1.1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotStepEntry>,
    /// The parts held in place while the rest stands without it (`--grippers N`), when every
    /// step is feasible. Since 1.1.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<NamedPart>,
}

/// Why a step fails.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Failure {
    /// Every straight motion tried collides (along the given direction, when one was given).
    Blocked {
        /// Whether only the given direction was tried.
        along_given: bool,
        /// Per insertion direction tried, the parts already in place it collides with.
        directions: Vec<DirectionBlockers>,
        /// Every blocker of every direction.
        blockers: Vec<NamedPart>,
        /// With a given direction: the candidate insertion directions that are free instead.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        free_directions: Vec<[f64; 3]>,
    },
    /// Every straight motion collides and the path planner found no path either.
    NoPath {
        /// Per insertion direction, the parts it collides with.
        directions: Vec<DirectionBlockers>,
        /// Every blocker of every direction.
        blockers: Vec<NamedPart>,
    },
    /// The step goes in along `motion`, but the state before it does not stand: `floating` parts
    /// are not supported without it (in disassembly terms: removing it leaves them unsupported).
    Unstable {
        /// The parts left without support.
        floating: Vec<NamedPart>,
        /// The free insertion motion.
        motion: MotionEntry,
    },
    /// The parts are free to go in along `motion`, but the robot cannot carry the step out (in
    /// disassembly terms): `robot_reason` says why (`no reachable grasp`, `no path`, `blocked`:
    /// the arm would hit a part; a group: the robot carries one part at a time). Since 1.1.
    Robot {
        /// The robot's reason.
        robot_reason: String,
        /// The parts' own free insertion motion.
        motion: MotionEntry,
    },
}

impl Failure {
    /// The reason's name (`blocked`, `no_path`, `unstable`).
    pub fn reason(&self) -> &'static str {
        match self {
            Failure::Blocked { .. } => "blocked",
            Failure::NoPath { .. } => "no_path",
            Failure::Unstable { .. } => "unstable",
            Failure::Robot { .. } => "robot",
        }
    }
}

/// The blockers of one insertion direction.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DirectionBlockers {
    /// Unit insertion direction, model frame.
    pub direction: [f64; 3],
    /// The parts in place that it collides with (a motion along it pushes into them).
    pub blockers: Vec<NamedPart>,
}

/// How the repair search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RepairStatus {
    /// A feasible sequence of the given steps.
    Found,
    /// No order of the given steps is feasible (with these settings).
    None,
    /// The budget (`max_tests`, `timeout`) ran out first.
    BudgetExhausted,
}

/// The nearest feasible sequence found.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Repair {
    /// How the search ended.
    pub status: RepairStatus,
    /// The feasible sequence in assembly order (empty unless `found`).
    pub sequence: Vec<RepairStep>,
    /// Steps moved: the number of steps minus the longest common subsequence of the two orders.
    pub moved: usize,
    /// The Kendall tau distance: pairs of steps the repair puts in the other order.
    pub kendall_tau: usize,
    /// Removal tests the search ran.
    pub removal_tests: u64,
}

/// One step of the repair.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RepairStep {
    /// Its parts.
    pub parts: Vec<NamedPart>,
    /// Its index in the given sequence.
    pub given_step: usize,
    /// Whether it is one of the moved steps (not in the longest common subsequence).
    pub moved: bool,
    /// How it goes in.
    pub motion: MotionEntry,
    /// How the robot takes it out (`--robot`). Since 1.1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotStepEntry>,
    /// The parts held in place (`--grippers N`). Since 1.1.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<NamedPart>,
}

/// Effort.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct CheckStats {
    /// Removal tests of the check and the repair.
    pub removal_tests: u64,
    /// Wall time, seconds (loading and the world included).
    pub seconds: f64,
}

impl CheckReport {
    /// The report as JSON: pretty-printed, with a final newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("check reports serialise");
        s.push('\n');
        s
    }

    /// Whether the sequence is feasible.
    pub fn feasible(&self) -> bool {
        self.status == CheckStatus::Feasible
    }

    /// The report as text: a line per step, the first failure with its reason, the repair with
    /// its moved steps marked `*`.
    pub fn to_text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let names = |ps: &[NamedPart]| ps.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ");
        let label = |ps: &[NamedPart]| if ps.len() == 1 { ps[0].name.clone() } else { format!("[{}]", names(ps)) };
        let _ = writeln!(s, "model: {} ({} steps onto {})", self.model, self.steps.len(), names(&self.base));
        if let Some(r) = &self.robot {
            let _ = writeln!(s, "robot: {} (every step carried out by the arm; path lengths below are the arm's, in disassembly)", r.name);
        }
        for st in &self.steps {
            let what = match (&st.motion, &st.failure) {
                (Some(m), _) => format!("ok, in {}{}", motion_text(m, &self.units), robot_text(st.robot.as_ref(), &st.held, &self.units)),
                (None, Some(f)) => failure_text(f),
                _ => String::new(),
            };
            let _ = writeln!(s, "  {:>3}. {:<24} {what}", st.step + 1, label(&st.parts));
        }
        match self.first_failure {
            None => {
                let _ = writeln!(s, "feasible: every step goes in");
            }
            Some(k) => {
                let st = &self.steps[k];
                let why = st.failure.as_ref().map(failure_text).unwrap_or_default();
                let _ = writeln!(s, "infeasible: step {} ({}) fails: {why}", k + 1, label(&st.parts));
            }
        }
        if let Some(r) = &self.repair {
            match r.status {
                RepairStatus::Found => {
                    let _ = writeln!(
                        s,
                        "nearest feasible sequence ({} step{} moved, Kendall tau distance {}; * marks a moved step):",
                        r.moved,
                        if r.moved == 1 { "" } else { "s" },
                        r.kendall_tau
                    );
                    for (i, st) in r.sequence.iter().enumerate() {
                        let mark = if st.moved { "*" } else { " " };
                        let _ = writeln!(
                            s,
                            "  {mark}{:>3}. {:<24} in {}{} (given as step {})",
                            i + 1,
                            label(&st.parts),
                            motion_text(&st.motion, &self.units),
                            robot_text(st.robot.as_ref(), &st.held, &self.units),
                            st.given_step + 1
                        );
                    }
                }
                RepairStatus::None => {
                    let _ = writeln!(s, "no order of these steps is feasible");
                }
                RepairStatus::BudgetExhausted => {
                    let _ = writeln!(s, "no feasible order found within the budget");
                }
            }
        }
        for n in &self.notes {
            let _ = writeln!(s, "note: {n}");
        }
        s
    }
}

/// A direction as `+z` when it is an axis, else its three components.
fn direction_text(d: &[f64; 3]) -> String {
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        if (d[i].abs() - 1.0).abs() < 1e-6 {
            return format!("{}{axis}", if d[i] > 0.0 { "+" } else { "-" });
        }
    }
    format!("({:.3}, {:.3}, {:.3})", d[0], d[1], d[2])
}

fn motion_text(m: &MotionEntry, units: &str) -> String {
    match m {
        MotionEntry::Linear { direction, distance } => format!("along {} ({distance:.4} {units})", direction_text(direction)),
        MotionEntry::Screw { direction, distance, .. } => format!("screwed along {} ({distance:.4} {units})", direction_text(direction)),
        MotionEntry::Path { poses, .. } => format!("along a path of {} poses", poses.len()),
    }
}

/// `, robot path 0.412 m` (and the held parts) for a step the robot carries out.
fn robot_text(robot: Option<&RobotStepEntry>, held: &[NamedPart], units: &str) -> String {
    let mut s = robot.map(|r| format!(", robot path {:.3} {units}", r.path_length)).unwrap_or_default();
    if !held.is_empty() {
        s += &format!(", holding {}", held.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", "));
    }
    s
}

fn motion_dir_text(m: &MotionEntry) -> String {
    match m {
        MotionEntry::Linear { direction, .. } | MotionEntry::Screw { direction, .. } => direction_text(direction),
        MotionEntry::Path { poses, .. } => format!("a path of {} poses", poses.len()),
    }
}

fn failure_text(f: &Failure) -> String {
    let names = |ps: &[NamedPart]| ps.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ");
    let per_dir = |ds: &[DirectionBlockers]| {
        let shown: Vec<String> = ds
            .iter()
            .filter(|d| !d.blockers.is_empty())
            .take(6)
            .map(|d| format!("{} by {}", direction_text(&d.direction), names(&d.blockers)))
            .collect();
        let more = ds.iter().filter(|d| !d.blockers.is_empty()).count().saturating_sub(shown.len());
        let tail = if more > 0 { format!("; {more} more directions") } else { String::new() };
        format!("{}{tail}", shown.join("; "))
    };
    match f {
        Failure::Blocked { along_given: true, directions, free_directions, .. } => {
            let free = if free_directions.is_empty() {
                String::new()
            } else {
                format!(" (free instead: {})", free_directions.iter().map(direction_text).collect::<Vec<_>>().join(", "))
            };
            format!("blocked along the given direction: {}{free}", per_dir(directions))
        }
        Failure::Blocked { blockers, directions, .. } => {
            format!("blocked by {} (insertion {})", names(blockers), per_dir(directions))
        }
        Failure::NoPath { blockers, directions } => {
            format!("blocked by {} along every straight line (insertion {}) and no path found", names(blockers), per_dir(directions))
        }
        Failure::Unstable { floating, .. } => format!("unstable: {}, placed before it, would not be supported without it", names(floating)),
        Failure::Robot { robot_reason, motion } => {
            format!("the parts go in along {}, but the robot cannot: {robot_reason}", motion_dir_text(motion))
        }
    }
}
