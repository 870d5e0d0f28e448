//! `asp view`, `asp render`, `asp plot` and `asp plan --mcap` end to end. The viewer runs in a
//! real headless Chromium driven over the DevTools protocol; those tests skip (and say why) when
//! no Chromium is installed (`apt-get install -y chromium`).

mod browser;

use asp_geom::fixtures;
use asp_geom::io::write_glb;
use browser::Browser;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn asp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asp")).args(args).output().expect("asp runs")
}

fn data(rel: &str) -> String {
    format!("{}/../../tests/data/{rel}", env!("CARGO_MANIFEST_DIR"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A folder that lives as long as the test binary (plans shared by several tests).
fn shared_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| tempfile::tempdir().unwrap()).path()
}

/// The plan of the IKEA Lack table (found), planned once.
fn lack_plan() -> &'static Path {
    static PLAN: OnceLock<PathBuf> = OnceLock::new();
    PLAN.get_or_init(|| {
        let out = shared_dir().join("lack.json");
        let o = asp(&["plan", &data("ikea/table_lack_0825.glb"), "--up", "z", "--quiet", "--out", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        out
    })
}

/// The plan of the pump without subassemblies (no plan: body, back lid and a screw are stuck),
/// planned once.
fn pump_plan() -> &'static Path {
    static PLAN: OnceLock<PathBuf> = OnceLock::new();
    PLAN.get_or_init(|| {
        let out = shared_dir().join("pump.json");
        let o = asp(&["plan", &data("pump"), "--unit", "mm", "--up", "z", "--no-subassemblies", "--quiet", "--out", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        out
    })
}

fn view(plan: &Path, name: &str) -> PathBuf {
    let page = shared_dir().join(name);
    let o = asp(&["view", plan.to_str().unwrap(), "--out", page.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    page
}

/// Pixels that are model, not background, grid or panel: coloured (saturated) or dark.
fn model_pixels(shot: &browser::Screenshot, x_from: u32) -> usize {
    let mut n = 0;
    for y in 0..shot.height {
        for x in x_from..shot.width {
            let [r, g, b] = shot.pixel(x, y);
            let (max, min) = (r.max(g).max(b), r.min(g).min(b));
            if max - min > 40 || max < 170 {
                n += 1;
            }
        }
    }
    n
}

fn red_pixels(shot: &browser::Screenshot, x_from: u32) -> usize {
    let mut n = 0;
    for y in 0..shot.height {
        for x in x_from..shot.width {
            let [r, g, b] = shot.pixel(x, y);
            if r > 120 && (g as u32) * 2 < r as u32 && (b as u32) * 2 < r as u32 {
                n += 1;
            }
        }
    }
    n
}

fn differing(a: &browser::Screenshot, b: &browser::Screenshot, x_from: u32) -> usize {
    let mut n = 0;
    for y in 0..a.height.min(b.height) {
        for x in x_from..a.width.min(b.width) {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            if (0..3).any(|i| (p[i] as i32 - q[i] as i32).abs() > 24) {
                n += 1;
            }
        }
    }
    n
}

/// The panel covers the left 330 pixels; the model is measured right of it.
const RIGHT_OF_PANEL: u32 = 330;

#[test]
fn the_viewer_plays_a_found_plan_in_a_headless_browser() {
    let Some(mut browser) = Browser::launch() else { return };
    let page = view(lack_plan(), "lack.html");
    browser.open(&page);
    let state = browser.eval("JSON.stringify(aspViewer.state())");
    let state: serde_json::Value = serde_json::from_str(state.as_str().unwrap()).unwrap();
    let total = state["total"].as_u64().unwrap();
    assert!(total >= 4, "the Lack table has legs and a top: {state}");
    assert_eq!(state["status"], "found");

    browser.eval("aspViewer.goto(0); true");
    let start = browser.screenshot();
    browser.eval(&format!("aspViewer.goto({total}); true"));
    let end = browser.screenshot();
    let area = ((end.width - RIGHT_OF_PANEL) * end.height) as usize;
    assert!(
        model_pixels(&end, RIGHT_OF_PANEL) > area / 50,
        "the assembled table is (nearly) blank: {} model pixels",
        model_pixels(&end, RIGHT_OF_PANEL)
    );
    assert!(differing(&start, &end, RIGHT_OF_PANEL) > area / 100, "all steps shown looks like no step shown");

    // one step: the first part flies in and comes to rest
    browser.eval("aspViewer.goto(0); true");
    let s: serde_json::Value = serde_json::from_str(browser.eval("JSON.stringify(aspViewer.step())").as_str().unwrap()).unwrap();
    assert_eq!(s["shown"], 1);
    assert!(s["flying"].is_u64(), "the part is in flight: {s}");
    let before = s["visible"].as_array().unwrap().len();
    browser.wait_for("aspViewer.state().flying === null", 10.0);
    let s: serde_json::Value = serde_json::from_str(browser.eval("JSON.stringify(aspViewer.state())").as_str().unwrap()).unwrap();
    assert_eq!(s["visible"].as_array().unwrap().len(), before, "the flying part stays once placed");
    assert!(s["current"].is_u64(), "the placed part is the current one: {s}");
    let one = browser.screenshot();
    assert!(differing(&start, &one, RIGHT_OF_PANEL) > 0, "one step changed nothing on screen");

    // the step list names every part with its number
    let items = browser.eval("document.querySelectorAll('#asp-steps li').length");
    assert_eq!(items.as_u64(), Some(total));
    // ... each with its part's colour as swatch (it was rgb(undefined,...), blank)
    let swatches = browser.eval("JSON.stringify([...document.querySelectorAll('#asp-steps .swatch')].map((s) => [s.style.background, getComputedStyle(s).backgroundColor]))");
    let swatches: Vec<(String, String)> = serde_json::from_str(swatches.as_str().unwrap()).unwrap();
    assert_eq!(swatches.len() as u64, total);
    for (inline, computed) in &swatches {
        assert!(inline.starts_with("rgb(") && !inline.contains("undefined"), "swatch style '{inline}'");
        assert!(computed.starts_with("rgb(") && computed != "rgba(0, 0, 0, 0)", "swatch colour '{computed}'");
    }
    browser.assert_no_errors();
}

#[test]
fn the_viewer_shows_a_no_plan_result_with_the_stuck_parts_in_red() {
    let Some(mut browser) = Browser::launch() else { return };
    let page = view(pump_plan(), "pump.html");
    browser.open(&page);
    let state: serde_json::Value = serde_json::from_str(browser.eval("JSON.stringify(aspViewer.goto(0))").as_str().unwrap()).unwrap();
    assert_eq!(state["status"], "no_plan");
    assert!(!state["stuck"].as_array().unwrap().is_empty(), "the pump's explanation names stuck parts: {state}");
    let shot = browser.screenshot();
    assert!(red_pixels(&shot, RIGHT_OF_PANEL) > 200, "no red stuck parts on screen ({} red pixels)", red_pixels(&shot, RIGHT_OF_PANEL));
    let explanation = browser.eval("document.querySelectorAll('#asp-explanation li').length").as_u64().unwrap();
    assert!(explanation >= 1);
    let total = state["total"].as_u64().unwrap();
    if total > 0 {
        browser.eval(&format!("aspViewer.goto({total}); true"));
        let end = browser.screenshot();
        assert!(differing(&shot, &end, RIGHT_OF_PANEL) > 0, "the partial sequence changes nothing");
    }
    browser.assert_no_errors();
}

#[test]
fn the_viewer_moves_path_motions_as_the_plan_format_documents() {
    let Some(mut browser) = Browser::launch() else { return };
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("l_path.glb");
    write_glb(&fixtures::l_path(), &model).unwrap();
    let plan = dir.path().join("l_path.json");
    // without the grid, whose moves would answer the voxel L first
    let o = asp(&["plan", model.to_str().unwrap(), "--no-grid", "--quiet", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let scene = asp_viz::Scene::from_plan_file(&plan, None).unwrap();
    let k = scene.steps.iter().position(|s| matches!(s.motion, Some(asp_viz::Insertion::Path { .. }))).expect("the L needs a path");
    let motion = scene.steps[k].motion.clone().unwrap();
    browser.open(&view(&plan, "l_path.html"));
    for s in [0.0f32, 0.2, 0.45, 0.5, 0.8, 1.0] {
        let js = browser.eval(&format!("aspViewer.poseAt({k}, {s})"));
        let rust = motion.pose_at(s); // metres; the fixture's unit is the metre
        let t: Vec<f64> = js["t"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let q: Vec<f64> = js["q"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let rt = rust.translation;
        let rq = rust.rotation;
        let dt = ((t[0] - rt.x as f64).powi(2) + (t[1] - rt.y as f64).powi(2) + (t[2] - rt.z as f64).powi(2)).sqrt();
        let dot = (q[0] * rq.x as f64 + q[1] * rq.y as f64 + q[2] * rq.z as f64 + q[3] * rq.w as f64).abs();
        assert!(dt < 1e-4 && dot > 1.0 - 1e-5, "s = {s}: page {t:?} {q:?}, library {rust:?}");
    }
    browser.assert_no_errors();
}

/// A burr's grid plan: the page plays each step's moves after its insertion, with the poses of
/// `Scene::pose_during` (which the library's tests check for pieces passing through others).
#[test]
fn the_viewer_plays_grid_moves_as_the_scene_does() {
    let Some(mut browser) = Browser::launch() else { return };
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("burr.glb");
    write_glb(&asp_geom::puzzles::burr_level(), &model).unwrap();
    let plan = dir.path().join("burr.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--quiet", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let scene = asp_viz::Scene::from_plan_file(&plan, None).unwrap();
    let k = scene.steps.iter().position(|s| !s.moves.is_empty()).expect("the burr's plan has moves");
    let duration = scene.steps[k].duration();
    browser.open(&view(&plan, "burr.html"));
    for i in 0..scene.assembly.parts.len() {
        for u in [0.0f32, 0.5, 1.0, 1.2, 1.5, duration - 0.1, duration] {
            let js = browser.eval(&format!("aspViewer.partPose({k}, {u}, {i})"));
            let t: Vec<f64> = js["t"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let rust = scene.pose_during(k, u, i).translation; // metres; the fixture's unit is the metre
            let d = ((t[0] - rust.x as f64).powi(2) + (t[1] - rust.y as f64).powi(2) + (t[2] - rust.z as f64).powi(2)).sqrt();
            assert!(d < 1e-6, "step {k}, u = {u}, part {i}: page {t:?}, library {rust:?}");
        }
    }
    // playing the step runs its moves too, and ends with every shown part at rest
    browser.eval(&format!("aspViewer.goto({k}); aspViewer.step(); true"));
    browser.wait_for("aspViewer.state().t > 1", 10.0);
    browser.wait_for("aspViewer.state().flying === null", 10.0);
    browser.assert_no_errors();
}

#[test]
fn render_writes_a_storyboard_png_of_the_right_size() {
    let out = shared_dir().join("lack.png");
    let o = asp(&["render", lack_plan().to_str().unwrap(), "--out", out.to_str().unwrap(), "--panel", "200", "--columns", "3"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(lack_plan()).unwrap()).unwrap();
    let steps = plan["assembly_sequence"].as_array().unwrap().len() as u32;
    let reader = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap())).read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (3 * 200, steps.div_ceil(3) * 200));
}

#[test]
fn view_and_render_name_the_file_when_the_model_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let mut plan: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(lack_plan()).unwrap()).unwrap();
    plan["model"] = "gone/table.glb".into();
    let path = dir.path().join("moved.json");
    std::fs::write(&path, plan.to_string()).unwrap();
    for cmd in ["view", "render"] {
        let out = dir.path().join(if cmd == "view" { "p.html" } else { "p.png" });
        let o = asp(&[cmd, path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{cmd}");
        let e = stderr(&o);
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.starts_with("error: ") && e.contains("moved.json") && e.contains("gone/table.glb") && e.contains("--model"), "{e}");
        // --model points at the model again
        let o = asp(&[cmd, path.to_str().unwrap(), "--out", out.to_str().unwrap(), "--model", &data("ikea/table_lack_0825.glb")]);
        assert_eq!(o.status.code(), Some(0), "{cmd}: {}", stderr(&o));
    }
    let o = asp(&["view", dir.path().join("none.json").to_str().unwrap(), "--out", "x.html"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("none.json"), "{}", stderr(&o));
}

#[test]
fn plan_writes_an_mcap_with_the_foxglove_topics() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tube.glb");
    write_glb(&fixtures::tube(), &model).unwrap();
    let out = dir.path().join("tube.mcap");
    let o = asp(&["plan", model.to_str().unwrap(), "--quiet", "--mcap", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bytes = std::fs::read(&out).unwrap();
    let mut topics = std::collections::BTreeMap::<String, (String, usize)>::new();
    let mut last = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert!(m.log_time >= last);
        last = m.log_time;
        let schema = m.channel.schema.as_ref().unwrap().name.clone();
        topics.entry(m.channel.topic.clone()).or_insert((schema, 0)).1 += 1;
    }
    assert_eq!(topics["/asp/parts"], ("foxglove.SceneUpdate".to_string(), 4), "the base, then 3 steps");
    assert_eq!(topics["/asp/paths"].1, 3);
    assert_eq!(topics["/tf"].0, "foxglove.FrameTransforms");
    // optimising runs go through the same pipeline and write it too
    let optimised = dir.path().join("optimised.mcap");
    let o = asp(&[
        "plan",
        model.to_str().unwrap(),
        "--quiet",
        "--objective",
        "access",
        "--threads",
        "1",
        "--mcap",
        optimised.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bytes = std::fs::read(&optimised).unwrap();
    let paths = mcap::MessageStream::new(&bytes).unwrap().filter(|m| m.as_ref().unwrap().channel.topic == "/asp/paths").count();
    assert_eq!(paths, 3);
}

#[test]
fn plot_draws_traces_and_rejects_a_plan_without_a_front() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("hv.csv");
    std::fs::write(&csv, "episode,iterations,seconds,value,front_size\n1,5,0.001,0.25,1\n4,20,0.004,0.5,2\n").unwrap();
    let svg = dir.path().join("hv.svg");
    let o = asp(&["plot", csv.to_str().unwrap(), "--out", svg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    assert_eq!(doc.descendants().filter(|n| n.has_tag_name("circle")).count(), 2);
    let o = asp(&["plot", lack_plan().to_str().unwrap(), "--out", svg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("pareto_front"), "{}", stderr(&o));
}

/// A part name built to hurt stays text in the viewer: no element it spells is made,
/// no script it carries runs, and the step list shows it verbatim.
#[test]
fn a_hostile_part_name_stays_text_in_the_viewer() {
    let Some(mut browser) = Browser::launch() else { return };
    let dir = tempfile::tempdir().unwrap();
    let hostile = r#"</script><img src=x onerror="window.__pwned=1"><b id="injected">x</b>"#;
    let mut a = fixtures::stacked_boxes();
    a.parts[1].name = hostile.into();
    let model = dir.path().join("hostile.glb");
    write_glb(&a, &model).unwrap();
    let plan = dir.path().join("hostile.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--quiet", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    browser.open(&view(&plan, "hostile.html"));
    browser.wait_for("typeof aspViewer !== 'undefined'", 10.0);
    assert_eq!(browser.eval("typeof window.__pwned").as_str(), Some("undefined"), "the name's script ran");
    assert_eq!(browser.eval("document.querySelectorAll('img, #injected').length").as_u64(), Some(0), "the name made elements");
    let steps = browser.eval("document.getElementById('asp-steps').textContent");
    assert!(steps.as_str().is_some_and(|t| t.contains(hostile)), "the step list does not show the name as text: {steps}");
    browser.assert_no_errors();
}

/// `asp render instructions`: the bookcase planned with its precedence graph, balanced into
/// three stations (every step at one station, no step before a predecessor's station, about
/// equal parts each), the pages open in the headless browser with their pictures loaded; a
/// times file moves the balance; a plan without a sequence, zero stations and a bad times file
/// are one-line errors.
#[test]
fn work_instructions_per_station_open_in_a_headless_browser() {
    let dir = tempfile::tempdir().unwrap();
    let plan = dir.path().join("grevback.json");
    let model = data("ikea/bookcase_grevback_0484.glb");
    let o = asp(&["plan", &model, "--up", "z", "--precedence", "--quiet", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let line = dir.path().join("line");
    let o = asp(&["render", "instructions", plan.to_str().unwrap(), "--stations", "3", "--out", line.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("3 stations") && stderr(&o).contains("on the precedence graph"), "{}", stderr(&o));
    for f in ["index.html", "station-01.html", "station-01.png", "station-02.html", "station-03.png"] {
        assert!(line.join(f).is_file(), "{f} missing");
    }
    assert!(!line.join("station-04.html").exists());
    // the stations against the plan's graph
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&plan).unwrap()).unwrap();
    let steps = report["assembly_sequence"].as_array().unwrap().len();
    let pages: Vec<String> = (1..=3).map(|i| std::fs::read_to_string(line.join(format!("station-{i:02}.html"))).unwrap()).collect();
    let station_of = |k: usize| -> usize {
        let name = report["assembly_sequence"][k]["name"].as_str().unwrap();
        let cell = format!("<tr><td>{}</td><td>{name}", k + 1);
        let at: Vec<usize> = (0..3).filter(|&i| pages[i].contains(&cell)).collect();
        assert_eq!(at.len(), 1, "step {} is at one station: {at:?}", k + 1);
        at[0]
    };
    let stations: Vec<usize> = (0..steps).map(station_of).collect();
    for e in report["precedence"]["edges"].as_array().unwrap() {
        let (a, b) = (e["before"].as_u64().unwrap() as usize, e["after"].as_u64().unwrap() as usize);
        assert!(stations[a] <= stations[b], "step {} before step {} but at a later station", a + 1, b + 1);
    }
    let per: Vec<usize> = (0..3).map(|i| stations.iter().filter(|&&s| s == i).count()).collect();
    assert!(per.iter().all(|&c| c >= 1 && c <= steps.div_ceil(3) + 1), "{per:?}");
    // the pages in a browser: no errors, the pictures loaded
    if let Some(mut browser) = Browser::launch() {
        let loaded = "document.readyState === 'complete' && document.images.length > 0 && Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)";
        browser.open_until(&line.join("station-01.html"), loaded);
        assert!(browser.eval("document.querySelectorAll('tr').length").as_u64().unwrap() >= 2);
        let shot = browser.screenshot();
        assert!(model_pixels(&shot, 0) > 500, "the station's pictures show the model");
        browser.open_until(&line.join("index.html"), "document.readyState === 'complete'");
        assert_eq!(browser.eval("document.querySelectorAll('a[href^=\"station-\"]').length").as_u64(), Some(3));
        browser.assert_no_errors();
    }
    // a time per part: the heaviest part alone fills a station
    let first = report["assembly_sequence"][0]["name"].as_str().unwrap().to_string();
    let times = dir.path().join("times.csv");
    std::fs::write(&times, format!("# seconds per part\n{first},100\n")).unwrap();
    let timed = dir.path().join("timed");
    // two stations with the times file as it stands
    let timed_run = || {
        asp(&[
            "render",
            "instructions",
            plan.to_str().unwrap(),
            "--stations",
            "2",
            "--times",
            times.to_str().unwrap(),
            "--out",
            timed.to_str().unwrap(),
        ])
    };
    let o = timed_run();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("cycle 100.0 s"), "{}", stderr(&o));
    // errors: one line each, naming the cause
    std::fs::write(&times, "nope,1\n").unwrap();
    let o = timed_run();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("'nope', which is no part of the plan"), "{}", stderr(&o));
    std::fs::write(&times, "x;1\n").unwrap();
    let o = timed_run();
    assert!(o.status.code() == Some(2) && stderr(&o).contains("times.csv:1: no comma"), "{}", stderr(&o));
    let o = asp(&["render", "instructions", plan.to_str().unwrap(), "--stations", "0", "--out", timed.to_str().unwrap()]);
    assert!(o.status.code() == Some(2) && stderr(&o).contains("--stations must be at least 1"), "{}", stderr(&o));
    let o = asp(&["render", "instructions", pump_plan().to_str().unwrap(), "--stations", "2", "--out", timed.to_str().unwrap()]);
    assert!(o.status.code() == Some(2) && stderr(&o).contains("instructions need an assembly sequence"), "{}", stderr(&o));
    // the storyboard is still `asp render PLAN --out FILE`
    let png = dir.path().join("board.png");
    let o = asp(&["render", plan.to_str().unwrap(), "--out", png.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// The viewer shows a plan's precedence graph (`asp plan --precedence`): its levels, the
/// critical path in bold, a click on a step shows the model up to it; without the graph the
/// section stays hidden.
#[test]
fn the_viewer_shows_the_precedence_levels() {
    let Some(mut browser) = Browser::launch() else { return };
    let dir = tempfile::tempdir().unwrap();
    let plan = dir.path().join("grevback.json");
    let o =
        asp(&["plan", &data("ikea/bookcase_grevback_0484.glb"), "--up", "z", "--precedence", "--quiet", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&plan).unwrap()).unwrap();
    let levels = report["precedence"]["levels"].as_array().unwrap().len();
    let page = dir.path().join("grevback.html");
    let o = asp(&["view", plan.to_str().unwrap(), "--out", page.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    browser.open(&page);
    assert_eq!(browser.eval("document.getElementById('asp-precedence').hidden"), serde_json::json!(false));
    assert_eq!(browser.eval("document.querySelectorAll('#asp-precedence li.asp-level').length").as_u64(), Some(levels as u64));
    let critical = report["precedence"]["critical_path"].as_array().unwrap().len() as u64;
    assert_eq!(browser.eval("document.querySelectorAll('#asp-precedence .asp-step.critical').length").as_u64(), Some(critical));
    // a click on the first step of the last level shows the model up to that step
    let k = report["precedence"]["levels"][levels - 1][0].as_u64().unwrap();
    browser.eval("document.querySelector('#asp-precedence li.asp-level:last-child .asp-step').click(); true");
    let state: serde_json::Value = serde_json::from_str(browser.eval("JSON.stringify(aspViewer.state())").as_str().unwrap()).unwrap();
    assert_eq!(state["shown"].as_u64(), Some(k + 1), "{state}");
    browser.assert_no_errors();
    // a plan without the graph: no section
    browser.open(&view(lack_plan(), "lack-no-precedence.html"));
    assert_eq!(browser.eval("document.getElementById('asp-precedence').hidden"), serde_json::json!(true));
}
