//! MCAP files read back with the `mcap` crate's reader: topics, schemas, message counts, log
//! times, every message complete for its Foxglove schema, poses that follow the plan.

use crate::common::{planned, stuck_tube};
use asp_geom::fixtures;
use asp_viz::mcap::{write_scene, McapOptions, FRAME_TRANSFORMS_SCHEMA, SCENE_UPDATE_SCHEMA, TOPIC_PARTS, TOPIC_PATHS, TOPIC_TRANSFORMS};
use asp_viz::{Insertion, Scene};
use serde_json::Value;
use std::collections::BTreeMap;

struct Read {
    /// (topic, log time, message) in file order.
    messages: Vec<(String, u64, Value)>,
    schemas: BTreeMap<String, (String, String, String)>,
}

fn read(path: &std::path::Path) -> Read {
    let bytes = std::fs::read(path).unwrap();
    let mut messages = Vec::new();
    let mut schemas = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let schema = m.channel.schema.as_ref().expect("every channel has a schema");
        schemas.insert(m.channel.topic.clone(), (schema.name.clone(), schema.encoding.clone(), m.channel.message_encoding.clone()));
        assert_eq!(
            String::from_utf8_lossy(&schema.data),
            if schema.name == "foxglove.SceneUpdate" { SCENE_UPDATE_SCHEMA } else { FRAME_TRANSFORMS_SCHEMA }
        );
        messages.push((m.channel.topic.clone(), m.log_time, serde_json::from_slice(&m.data).unwrap()));
    }
    Read { messages, schemas }
}

/// Every key the schema lists as `required` is present, recursively.
fn complete(schema: &Value, value: &Value, at: &str) {
    if let (Some(required), Some(obj)) = (schema.get("required").and_then(Value::as_array), value.as_object()) {
        for key in required {
            let key = key.as_str().unwrap();
            assert!(obj.contains_key(key), "{at}: missing '{key}'");
        }
    }
    if let (Some(props), Some(obj)) = (schema.get("properties").and_then(Value::as_object), value.as_object()) {
        for (key, sub) in obj {
            let s = props.get(key).unwrap_or_else(|| panic!("{at}: '{key}' is not in the schema"));
            complete(s, sub, &format!("{at}.{key}"));
        }
    }
    if let (Some(items), Some(list)) = (schema.get("items"), value.as_array()) {
        for (k, v) in list.iter().enumerate() {
            complete(items, v, &format!("{at}[{k}]"));
        }
    }
}

fn check_file(scene: &Scene, options: &McapOptions) -> Read {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.mcap");
    let summary = write_scene(&path, scene, options).unwrap();
    let r = read(&path);
    let scene_schema: Value = serde_json::from_str(SCENE_UPDATE_SCHEMA).unwrap();
    let tf_schema: Value = serde_json::from_str(FRAME_TRANSFORMS_SCHEMA).unwrap();
    assert_eq!(r.schemas[TOPIC_PARTS], ("foxglove.SceneUpdate".into(), "jsonschema".into(), "json".into()));
    assert_eq!(r.schemas[TOPIC_TRANSFORMS], ("foxglove.FrameTransforms".into(), "jsonschema".into(), "json".into()));
    let count = |topic: &str| r.messages.iter().filter(|m| m.0 == topic).count() as u64;
    let moving = scene.steps.iter().filter(|s| s.motion.is_some()).count() as u64;
    let frames = (options.step_seconds * 0.8 * options.rate).round() as u64;
    assert_eq!(count(TOPIC_PARTS), 1 + scene.steps.len() as u64);
    assert_eq!(count(TOPIC_PATHS), moving);
    assert_eq!(count(TOPIC_TRANSFORMS), 1 + moving * (frames + 1) + (scene.steps.len() as u64 - moving));
    for (topic, n) in &summary.messages {
        assert_eq!(count(topic), *n, "{topic}");
    }
    // log times never go back, and strictly increase on each topic
    assert!(r.messages.windows(2).all(|w| w[0].1 <= w[1].1), "log times go back");
    for topic in [TOPIC_PARTS, TOPIC_PATHS, TOPIC_TRANSFORMS] {
        let times: Vec<u64> = r.messages.iter().filter(|m| m.0 == topic).map(|m| m.1).collect();
        assert!(times.windows(2).all(|w| w[0] < w[1]), "{topic}: {times:?}");
    }
    for (topic, t, m) in &r.messages {
        complete(if topic == TOPIC_TRANSFORMS { &tf_schema } else { &scene_schema }, m, topic);
        // header time stamps are the log times
        let stamp = if topic == TOPIC_TRANSFORMS { &m["transforms"][0]["timestamp"] } else { &m["entities"][0]["timestamp"] };
        if !stamp.is_null() {
            assert_eq!(stamp["sec"].as_u64().unwrap() * 1_000_000_000 + stamp["nsec"].as_u64().unwrap(), *t);
        }
    }
    assert_eq!(summary.end_ns, r.messages.last().unwrap().1);
    r
}

