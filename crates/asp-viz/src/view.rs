//! `asp view`: one self-contained HTML page (meshes, plan and three.js embedded; no network at
//! view time) that plays the assembly sequence.

use crate::error::{Result, VizError};
use crate::scene::{part_colour, Insertion, Scene, BASE, STUCK};
use asp_search::report::{ExplanationReason, PlanStatus};
use base64::Engine;
use serde_json::{json, Value};
use std::path::Path;

const TEMPLATE: &str = include_str!("../assets/viewer.html");
const VIEWER_JS: &str = include_str!("../assets/viewer.js");
const THREE_CORE: &str = include_str!("../assets/three/three.core.min.js");
const THREE_MODULE: &str = include_str!("../assets/three/three.module.min.js");
const ORBIT_CONTROLS: &str = include_str!("../assets/three/OrbitControls.js");
/// The module `three.module.min.js` imports three's core from; the page maps it to a bare name.
const CORE_IMPORT: &str = "\"./three.core.min.js\"";

/// The viewer page of `scene`: a complete HTML document.
pub fn html(scene: &Scene) -> String {
    let data = serde_json::to_string(&page_data(scene)).unwrap_or_else(|_| "{}".into());
    // inside <script> only `</` could end the element; `<` never occurs outside JSON strings
    let data = data.replace('<', "\\u003c");
    let title = format!("asp plan: {}", scene.report.model);
    fill(
        TEMPLATE,
        &[
            ("TITLE", &escape_html(&title)),
            ("DATA", &data),
            ("THREE_CORE", THREE_CORE),
            ("THREE_MODULE", &THREE_MODULE.replace(CORE_IMPORT, "\"three/core\"")),
            ("ORBIT", ORBIT_CONTROLS),
            ("VIEWER", VIEWER_JS),
        ],
    )
}

/// Writes the viewer page of `scene` to `path`.
pub fn write_html(path: &Path, scene: &Scene) -> Result<()> {
    asp_geom::io::write_atomic(path, html(scene).as_bytes()).map_err(|e| VizError::io(path, e))
}

/// The JSON the page's script reads: meshes in model units (base64 little-endian `f32`
/// positions, `u16`/`u32` indices), the steps with their motions and grid moves as in the plan,
/// the base, the stuck parts and their explanation.
fn page_data(scene: &Scene) -> Value {
    let r = &scene.report;
    let per_metre = 1.0 / scene.metres_per_unit;
    let b64 = base64::engine::general_purpose::STANDARD;
    let parts: Vec<Value> = scene
        .assembly
        .parts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut positions = Vec::with_capacity(p.mesh.vertices.len() * 12);
            for v in &p.mesh.vertices {
                for c in [v.x, v.y, v.z] {
                    positions.extend_from_slice(&((c as f64 * per_metre) as f32).to_le_bytes());
                }
            }
            let small = p.mesh.vertices.len() <= u16::MAX as usize + 1;
            let mut indices = Vec::with_capacity(p.mesh.triangles.len() * if small { 6 } else { 12 });
            for t in &p.mesh.triangles {
                for &k in t {
                    if small {
                        indices.extend_from_slice(&(k as u16).to_le_bytes());
                    } else {
                        indices.extend_from_slice(&k.to_le_bytes());
                    }
                }
            }
            let colour = if scene.stuck.contains(&i) {
                STUCK
            } else if scene.is_base(i) {
                BASE
            } else {
                part_colour(i)
            };
            json!({
                "name": p.name,
                "path": p.path.join("/"),
                "fixed": scene.is_base(i),
                "stuck": scene.stuck.contains(&i),
                "colour": colour,
                "positions": b64.encode(&positions),
                "indices": b64.encode(&indices),
                "index_bits": if small { 16 } else { 32 },
            })
        })
        .collect();
    let steps: Vec<Value> = scene
        .steps
        .iter()
        .map(|s| {
            let motion = match &s.motion {
                None => Value::Null,
                Some(Insertion::Linear { direction, distance }) => json!({
                    "kind": "linear",
                    "direction": [direction.x, direction.y, direction.z],
                    "distance": *distance as f64 * per_metre,
                }),
                Some(Insertion::Path { poses, pivot, radius }) => json!({
                    "kind": "path",
                    "poses": poses.iter().map(|p| {
                        let t = p.translation;
                        let q = p.rotation;
                        [t.x as f64 * per_metre, t.y as f64 * per_metre, t.z as f64 * per_metre, q.x as f64, q.y as f64, q.z as f64, q.w as f64]
                    }).collect::<Vec<_>>(),
                    "pivot": [pivot.x as f64 * per_metre, pivot.y as f64 * per_metre, pivot.z as f64 * per_metre],
                    "radius": *radius as f64 * per_metre,
                }),
            };
            let moves: Vec<Value> = s
                .moves
                .iter()
                .map(|m| {
                    let t = m.translation;
                    json!({ "parts": m.parts, "translation": [t.x as f64 * per_metre, t.y as f64 * per_metre, t.z as f64 * per_metre] })
                })
                .collect();
            json!({ "part": s.part, "name": s.name, "motion": motion, "group": s.parts, "moves": moves })
        })
        .collect();
    let explanation: Vec<Value> = r
        .explanation
        .iter()
        .map(|e| {
            let names: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
            let text = match (e.reason, &e.robot) {
                (_, Some(r)) => format!("{}: the arm cannot take it out: {} ({})", e.name, r.reason.words(), r.detail),
                (ExplanationReason::Blocked, None) => format!("{}: blocked by {}", e.name, names.join(", ")),
                (ExplanationReason::Unsupported, None) => format!("{}: removing it leaves {} unsupported", e.name, names.join(", ")),
                (ExplanationReason::DeadEnd, None) => format!("{}: can leave, but every state after that is stuck", e.name),
            };
            json!({ "part": e.part, "name": e.name, "reason": e.reason, "text": text })
        })
        .collect();
    // the precedence graph (`asp plan --precedence`): which steps may go in side by side
    let precedence = r.precedence.as_ref().map(|p| {
        json!({
            "levels": p.levels,
            "critical_path": p.critical_path,
            "edges": p.edges.iter().map(|e| [e.before, e.after]).collect::<Vec<_>>(),
            "conservative": p.stability.conservative,
        })
    });
    let up = asp_geom::math::Axis::parse(&r.up).map(|a| a.vector()).unwrap_or(asp_geom::math::Vec3::Z);
    json!({
        "title": r.model,
        "status": r.status,
        "status_text": status_text(scene),
        "units": r.units,
        "up": [up.x, up.y, up.z],
        "parts": parts,
        "initial": scene.initial,
        "stuck": scene.stuck,
        "steps": steps,
        "explanation": explanation,
        "precedence": precedence,
    })
}

