//! What every picture shows: the model loaded for a plan, the steps in assembly order with their
//! insertion motions in metres, the parts present before the first step, and the stuck parts of
//! a `no_plan` explanation.

use crate::error::{Result, VizError};
use asp_geom::io::{load, LoadOptions};
use asp_geom::math::{aabb_of, Axis, Pose, Rot, Vec3};
use asp_geom::{Assembly, Units};
use asp_search::report::{MotionEntry, PlanReport, SubassemblyStatus};
use std::path::{Path, PathBuf};

/// Reads and parses a plan JSON (`docs/plan-format.md`); a plan of another major format
/// version is refused before its fields are read.
pub fn read_plan(path: &Path) -> Result<PlanReport> {
    let text = std::fs::read_to_string(path).map_err(|e| VizError::io(path, e))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| VizError::input(path, format!("not a plan JSON: {e}")))?;
    let ours = asp_search::report::FORMAT_VERSION;
    let major = |v: &str| v.split('.').next().map(str::to_string);
    match value.get("format_version").and_then(|v| v.as_str()) {
        Some(v) if major(v) == major(ours) => {}
        Some(v) => {
            return Err(VizError::input(
                path,
                format!("plan format version {v} is not one this asp reads ({ours}); plan the model again with this asp"),
            ))
        }
        None => return Err(VizError::input(path, "not a plan JSON: it has no format_version")),
    }
    serde_json::from_value(value).map_err(|e| VizError::input(path, format!("not a plan JSON: {e}")))
}

/// Where the plan's model is: `model` when given, else the plan's `model` field as written
/// (relative to the working directory, as `asp plan` was given it) or, when that does not
/// exist, relative to the plan file's folder.
pub fn model_path(report: &PlanReport, plan_path: &Path, model: Option<&Path>) -> Result<PathBuf> {
    if let Some(m) = model {
        return Ok(m.to_path_buf());
    }
    let given = PathBuf::from(&report.model);
    if given.exists() {
        return Ok(given);
    }
    if given.is_relative() {
        if let Some(dir) = plan_path.parent() {
            let beside = dir.join(&given);
            if beside.exists() {
                return Ok(beside);
            }
        }
    }
    Err(VizError::input(plan_path, format!("the plan's model '{}' does not exist (give the model with --model)", report.model)))
}

/// Loads the plan's model with the plan's `units`, `up` and fixed parts, and checks that its
/// parts are the plan's parts.
pub fn load_model(report: &PlanReport, plan_path: &Path, model: Option<&Path>) -> Result<Assembly> {
    let path = model_path(report, plan_path, model)?;
    let unit = Units::parse(&report.units).ok_or_else(|| VizError::input(plan_path, format!("unknown unit '{}'", report.units)))?;
    let up = Axis::parse(&report.up).ok_or_else(|| VizError::input(plan_path, format!("'{}' is not an up axis", report.up)))?;
    let fixed = report.parts.iter().filter(|p| p.fixed).map(|p| p.name.clone()).collect();
    let mut options = LoadOptions { unit: Some(unit), up: Some(up), fixed, ..LoadOptions::default() };
    if asp_geom::io::step::is_step(&path) {
        // a STEP file names its unit, and is tessellated again as the plan records
        options.unit = None;
        if let Some(t) = report.parts.iter().find_map(|p| p.tessellation.as_ref()) {
            options.tessellation = asp_geom::io::Tessellation { relative: t.relative, angular: t.angular };
        }
    }
    let assembly = load(&path, &options)?;
    check_parts(&assembly, report, &path)?;
    Ok(assembly)
}

/// The model's parts must be the plan's parts, in the same order.
fn check_parts(assembly: &Assembly, report: &PlanReport, model: &Path) -> Result<()> {
    if assembly.parts.len() != report.parts.len() {
        return Err(VizError::input(
            model,
            format!("the model has {} parts but the plan lists {}", assembly.parts.len(), report.parts.len()),
        ));
    }
    for (i, (a, p)) in assembly.parts.iter().zip(&report.parts).enumerate() {
        if a.name != p.name {
            return Err(VizError::input(model, format!("part {i} of the model is '{}' but the plan calls it '{}'", a.name, p.name)));
        }
    }
    Ok(())
}

