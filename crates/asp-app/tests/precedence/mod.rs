//! `asp plan --precedence` (plan format 1.12): every order the precedence graph allows is
//! feasible with the plan's own motions (the graph's travel per step), by the independent
//! re-check of `asp_check::verify`.

use crate::fuzz::{removals, removals_scaled};
use crate::verify::verify_removals;
use asp_app::pipeline::{checker, plan_assembly, PlanSettings};
use asp_gen::batch::{generate_item, Generator};
use asp_gen::{StressKind, StressParams};
use asp_geom::{fixtures, Assembly, Motion};
use asp_search::report::{PlanStatus, PrecedenceEntry, PrecedenceReason};
use asp_search::Step;
use rand::{RngExt, SeedableRng};

/// Linear extensions sampled per model.
const SAMPLES: usize = 60;

/// A random order of the steps that keeps every edge (Kahn's algorithm, a random ready step
/// each time).
fn linear_extension(g: &PrecedenceEntry, rng: &mut impl RngExt) -> Vec<usize> {
    let k = g.steps.len();
    let mut preds = vec![0usize; k];
    for e in &g.edges {
        preds[e.after] += 1;
    }
    let mut ready: Vec<usize> = (0..k).filter(|&s| preds[s] == 0).collect();
    let mut order = Vec::new();
    while !ready.is_empty() {
        let s = ready.swap_remove(rng.random_range(0..ready.len()));
        order.push(s);
        for e in g.edges.iter().filter(|e| e.before == s) {
            preds[e.after] -= 1;
            if preds[e.after] == 0 {
                ready.push(e.after);
            }
        }
    }
    assert_eq!(order.len(), k, "the graph has a cycle");
    order
}

/// Plans `assembly` with the precedence graph and re-checks `SAMPLES` random linear extensions;
/// returns the graph and how many distinct orders were drawn.
fn extensions_are_feasible(what: &str, assembly: Assembly, seed: u64) -> (PrecedenceEntry, usize) {
    sampled_extensions_are_feasible(what, assembly, seed, SAMPLES)
}

/// [`extensions_are_feasible`] with `samples` extensions.
fn sampled_extensions_are_feasible(what: &str, assembly: Assembly, seed: u64, samples: usize) -> (PrecedenceEntry, usize) {
    let settings = PlanSettings { precedence: true, ..PlanSettings::default() };
    let n = assembly.len();
    let metres = assembly.units.metres as f32;
    let r = plan_assembly(assembly.clone(), &settings, None).unwrap();
    assert_eq!(r.report.status, PlanStatus::Found, "{what}: {}", r.report.to_text());
    let g = r.report.precedence.clone().unwrap_or_else(|| panic!("{what}: no precedence graph"));
    let k = r.report.assembly_sequence.len();
    assert_eq!(g.steps.len(), k);
    // the plan's own order is an extension, and levels respect every edge
    for e in &g.edges {
        assert!(e.before < e.after, "{what}: {e:?} against the plan's order");
        assert!(g.steps[e.before].level < g.steps[e.after].level, "{what}: {e:?}");
    }
    assert_eq!(g.critical_path.len(), g.levels.len(), "{what}: the critical path crosses every level");
    for w in g.critical_path.windows(2) {
        assert!(g.edges.iter().any(|e| e.before == w[0] && e.after == w[1]), "{what}: {w:?} is no edge");
    }
    assert_eq!(g.levels.iter().map(Vec::len).sum::<usize>(), k);
    // each assembly step as a removal, with the graph's travel
    let mut steps: Vec<Step> = removals_scaled(&r.report.assembly_sequence, n, metres as f64).into_iter().rev().collect();
    for (s, entry) in steps.iter_mut().zip(&g.steps) {
        if let (Motion::Linear { distance, .. } | Motion::Screw { distance, .. }, Some(d)) = (&mut s.motion, entry.distance) {
            *distance = d as f32 * metres;
        }
    }
    let world = checker(assembly, &settings).unwrap();
    let world = world.world();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut seen = std::collections::HashSet::new();
    // one verifier for every order: a step's motion swept clear of a part once is clear of it in
    // every order (each test of the sweep is pairwise); states and bounds are tested every time
    let mut verifier = crate::verify::Verifier::default();
    for _ in 0..samples {
        let order = linear_extension(&g, &mut rng);
        if seen.contains(&order) {
            continue; // re-checked already
        }
        let removal: Vec<Step> = order.iter().rev().map(|&i| steps[i].clone()).collect();
        let left = verifier.verify_removals(world, &removal);
        assert!(left.iter().all(|p| world.contacts().fixed().contains(p)), "{what}: {order:?} leaves parts");
        seen.insert(order);
    }
    (g, seen.len())
}

#[test]
fn every_linear_extension_of_the_precedence_graph_is_feasible() {
    let mut orders = 0;
    let mut parallel = 0;
    let mut models: Vec<(String, Assembly)> = vec![
        ("tube".into(), fixtures::tube()),
        ("arch".into(), fixtures::arch()),
        ("profiles".into(), crate::fixtures::small_profiles(2, 1)),
    ];
    for stress in [StressKind::Chair, StressKind::Carcass, StressKind::Bolted] {
        let (generated, _) = generate_item(&Generator::Stress(StressParams { stress }), 0, 1, 7).unwrap();
        models.push((stress.name().to_string(), generated.assembly));
    }
    for (i, (what, a)) in models.into_iter().enumerate() {
        let (g, distinct) = extensions_are_feasible(&what, a, i as u64);
        orders += distinct;
        parallel += usize::from(g.levels.iter().any(|l| l.len() > 1));
    }
    // the graphs leave real freedom: several orders per model, parallel steps
    assert!(orders > 6 * 3, "{orders} distinct orders");
    assert!(parallel >= 3, "{parallel} models with parallel steps");
}

