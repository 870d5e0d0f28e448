//! `asp plan --mcap`: the assembly animated over time as an MCAP file for Foxglove, in
//! Foxglove's published JSON schemas.
//!
//! Topics (JSON encoding, schema encoding `jsonschema`):
//! - [`TOPIC_PARTS`] (`foxglove.SceneUpdate`): one entity per part (`part/<index>`, a triangle
//!   list in the part's own frame, its name as metadata and as a text label). The parts present
//!   at the start come first; each step adds its part when it starts to move.
//! - [`TOPIC_TRANSFORMS`] (`foxglove.FrameTransforms`): `world` → `model` (turns the model's up
//!   axis to Foxglove's +z, once), and `model` → `part/<index>`, the part's pose along its
//!   insertion motion, [`McapOptions::rate`] times a second while it moves, and after it the
//!   step's grid moves (each slides its parts in turn, [`MOVE_TIME`] of a step each;
//!   docs/plan-format.md, "Grid plans").
//! - [`TOPIC_PATHS`] (`foxglove.SceneUpdate`): the insertion path of each step's part (the
//!   centre of its bounds), a line strip entity `path/<index>` in the `model` frame, published
//!   when the step starts. Removal paths are the same curves run backwards.
//!
//! Lengths are metres; log times start at 0 and increase.

use crate::error::{Result, VizError};
use crate::scene::{part_colour, Rgb, Scene, BASE, MOVE_TIME, STUCK};
use asp_geom::math::{Axis, Pose, Rot, Vec3};
use asp_geom::Assembly;
use asp_search::report::PlanReport;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// The parts, as `foxglove.SceneUpdate`.
pub const TOPIC_PARTS: &str = "/asp/parts";
/// The motion paths, as `foxglove.SceneUpdate`.
pub const TOPIC_PATHS: &str = "/asp/paths";
/// The parts' poses, as `foxglove.FrameTransforms`.
pub const TOPIC_TRANSFORMS: &str = "/tf";
/// The fixed frame.
pub const FRAME_WORLD: &str = "world";
/// The model's frame (the model's up axis turned to +z).
pub const FRAME_MODEL: &str = "model";
/// Foxglove's JSON schema of `foxglove.SceneUpdate` (npm `@foxglove/schemas` 2.1.0).
pub const SCENE_UPDATE_SCHEMA: &str = include_str!("../assets/foxglove/SceneUpdate.json");
/// Foxglove's JSON schema of `foxglove.FrameTransforms` (npm `@foxglove/schemas` 2.1.0).
pub const FRAME_TRANSFORMS_SCHEMA: &str = include_str!("../assets/foxglove/FrameTransforms.json");

/// The timing of the animation.
#[derive(Clone, Debug)]
pub struct McapOptions {
    /// Seconds per step: the part moves during the first 80 %, then rests. Each grid move
    /// after it takes [`MOVE_TIME`] of this, likewise.
    pub step_seconds: f64,
    /// Poses per second while a part moves.
    pub rate: f64,
}

impl Default for McapOptions {
    fn default() -> Self {
        McapOptions { step_seconds: 2.0, rate: 20.0 }
    }
}

/// What was written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct McapSummary {
    /// Messages per topic.
    pub messages: BTreeMap<String, u64>,
    /// The last log time, nanoseconds.
    pub end_ns: u64,
}

/// Writes the MCAP of a plan found on `assembly` (metres, as the planner saw it) to `path`,
/// with the default timing. This is what `asp plan --mcap FILE` calls.
pub fn write_plan(path: &Path, assembly: &Assembly, report: &PlanReport) -> Result<McapSummary> {
    let scene = Scene::new(assembly.clone(), report.clone(), path)?;
    write_scene(path, &scene, &McapOptions::default())
}

/// Writes the MCAP of `scene` to `path`.
pub fn write_scene(path: &Path, scene: &Scene, options: &McapOptions) -> Result<McapSummary> {
    if !(options.step_seconds > 0.0 && options.step_seconds.is_finite() && options.rate > 0.0 && options.rate.is_finite()) {
        return Err(VizError::output(path, "the step time and the rate must be positive"));
    }
    // written to a temporary file beside `path` and renamed over it at the end: never half a file
    let mut failed = None;
    asp_geom::io::write_atomic_with(path, |file| {
        let file = file.try_clone()?;
        write_mcap(path, scene, options, file).map_err(|e| {
            failed = Some(e);
            std::io::Error::other("mcap")
        })
    })
    .map_err(|e| failed.take().unwrap_or_else(|| VizError::io(path, e)))
}