/// An insertion motion in metres, ending in the assembled pose (`s = 1`).
#[derive(Clone, Debug, PartialEq)]
pub enum Insertion {
    /// From `distance` away along `-direction`, straight into place.
    Linear {
        /// Unit insertion direction.
        direction: Vec3,
        /// Travel, metres.
        distance: f32,
    },
    /// Through `poses` (rigid transforms of the assembled geometry, the last the identity);
    /// between waypoints `pivot` moves straight while the rotation turns by slerp about it
    /// (`docs/plan-format.md`, "Motions").
    Path {
        /// Waypoints, metres.
        poses: Vec<Pose>,
        /// The point that moves straight, metres.
        pivot: Vec3,
        /// How much time a rotation takes: a turn by `a` radians counts as a travel of
        /// `a * radius` (the part's half diagonal), so turning in place is animated too.
        radius: f32,
    },
}

impl Insertion {
    /// The motion of a plan step in metres; `radius` is the part's half diagonal (metres).
    pub fn from_entry(entry: &MotionEntry, metres_per_unit: f64, radius: f32) -> Insertion {
        let m = |v: f64| (v * metres_per_unit) as f32;
        match entry {
            // a screw's turn about its own axis is not drawn: the part is nearly symmetric about it
            MotionEntry::Linear { direction, distance } | MotionEntry::Screw { direction, distance, .. } => {
                let d = Vec3::new(direction[0] as f32, direction[1] as f32, direction[2] as f32);
                Insertion::Linear { direction: d.normalize_or_zero(), distance: m(*distance) }
            }
            MotionEntry::Path { poses, pivot } => Insertion::Path {
                poses: poses
                    .iter()
                    .map(|p| {
                        let r = Rot::from_xyzw(p[3] as f32, p[4] as f32, p[5] as f32, p[6] as f32).normalize();
                        Pose::from_parts(Vec3::new(m(p[0]), m(p[1]), m(p[2])), r)
                    })
                    .collect(),
                pivot: Vec3::new(m(pivot[0]), m(pivot[1]), m(pivot[2])),
                radius,
            },
        }
    }

    /// The pose of the part a fraction `s` (0 = outside, 1 = assembled) through the motion.
    /// Path waypoints are timed by the pivot's travel plus the turn times the radius.
    pub fn pose_at(&self, s: f32) -> Pose {
        let s = s.clamp(0.0, 1.0);
        match self {
            Insertion::Linear { direction, distance } => Pose::from_translation(-*direction * *distance * (1.0 - s)),
            Insertion::Path { poses, pivot, radius } => {
                if poses.is_empty() {
                    return Pose::IDENTITY;
                }
                if poses.len() == 1 {
                    return poses[0];
                }
                let weights: Vec<f32> = poses.windows(2).map(|w| segment_weight(&w[0], &w[1], *pivot, *radius)).collect();
                let total: f32 = weights.iter().sum();
                if total <= 0.0 {
                    return *poses.last().unwrap_or(&Pose::IDENTITY);
                }
                let mut left = s * total;
                for (i, w) in weights.iter().enumerate() {
                    if left <= *w || i + 1 == weights.len() {
                        let f = if *w > 0.0 { (left / w).clamp(0.0, 1.0) } else { 1.0 };
                        return asp_geom::feasibility::interpolate_about(*pivot, &poses[i], &poses[i + 1], f);
                    }
                    left -= w;
                }
                *poses.last().unwrap_or(&Pose::IDENTITY)
            }
        }
    }

    /// Where `point` (assembled, metres) is at `samples + 1` evenly spaced times of the motion,
    /// from outside to assembled: the curve drawn as the motion's arrow.
    pub fn trace(&self, point: Vec3, samples: usize) -> Vec<Vec3> {
        let samples = match self {
            Insertion::Linear { .. } => 1,
            Insertion::Path { .. } => samples.max(1),
        };
        (0..=samples).map(|k| self.pose_at(k as f32 / samples as f32).transform_point(point)).collect()
    }
}

/// The time a path segment takes: the pivot's travel plus the turn times `radius`.
fn segment_weight(a: &Pose, b: &Pose, pivot: Vec3, radius: f32) -> f32 {
    let travel = (b.transform_point(pivot) - a.transform_point(pivot)).length();
    let turn = a.rotation.angle_between(b.rotation);
    travel + turn * radius
}

/// A rigid slide, in a grid plan, of parts already in place (docs/plan-format.md, "Grid plans").
#[derive(Clone, Debug, PartialEq)]
pub struct Move {
    /// The parts that move together.
    pub parts: Vec<usize>,
    /// Their translation, metres, model frame.
    pub translation: Vec3,
}

/// The time a move takes in the pictures' timelines, as a fraction of an insertion's.
pub const MOVE_TIME: f32 = 0.5;