#[test]
fn precedence_edges_say_why() {
    let settings = PlanSettings { precedence: true, ..PlanSettings::default() };
    // the arch: the keystone after a pillar that holds it up; both pillars in parallel
    let r = plan_assembly(fixtures::arch(), &settings, None).unwrap();
    let g = r.report.precedence.unwrap();
    assert_eq!(g.stability.criterion, "contact");
    assert!(g.stability.conservative && g.stability.guaranteed);
    let step = |name: &str| r.report.assembly_sequence.iter().position(|s| s.name == name).unwrap();
    let keystone = step("keystone");
    assert_eq!(g.steps[keystone].level, 1);
    let supports: Vec<usize> =
        g.edges.iter().filter(|e| e.after == keystone && e.reasons.contains(&PrecedenceReason::Supports)).map(|e| e.before).collect();
    assert_eq!(supports.len(), 1, "one pillar is enough to hold the keystone up in contact terms: {:?}", g.edges);
    assert_eq!(g.levels[0].len(), 2, "both pillars may go in in parallel: {:?}", g.levels);
    let dot = g.to_dot();
    assert!(dot.starts_with("digraph precedence {") && dot.contains("keystone") && dot.contains("supports"), "{dot}");
    // without the flag there is no graph
    let r = plan_assembly(fixtures::arch(), &PlanSettings::default(), None).unwrap();
    assert!(r.report.precedence.is_none());
}

/// The re-check the extensions pass has teeth: an order the graph forbids (the tube's handle
/// before its stick, against a blocking edge) is refused by it.
#[test]
fn an_order_against_a_blocking_edge_fails_the_re_check() {
    let settings = PlanSettings { precedence: true, ..PlanSettings::default() };
    let a = fixtures::tube();
    let n = a.len();
    let r = plan_assembly(a.clone(), &settings, None).unwrap();
    let g = r.report.precedence.unwrap();
    let step = |name: &str| r.report.assembly_sequence.iter().position(|s| s.name == name).unwrap();
    let (stick, handle) = (step("stick"), step("handle"));
    let edge = g.edges.iter().find(|e| e.before == stick && e.after == handle).expect("the handle closes the stick's way");
    assert!(edge.reasons.contains(&PrecedenceReason::Blocks), "{edge:?}");
    // the handle first, then the stick along its own motion, then the rest
    let steps: Vec<Step> = removals(&r.report.assembly_sequence, n).into_iter().rev().collect();
    let mut order = vec![handle, stick];
    order.extend((0..steps.len()).filter(|s| *s != handle && *s != stick));
    let removal: Vec<Step> = order.iter().rev().map(|&i| steps[i].clone()).collect();
    let world = checker(a, &settings).unwrap();
    let refused = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| verify_removals(world.world(), &removal)));
    assert!(refused.is_err(), "the stick went in through the handle");
}

/// The shipped real models (`tests/data`, all 17): their plans' graphs, 1,000 sampled extensions
/// each, every distinct one re-checked. One verifier per model sweeps each (step, part) pair once,
/// so the orders after the first few cost only their states' stability and bounds (all 17 models
/// in about 40 s, the goal in CI). `ASP_EXTENSIONS=N` samples N per model instead,
/// `ASP_EXTENSIONS_SKIP=NAME,...` leaves the models named out.
#[test]
fn the_shipped_models_precedence_graphs_hold_for_every_sampled_order() {
    use asp_geom::io::{load, LoadOptions};
    use asp_geom::math::Axis;
    let asked: Option<usize> = std::env::var("ASP_EXTENSIONS").ok().and_then(|v| v.parse().ok());
    let samples = asked.unwrap_or(1000);
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
    let z = LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() };
    let mm = LoadOptions { unit: asp_geom::Units::parse("mm"), up: Some(Axis::Z), ..LoadOptions::default() };
    let mut models: Vec<(String, Assembly)> = Vec::new();
    for m in ["pump", "pump-extension", "pump-threaded", "cube20", "cube81"] {
        models.push((m.into(), load(&data.join(m), &mm).unwrap()));
    }
    let mut glb: Vec<std::path::PathBuf> = ["beam", "ikea", "step", "bearing"]
        .iter()
        .flat_map(|d| std::fs::read_dir(data.join(d)).unwrap().map(|e| e.unwrap().path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    glb.sort();
    for p in glb {
        models.push((p.file_name().unwrap().to_string_lossy().into_owned(), load(&p, &z).unwrap()));
    }
    // `ASP_EXTENSIONS_SKIP=NAME,...` leaves models out of a long benchmark run
    let skip: Vec<String> = std::env::var("ASP_EXTENSIONS_SKIP").map(|v| v.split(',').map(str::to_string).collect()).unwrap_or_default();
    models.retain(|(what, _)| !skip.contains(what));
    let started = std::time::Instant::now();
    for (i, (what, a)) in models.iter().enumerate() {
        let t = std::time::Instant::now();
        let (g, distinct) = sampled_extensions_are_feasible(what, a.clone(), 100 + i as u64, samples);
        eprintln!(
            "{what}: {} steps, {} edges, {} levels, {distinct} distinct of {samples} orders re-checked in {:.2} s",
            g.steps.len(),
            g.edges.len(),
            g.levels.len(),
            t.elapsed().as_secs_f64()
        );
    }
    eprintln!("{} models in {:.1} s", models.len(), started.elapsed().as_secs_f64());
}