/// Writes the MCAP of `scene` into `file` (`path` names it in errors).
fn write_mcap(path: &Path, scene: &Scene, options: &McapOptions, file: std::fs::File) -> Result<McapSummary> {
    let err = |e: ::mcap::McapError| VizError::output(path, format!("mcap: {e}"));
    let mut writer = ::mcap::WriteOptions::new()
        .compression(Some(::mcap::Compression::Zstd))
        .profile("")
        .library(concat!("asp-viz ", env!("CARGO_PKG_VERSION")))
        .create(BufWriter::new(file))
        .map_err(err)?;
    let scene_schema = writer.add_schema("foxglove.SceneUpdate", "jsonschema", SCENE_UPDATE_SCHEMA.as_bytes()).map_err(err)?;
    let tf_schema = writer.add_schema("foxglove.FrameTransforms", "jsonschema", FRAME_TRANSFORMS_SCHEMA.as_bytes()).map_err(err)?;
    let none = BTreeMap::new();
    let parts_ch = writer.add_channel(scene_schema, TOPIC_PARTS, "json", &none).map_err(err)?;
    let paths_ch = writer.add_channel(scene_schema, TOPIC_PATHS, "json", &none).map_err(err)?;
    let tf_ch = writer.add_channel(tf_schema, TOPIC_TRANSFORMS, "json", &none).map_err(err)?;

    let mut out = Out { writer, sequence: 0, summary: McapSummary { messages: BTreeMap::new(), end_ns: 0 } };
    let up = Axis::parse(&scene.report.up).map(|a| a.vector()).unwrap_or(Vec3::Z);
    let model_to_world = Rot::from_rotation_arc(up, Vec3::Z);
    let diag = scene.assembly.diagonal();

    // t = 0: the model frame, the parts present at the start
    let mut first = vec![transform(0, FRAME_WORLD, FRAME_MODEL, &Pose::from_parts(Vec3::ZERO, model_to_world))];
    for &i in &scene.initial {
        first.push(transform(0, FRAME_MODEL, &part_frame(i), &Pose::from_translation(scene.offset(i, 0, 0))));
    }
    out.put(tf_ch, TOPIC_TRANSFORMS, 0, &json!({ "transforms": first })).map_err(err)?;
    let entities: Vec<Value> = scene.initial.iter().map(|&i| part_entity(scene, i, 0)).collect();
    out.put(parts_ch, TOPIC_PARTS, 0, &json!({ "deletions": [], "entities": entities })).map_err(err)?;

    let step_ns = (options.step_seconds * 1e9) as u64;
    let move_ns = (options.step_seconds * f64::from(MOVE_TIME) * 1e9) as u64;
    let lead = step_ns / 4;
    let frames = ((options.step_seconds * 0.8 * options.rate).round() as u64).max(1);
    let move_frames = ((options.step_seconds * f64::from(MOVE_TIME) * 0.8 * options.rate).round() as u64).max(1);
    let mut start = lead;
    for (k, step) in scene.steps.iter().enumerate() {
        // a subassembly's parts appear and move together
        let entities: Vec<Value> = step.parts.iter().map(|&i| part_entity(scene, i, start)).collect();
        out.put(parts_ch, TOPIC_PARTS, start, &json!({ "deletions": [], "entities": entities })).map_err(err)?;
        if let Some(motion) = &step.motion {
            let centre = scene.assembly.parts[step.part].mesh.aabb().map(|b| (b.mins + b.maxs) / 2.0).unwrap_or(Vec3::ZERO);
            let offset = scene.offset(step.part, k, 0);
            let curve: Vec<Vec3> = motion.trace(centre, 64).into_iter().map(|p| p + offset).collect();
            out.put(paths_ch, TOPIC_PATHS, start, &json!({ "deletions": [], "entities": [path_entity(step.part, start, &curve, diag)] }))
                .map_err(err)?;
        }
        // the poses of `parts` at time `u` of the step's timeline, logged at `t`
        let mut put_poses = |t: u64, u: f32, parts: &[usize]| {
            let transforms: Vec<Value> =
                parts.iter().map(|&i| transform(t, FRAME_MODEL, &part_frame(i), &scene.pose_during(k, u, i))).collect();
            out.put(tf_ch, TOPIC_TRANSFORMS, t, &json!({ "transforms": transforms }))
        };
        if step.motion.is_some() {
            for j in 0..=frames {
                put_poses(start + j * (step_ns * 4 / 5) / frames, j as f32 / frames as f32, &step.parts).map_err(err)?;
            }
        } else {
            put_poses(start, 1.0, &step.parts).map_err(err)?;
        }
        for (m, mv) in step.moves.iter().enumerate() {
            let begin = start + step_ns + m as u64 * move_ns;
            for j in 0..=move_frames {
                let u = 1.0 + MOVE_TIME * (m as f32 + j as f32 / move_frames as f32);
                put_poses(begin + j * (move_ns * 4 / 5) / move_frames, u, &mv.parts).map_err(err)?;
            }
        }
        start += step_ns + step.moves.len() as u64 * move_ns;
    }
    let Out { mut writer, summary, .. } = out;
    writer.finish().map_err(err)?;
    Ok(summary)
}

/// The writer with its sequence counter and tallies.
struct Out<W: std::io::Write + std::io::Seek> {
    writer: ::mcap::Writer<W>,
    sequence: u32,
    summary: McapSummary,
}