#[test]
fn a_found_plan_animates_every_part_along_its_motion() {
    let scene = planned(fixtures::tube());
    let r = check_file(&scene, &McapOptions::default());
    // one entity per part in all, each with a triangle list of the part's mesh
    let entities: Vec<&Value> =
        r.messages.iter().filter(|m| m.0 == TOPIC_PARTS).flat_map(|m| m.2["entities"].as_array().unwrap()).collect();
    assert_eq!(entities.len(), scene.assembly.parts.len());
    for e in &entities {
        let i: usize = e["id"].as_str().unwrap().trim_start_matches("part/").parse().unwrap();
        let tri = &e["triangles"][0];
        assert_eq!(tri["points"].as_array().unwrap().len(), scene.assembly.parts[i].mesh.vertices.len());
        assert_eq!(tri["indices"].as_array().unwrap().len(), 3 * scene.assembly.parts[i].mesh.triangles.len());
    }
    // each moving part starts where its motion starts and ends assembled
    for step in &scene.steps {
        let frame = format!("part/{}", step.part);
        let poses: Vec<&Value> = r
            .messages
            .iter()
            .filter(|m| m.0 == TOPIC_TRANSFORMS)
            .flat_map(|m| m.2["transforms"].as_array().unwrap())
            .filter(|t| t["child_frame_id"] == frame.as_str())
            .collect();
        let v = |t: &Value| {
            [t["translation"]["x"].as_f64().unwrap(), t["translation"]["y"].as_f64().unwrap(), t["translation"]["z"].as_f64().unwrap()]
        };
        let Some(Insertion::Linear { direction, distance }) = &step.motion else { panic!("the tube moves in straight lines") };
        let start = v(poses[0]);
        let expected = -*direction * *distance;
        assert!(
            (start[0] - expected.x as f64).abs() < 1e-5
                && (start[1] - expected.y as f64).abs() < 1e-5
                && (start[2] - expected.z as f64).abs() < 1e-5,
            "{frame}: {start:?}"
        );
        assert!(v(poses.last().unwrap()).iter().all(|c| c.abs() < 1e-6), "{frame} does not end assembled");
    }
    let path = r.messages.iter().find(|m| m.0 == TOPIC_PATHS).unwrap();
    assert_eq!(path.2["entities"][0]["lines"][0]["type"], 0, "a line strip");
}

#[test]
fn path_motions_and_unfinished_plans_write_complete_files() {
    check_file(&planned(fixtures::l_path()), &McapOptions { step_seconds: 1.0, rate: 10.0 });
    let r = check_file(&stuck_tube(), &McapOptions::default());
    let first = &r.messages.iter().find(|m| m.0 == TOPIC_PARTS).unwrap().2;
    let stuck = first["entities"].as_array().unwrap().iter().find(|e| e["metadata"][0]["value"] == "stick").unwrap();
    assert_eq!(stuck["metadata"][1]["value"], "stuck");
    assert!(stuck["triangles"][0]["color"]["r"].as_f64().unwrap() > 0.8, "the stuck stick is red");
}