/// One step of the pictures: a part, or a subassembly, going in.
#[derive(Clone, Debug)]
pub struct Step {
    /// Part index (a subassembly's base).
    pub part: usize,
    /// Every part that goes in with this motion: `[part]`, or a subassembly's parts (built
    /// beforehand, moving together).
    pub parts: Vec<usize>,
    /// Part name.
    pub name: String,
    /// Its insertion motion; `None` for the partial sequence of a `no_plan` or
    /// `budget_exhausted` plan, which records the order but not the motions.
    pub motion: Option<Insertion>,
    /// The moves made after the step goes in, in order (grid plans; usually none).
    pub moves: Vec<Move>,
}

impl Step {
    /// The length of the step's timeline: its insertion (1), then each move ([`MOVE_TIME`]).
    pub fn duration(&self) -> f32 {
        1.0 + MOVE_TIME * self.moves.len() as f32
    }
}

/// A plan with its model: what every picture draws.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The model, metres, world frame, parts in their assembled poses.
    pub assembly: Assembly,
    /// The plan.
    pub report: PlanReport,
    /// The steps in assembly order.
    pub steps: Vec<Step>,
    /// The parts present before the first step: the base (fixed parts), or for a plan that was
    /// not found the deepest dead end (the explanation's parts; without an explanation the
    /// parts the last branch did not remove).
    pub initial: Vec<usize>,
    /// The parts the plan's `explanation` names as stuck (`no_plan`), or its locked cores (`partial`).
    pub stuck: Vec<usize>,
    /// Metres per model unit (the plan's `units`).
    pub metres_per_unit: f64,
    /// Whether the steps' order is the plan's. It is not for a `no_plan` whose last branch
    /// (`disassembly_sequence`) does not lead to the dead end its explanation describes: the
    /// steps then list the other parts in index order.
    pub order_recorded: bool,
}

impl Scene {
    /// Reads the plan at `plan_path` and loads its model (`model` overrides the plan's path).
    pub fn from_plan_file(plan_path: &Path, model: Option<&Path>) -> Result<Scene> {
        let report = read_plan(plan_path)?;
        let assembly = load_model(&report, plan_path, model)?;
        Scene::new(assembly, report, plan_path)
    }

    /// The scene of `report` on `assembly` (whose parts must be the plan's; `source` names
    /// the plan in errors).
    pub fn new(assembly: Assembly, report: PlanReport, source: &Path) -> Result<Scene> {
        check_parts(&assembly, &report, source)?;
        let n = assembly.parts.len();
        let bad = |i: usize| VizError::input(source, format!("the plan names part {i}, but the model has {n} parts"));
        let metres = Units::parse(&report.units).ok_or_else(|| VizError::input(source, format!("unknown unit '{}'", report.units)))?.metres;
        let mut order_recorded = true;
        // plans since format 1.3 carry the partial disassembly of a failed search with its motions
        let sequence = if report.status.has_sequence() { &report.assembly_sequence } else { &report.partial_assembly_sequence };
        let steps: Vec<Step> = if report.status.has_sequence() || !sequence.is_empty() {
            sequence
                .iter()
                .map(|s| {
                    let part = assembly.parts.get(s.part).ok_or_else(|| bad(s.part))?;
                    let radius = aabb_of(part.mesh.vertices.iter().copied()).map(|b| (b.maxs - b.mins).length() / 2.0).unwrap_or(0.0);
                    let parts = s.subassembly.as_ref().map_or_else(|| vec![s.part], |g| g.parts.clone());
                    if let Some(&p) = parts.iter().find(|&&p| p >= n) {
                        return Err(bad(p));
                    }
                    let name = match &s.subassembly {
                        None => part.name.clone(),
                        Some(g) if matches!(g.status, SubassemblyStatus::Found | SubassemblyStatus::Partial) => {
                            format!("{} + {} parts (subassembly)", part.name, g.parts.len() - 1)
                        }
                        Some(g) if g.status == SubassemblyStatus::Unit => {
                            format!("{} + {} parts (declared one unit)", part.name, g.parts.len() - 1)
                        }
                        Some(g) => format!("{} + {} parts (subassembly, locked core: goes in as one unit)", part.name, g.parts.len() - 1),
                    };
                    let mut moves = Vec::with_capacity(s.moves.len());
                    for m in &s.moves {
                        if let Some(&p) = m.parts.iter().find(|&&p| p >= n) {
                            return Err(bad(p));
                        }
                        let t = m.translation.map(|c| (c * metres) as f32);
                        moves.push(Move { parts: m.parts.clone(), translation: Vec3::new(t[0], t[1], t[2]) });
                    }
                    Ok(Step { part: s.part, parts, name, motion: Some(Insertion::from_entry(&s.motion, metres, radius)), moves })
                })
                .collect::<Result<_>>()?
        } else {
            // Older plans (format < 1.3) have no partial sequence. The explanation lists every
            // movable part of the deepest dead end; with the fixed parts that is the starting
            // scene. `disassembly_sequence` is the branch the search was on last, which leads
            // there only when its complement is that dead end (after a full backtrack it is
            // empty); the other parts follow in index order, and the scene says the order is
            // not recorded.
            let complement: Vec<usize> = (0..n).filter(|i| !report.disassembly_sequence.contains(i)).collect();
            let mut core: Vec<usize> = report.explanation.iter().map(|e| e.part).filter(|&p| p < n).collect();
            if core.is_empty() {
                core = complement.clone();
            } else {
                core.extend((0..n).filter(|&i| report.parts[i].fixed)); // never removed
            }
            core.sort_unstable();
            core.dedup();
            order_recorded = complement == core;
            let mut order: Vec<usize> = Vec::new();
            for &p in report.disassembly_sequence.iter().rev() {
                if p >= n {
                    return Err(bad(p));
                }
                if !core.contains(&p) && !order.contains(&p) {
                    order.push(p);
                }
            }
            let rest: Vec<usize> = (0..n).filter(|i| !core.contains(i) && !order.contains(i)).collect();
            order.extend(rest);
            order
                .into_iter()
                .map(|p| Step { part: p, parts: vec![p], name: assembly.parts[p].name.clone(), motion: None, moves: Vec::new() })
                .collect()
        };
        let mut placed = vec![false; n];
        for &p in steps.iter().flat_map(|s| &s.parts) {
            if std::mem::replace(&mut placed[p], true) {
                return Err(VizError::input(source, format!("the plan inserts part {p} twice")));
            }
        }
        let initial = (0..n).filter(|&i| !placed[i]).collect();
        // the parts a plan could not take apart: a dead end's, or a partial plan's locked cores
        let mut stuck: Vec<usize> = report.explanation.iter().map(|e| e.part).filter(|&p| p < n).collect();
        stuck.extend(report.locked_cores.iter().flat_map(|c| c.parts.iter().copied()).filter(|&p| p < n));
        stuck.sort_unstable();
        stuck.dedup();
        Ok(Scene { assembly, report, steps, initial, stuck, metres_per_unit: metres, order_recorded })
    }

