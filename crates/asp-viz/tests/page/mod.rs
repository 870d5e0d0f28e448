//! The viewer page's content without a browser (the browser tests are in asp-cli's tests).

use crate::common::{locked_burr, planned, stuck_tube};
use asp_geom::fixtures;
use asp_viz::view::html;
use base64::Engine;
use serde_json::Value;

fn data(page: &str) -> Value {
    let start = page.find(r#"<script type="application/json" id="asp-data">"#).unwrap();
    let rest = &page[start..];
    let open = rest.find('>').unwrap() + 1;
    let close = rest.find("</script>").unwrap();
    serde_json::from_str(&rest[open..close]).unwrap()
}

#[test]
fn the_page_embeds_three_the_meshes_and_the_steps_and_fetches_nothing() {
    let scene = planned(fixtures::tube());
    let page = html(&scene);
    assert!(page.contains("const t=\"183\""), "three r183 embedded");
    assert!(page.contains("class OrbitControls"));
    for remote in ["http://", "https://", "src=\"//"] {
        // three's licence header and comments may name web sites; no element may load one
        for tag in ["<script src", "<link", "<img"] {
            assert!(!page.contains(&format!("{tag}=\"{remote}")), "{tag} {remote}");
        }
    }
    assert!(!page.contains("<script src"), "no external scripts");
    let d = data(&page);
    assert_eq!(d["parts"].as_array().unwrap().len(), 4);
    assert_eq!(d["steps"].as_array().unwrap().len(), 3);
    assert_eq!(d["status"], "found");
    assert_eq!(d["up"], serde_json::json!([0.0, 0.0, 1.0]));
    let b64 = base64::engine::general_purpose::STANDARD;
    for (i, p) in d["parts"].as_array().unwrap().iter().enumerate() {
        let pos = b64.decode(p["positions"].as_str().unwrap()).unwrap();
        assert_eq!(pos.len(), 12 * scene.assembly.parts[i].mesh.vertices.len());
        let idx = b64.decode(p["indices"].as_str().unwrap()).unwrap();
        assert_eq!(idx.len(), 3 * (p["index_bits"].as_u64().unwrap() as usize / 8) * scene.assembly.parts[i].mesh.triangles.len());
    }
    assert_eq!(d["steps"][0]["motion"]["kind"], "linear");
    let base: Vec<u64> = d["initial"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    assert_eq!(base.len(), 1, "the receptacle is the base");
    assert_eq!(d["parts"][base[0] as usize]["fixed"], true);
}

#[test]
fn an_unfinished_plan_shows_its_partial_sequence_and_stuck_parts() {
    let scene = stuck_tube();
    let d = data(&html(&scene));
    assert_eq!(d["status"], "no_plan");
    assert_eq!(d["steps"].as_array().unwrap().len(), 1);
    // the partial plan (format 1.3) records how the part that came off moves
    assert_eq!(d["steps"][0]["motion"]["kind"], "linear");
    assert!(d["status_text"].as_str().unwrap().contains("the partial plan"), "{}", d["status_text"]);
    assert_eq!(d["initial"].as_array().unwrap().len(), 3);
    let stick = d["stuck"][0].as_u64().unwrap() as usize;
    assert_eq!(d["parts"][stick]["stuck"], true);
    assert_eq!(d["parts"][stick]["colour"], serde_json::json!(asp_viz::scene::STUCK));
    assert!(d["explanation"][0]["text"].as_str().unwrap().contains("blocked by receptacle, cap"));
}

/// A partial plan opens as a complete sequence, its locked core's parts in red and
/// its step labelled as a locked core.
#[test]
fn a_partial_plan_highlights_its_locked_core() {
    let scene = locked_burr();
    let d = data(&html(&scene));
    assert_eq!(d["status"], "partial");
    assert!(d["status_text"].as_str().unwrap().starts_with("Partial plan: 1 steps"), "{}", d["status_text"]);
    assert!(d["status_text"].as_str().unwrap().contains("6 parts go in as locked cores"), "{}", d["status_text"]);
    assert_eq!(d["steps"].as_array().unwrap().len(), 1);
    assert!(d["steps"][0]["name"].as_str().unwrap().contains("locked core"), "{}", d["steps"][0]["name"]);
    let stuck: Vec<u64> = d["stuck"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    assert_eq!(stuck, (0..6).collect::<Vec<u64>>());
    for p in d["parts"].as_array().unwrap() {
        assert_eq!(p["stuck"], true);
        assert_eq!(p["colour"], serde_json::json!(asp_viz::scene::STUCK));
    }
}

#[test]
fn names_cannot_break_out_of_the_data_script() {
    let mut scene = planned(fixtures::tube());
    scene.assembly.parts[1].name = "</script><script>alert(1)</script>".into();
    let page = html(&scene);
    assert_eq!(page.matches("</script>").count(), html(&planned(fixtures::tube())).matches("</script>").count());
}

#[test]
fn a_no_plan_after_a_full_backtrack_starts_from_the_dead_end_its_explanation_describes() {
    // the planner backtracked to the root: the last branch is empty, the explanation names the
    // dead end {stick, cap} (+ the fixed receptacle)
    // a plan of format < 1.3: no partial sequence
    let mut scene = stuck_tube();
    scene.report.disassembly_sequence.clear();
    scene.report.partial_assembly_sequence.clear();
    let scene = asp_viz::Scene::new(scene.assembly.clone(), scene.report.clone(), std::path::Path::new("fixture")).unwrap();
    assert_eq!(scene.initial.len(), 3);
    assert_eq!(scene.steps.len(), 1, "the handle");
    assert!(!scene.order_recorded || scene.steps.len() == 1);
    let d = data(&html(&scene));
    assert_eq!(d["initial"].as_array().unwrap().len(), 3);
}