/// One line about the plan for the page's header.
fn status_text(scene: &Scene) -> String {
    let n = scene.steps.len();
    let moving = n > 0 && scene.steps.iter().all(|s| s.motion.is_some());
    match scene.report.status {
        PlanStatus::Found => format!("Plan found: {n} steps ({} parts, units {}).", scene.assembly.parts.len(), scene.report.units),
        PlanStatus::Partial => format!(
            "Partial plan: {n} steps ({} parts, units {}); {} parts go in as locked cores that asp could not take apart \
             (in red).",
            scene.assembly.parts.len(),
            scene.report.units,
            scene.report.locked_cores.iter().map(|c| c.parts.len()).sum::<usize>()
        ),
        PlanStatus::NoPlan if moving => format!(
            "No plan: the search got stuck with {} parts left (stuck parts in red). Steps: the partial plan, \
             the other {n} parts in assembly order onto them.",
            scene.initial.len()
        ),
        PlanStatus::NoPlan => format!(
            "No plan: the search got stuck with {} parts left (stuck parts in red). Steps: the other {n} parts, {}, \
             appearing in place (no motions are recorded for them).",
            scene.initial.len(),
            if scene.order_recorded { "in the order of the branch reached" } else { "order not recorded" }
        ),
        other if moving => format!("{}: the partial plan reached ({n} parts).", other.as_str().replace('_', " ")),
        other => format!("{}: the partial sequence reached ({n} parts; motions not recorded).", other.as_str().replace('_', " ")),
    }
}

/// `template` with every `{{KEY}}` replaced once, in one pass (inserted text is not scanned).
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out = String::with_capacity(template.len() + values.iter().map(|(_, v)| v.len()).sum::<usize>());
    let mut rest = template;
    while let Some(start) = rest.find("{{") {
        let Some(len) = rest[start + 2..].find("}}") else { break };
        let key = &rest[start + 2..start + 2 + len];
        out.push_str(&rest[..start]);
        match values.iter().find(|(k, _)| *k == key) {
            Some((_, v)) => out.push_str(v),
            None => out.push_str(&rest[start..start + 4 + len]),
        }
        rest = &rest[start + 4 + len..];
    }
    out.push_str(rest);
    out
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_scripts_cannot_end_their_script_elements() {
        for (name, text) in [("core", THREE_CORE), ("module", THREE_MODULE), ("orbit", ORBIT_CONTROLS), ("viewer", VIEWER_JS)] {
            assert!(!text.to_ascii_lowercase().contains("</script"), "{name} contains </script");
        }
    }

    #[test]
    fn three_module_imports_its_core_by_the_name_the_page_maps() {
        assert!(THREE_MODULE.contains(CORE_IMPORT), "three.module.min.js no longer imports {CORE_IMPORT}");
        assert!(ORBIT_CONTROLS.contains("from 'three'"));
    }

    #[test]
    fn fill_replaces_each_key_once_without_rescanning() {
        assert_eq!(fill("a{{X}}b{{Y}}c{{Z}}", &[("X", "{{Y}}"), ("Y", "2")]), "a{{Y}}b2c{{Z}}");
    }
}