    /// Where part `i` sits, relative to its assembled pose, once step `k` went in and the first
    /// `done` of its moves are made: minus the translation of every later move that names it
    /// (docs/plan-format.md, "Grid plans"). Zero when no later move names it, so always after
    /// the last step, and for every plan without moves. `k == steps.len()` is the end.
    pub fn offset(&self, i: usize, k: usize, done: usize) -> Vec3 {
        let mut d = Vec3::ZERO;
        for (j, step) in self.steps.iter().enumerate().skip(k) {
            for m in step.moves.iter().skip(if j == k { done } else { 0 }) {
                if m.parts.contains(&i) {
                    d -= m.translation;
                }
            }
        }
        d
    }

    /// The pose of part `i` (in place, or going in with step `k`) at time `u` of step `k`'s
    /// timeline (0 ..= [`Step::duration`]): the step's parts follow its insertion while
    /// `u ≤ 1`, then its moves slide their parts in turn, [`MOVE_TIME`] each; every other part
    /// rests where the moves so far left it ([`Scene::offset`]). Which parts are visible is
    /// the caller's business.
    pub fn pose_during(&self, k: usize, u: f32, i: usize) -> Pose {
        let step = &self.steps[k];
        let (done, f) = if u <= 1.0 {
            (0, 0.0)
        } else {
            let w = (u - 1.0) / MOVE_TIME;
            let j = (w.floor().max(0.0) as usize).min(step.moves.len());
            (j, if j < step.moves.len() { (w - j as f32).clamp(0.0, 1.0) } else { 0.0 })
        };
        let mut t = self.offset(i, k, done);
        if let Some(m) = step.moves.get(done) {
            if f > 0.0 && m.parts.contains(&i) {
                t += m.translation * f;
            }
        }
        let base = match &step.motion {
            Some(m) if step.parts.contains(&i) => m.pose_at(u.min(1.0)),
            _ => Pose::IDENTITY,
        };
        Pose::from_parts(base.translation + t, base.rotation)
    }

    /// Whether part `i` is a base part (fixed in the plan).
    pub fn is_base(&self, i: usize) -> bool {
        self.report.parts.get(i).is_some_and(|p| p.fixed)
    }