impl<W: std::io::Write + std::io::Seek> Out<W> {
    fn put(&mut self, channel: u16, topic: &str, log_time: u64, message: &Value) -> ::mcap::McapResult<()> {
        let data = serde_json::to_vec(message).unwrap_or_default();
        self.sequence += 1;
        let header = ::mcap::records::MessageHeader { channel_id: channel, sequence: self.sequence, log_time, publish_time: log_time };
        self.writer.write_to_known_channel(&header, &data)?;
        *self.summary.messages.entry(topic.to_string()).or_default() += 1;
        self.summary.end_ns = self.summary.end_ns.max(log_time);
        Ok(())
    }
}

fn part_frame(i: usize) -> String {
    format!("part/{i}")
}

fn time(ns: u64) -> Value {
    json!({ "sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000 })
}

fn colour(rgb: Rgb, a: f32) -> Value {
    json!({ "r": rgb[0] as f32 / 255.0, "g": rgb[1] as f32 / 255.0, "b": rgb[2] as f32 / 255.0, "a": a })
}

fn pose(p: &Pose) -> Value {
    let (t, q) = (p.translation, p.rotation);
    json!({ "position": { "x": t.x, "y": t.y, "z": t.z }, "orientation": { "x": q.x, "y": q.y, "z": q.z, "w": q.w } })
}

fn transform(ns: u64, parent: &str, child: &str, p: &Pose) -> Value {
    let (t, q) = (p.translation, p.rotation);
    json!({
        "timestamp": time(ns),
        "parent_frame_id": parent,
        "child_frame_id": child,
        "translation": { "x": t.x, "y": t.y, "z": t.z },
        "rotation": { "x": q.x, "y": q.y, "z": q.z, "w": q.w },
    })
}

/// An entity with every list the schema requires, empty.
fn entity(ns: u64, frame: &str, id: &str, metadata: Vec<Value>) -> serde_json::Map<String, Value> {
    let mut e = serde_json::Map::new();
    e.insert("timestamp".into(), time(ns));
    e.insert("frame_id".into(), json!(frame));
    e.insert("id".into(), json!(id));
    e.insert("lifetime".into(), json!({ "sec": 0, "nsec": 0 }));
    e.insert("frame_locked".into(), json!(true));
    e.insert("metadata".into(), json!(metadata));
    for list in ["arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"] {
        e.insert(list.into(), json!([]));
    }
    e
}

/// Part `i` as a triangle list in its own frame (assembled coordinates) with a name label.
fn part_entity(scene: &Scene, i: usize, ns: u64) -> Value {
    let part = &scene.assembly.parts[i];
    let rgb = if scene.stuck.contains(&i) {
        STUCK
    } else if scene.is_base(i) {
        BASE
    } else {
        part_colour(i)
    };
    let points: Vec<Value> = part.mesh.vertices.iter().map(|v| json!({ "x": v.x, "y": v.y, "z": v.z })).collect();
    let indices: Vec<u32> = part.mesh.triangles.iter().flatten().copied().collect();
    let centre = part.mesh.aabb().map(|b| (b.mins + b.maxs) / 2.0).unwrap_or(Vec3::ZERO);
    let role = if scene.stuck.contains(&i) {
        "stuck"
    } else if scene.is_base(i) {
        "base"
    } else {
        "part"
    };
    let metadata = vec![json!({ "key": "name", "value": part.name }), json!({ "key": "role", "value": role })];
    let mut e = entity(ns, &part_frame(i), &part_frame(i), metadata);
    e.insert(
        "triangles".into(),
        json!([{ "pose": pose(&Pose::IDENTITY), "points": points, "color": colour(rgb, 1.0), "colors": [], "indices": indices }]),
    );
    e.insert(
        "texts".into(),
        json!([{
            "pose": pose(&Pose::from_translation(centre)),
            "billboard": true,
            "font_size": 14.0,
            "scale_invariant": true,
            "color": colour([29, 35, 48], 1.0),
            "text": part.name,
        }]),
    );
    Value::Object(e)
}

/// The path of part `i`'s centre, a line strip in the model frame.
fn path_entity(i: usize, ns: u64, curve: &[Vec3], diag: f32) -> Value {
    let points: Vec<Value> = curve.iter().map(|p| json!({ "x": p.x, "y": p.y, "z": p.z })).collect();
    let mut e = entity(ns, FRAME_MODEL, &format!("path/{i}"), vec![json!({ "key": "part", "value": i.to_string() })]);
    e.insert("frame_locked".into(), json!(false));
    e.insert(
        "lines".into(),
        json!([{
            "type": 0,
            "pose": pose(&Pose::IDENTITY),
            "thickness": (diag * 0.004).max(1e-4),
            "scale_invariant": false,
            "points": points,
            "color": colour([230, 81, 0], 1.0),
            "colors": [],
            "indices": [],
        }]),
    );
    Value::Object(e)
}