    /// The model's box (metres) including every motion's start, so pictures fit every pose.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut points: Vec<Vec3> = Vec::new();
        if let Some(b) = self.assembly.aabb() {
            points.push(b.mins);
            points.push(b.maxs);
        }
        for (k, s) in self.steps.iter().enumerate() {
            for &p in &s.parts {
                if let (Some(_), Some(b)) = (&s.motion, self.assembly.parts[p].mesh.aabb()) {
                    for j in 0..=8 {
                        let pose = self.pose_during(k, j as f32 / 8.0, p);
                        for c in corners(b.mins, b.maxs) {
                            points.push(pose.transform_point(c));
                        }
                    }
                }
            }
        }
        match aabb_of(points) {
            Some(b) => (b.mins, b.maxs),
            None => (Vec3::ZERO, Vec3::ZERO),
        }
    }
}

/// The eight corners of a box.
pub(crate) fn corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    let mut out = [Vec3::ZERO; 8];
    for (k, c) in out.iter_mut().enumerate() {
        *c = Vec3::new(if k & 1 == 0 { lo.x } else { hi.x }, if k & 2 == 0 { lo.y } else { hi.y }, if k & 4 == 0 { lo.z } else { hi.z });
    }
    out
}

/// An sRGB colour, 0-255 per channel.
pub type Rgb = [u8; 3];

/// The colour of placed parts in storyboards.
pub const GREY: Rgb = [176, 180, 186];
/// The colour of base (fixed) parts.
pub const BASE: Rgb = [84, 110, 140];
/// The colour of stuck parts of a `no_plan` explanation.
pub const STUCK: Rgb = [214, 40, 40];

/// A distinct, saturated colour for part `i` (golden-ratio hues; never grey, never the stuck
/// red, never the base blue-grey).
pub fn part_colour(i: usize) -> Rgb {
    let hue = (0.13 + i as f32 * 0.618_034).fract();
    // keep away from pure red (the stuck colour): hues within 0.04 of 0 are shifted
    let hue = if !(0.04..=0.96).contains(&hue) { hue + 0.08 } else { hue };
    hsv(hue.fract(), 0.75, 0.92)
}

fn hsv(h: f32, s: f32, v: f32) -> Rgb {
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - f * s), v * (1.0 - (1.0 - f) * s));
    let (r, g, b) = match i as i32 % 6 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [(r * 255.0).round() as u8, (g * 255.0).round() as u8, (b * 255.0).round() as u8]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_insertions_start_outside_and_end_in_place() {
        let m = Insertion::from_entry(&MotionEntry::Linear { direction: [0.0, 0.0, -1.0], distance: 50.0 }, 0.001, 0.1);
        let start = m.pose_at(0.0).translation;
        assert!((start - Vec3::new(0.0, 0.0, 0.05)).length() < 1e-6, "{start:?}");
        assert!(m.pose_at(1.0).translation.length() < 1e-9);
        assert!((m.pose_at(0.5).translation.z - 0.025).abs() < 1e-6);
    }

    #[test]
    fn path_insertions_follow_the_documented_interpolation() {
        // pivot at (1,0,0); first waypoint: turned 90° about z and lifted by 2; then identity
        let q = Rot::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let entry = MotionEntry::Path {
            poses: vec![[0.0, 0.0, 2.0, q.x as f64, q.y as f64, q.z as f64, q.w as f64], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]],
            pivot: [1.0, 0.0, 0.0],
        };
        let m = Insertion::from_entry(&entry, 1.0, 1.0);
        let pivot = Vec3::new(1.0, 0.0, 0.0);
        // the pivot's image moves on the straight line from q*pivot + (0,0,2) to the pivot
        let a = Pose::from_parts(Vec3::new(0.0, 0.0, 2.0), q).transform_point(pivot);
        let half = m.pose_at(0.5).transform_point(pivot);
        assert!((half - a.lerp(pivot, 0.5)).length() < 1e-5, "{half:?}");
        assert!(m.pose_at(1.0).transform_point(Vec3::new(3.0, 1.0, 0.0)).distance(Vec3::new(3.0, 1.0, 0.0)) < 1e-5);
        assert_eq!(m.trace(pivot, 4).len(), 5);
    }

    #[test]
    fn part_colours_are_saturated_and_not_the_stuck_red() {
        for i in 0..200 {
            let c = part_colour(i);
            let (max, min) = (*c.iter().max().unwrap() as i32, *c.iter().min().unwrap() as i32);
            assert!(max - min > 100, "{c:?} is too grey");
            assert_ne!(c, STUCK);
        }
    }
}
