//! The optimiser's figures for `docs/benchmarks.md`: distance-map build time, Pareto-MCTS
//! episodes per second on 1 and 2 threads, and the hypervolume reached after given times, on
//! random Soma cubes; and the fraction of the exact hypervolume on small cubes.
//!
//! ```text
//! cargo run --release -p asp-search --example optimise_figures -- speed 5 400      # 5×5×5, 400 episodes
//! cargo run --release -p asp-search --example optimise_figures -- hv 6 1,10,60     # HV after 1, 10, 60 s
//! cargo run --release -p asp-search --example optimise_figures -- exact 3 20       # 20 3×3×3 cubes
//! cargo run --release -p asp-search --example optimise_figures -- exact 4 3 10 2  # 10 s on 2 threads
//! cargo run --release -p asp-search --example optimise_figures -- small            # classic, profiles
//! cargo run --release -p asp-search --example optimise_figures -- maps             # map build times
//! ```

use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::Assembly;
use asp_search::exact::exact_front;
use asp_search::objective::parse_objectives;
use asp_search::{Mdp, ParetoMcts};
use rand::SeedableRng;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A random `size³` Soma cube of 5 cm cells from the generator (thesis Algorithm 1), on its
/// fixed floor slab.
pub fn soma_cube(size: usize, seed: u64) -> Assembly {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    asp_gen::SomaCube::random(size, &mut rng).expect("soma cube").to_assembly(0.05, "soma")
}

fn mdp(cube: &Assembly) -> (Mdp, f64) {
    let t = Instant::now();
    let maps = Arc::new(DistanceMaps::build(cube, &MapConfig::default()).expect("maps"));
    let seconds = t.elapsed().as_secs_f64();
    (Mdp::new(maps, parse_objectives("access,dirchange").expect("objectives")).expect("mdp"), seconds)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |k: usize, default: &str| args.get(k).cloned().unwrap_or_else(|| default.to_string());
    match arg(0, "speed").as_str() {
        "speed" => {
            let size: usize = arg(1, "5").parse().expect("size");
            let episodes: usize = arg(2, "400").parse().expect("episodes");
            let cube = soma_cube(size, 1);
            let (mdp, map_seconds) = mdp(&cube);
            println!("{size}x{size}x{size} Soma cube, {} parts: distance maps in {map_seconds:.3} s", cube.len());
            for threads in [1, 2] {
                let search = ParetoMcts::builder().episodes(episodes).threads(threads).seed(1).build().expect("settings");
                let out = search.solve(&mdp).expect("search");
                let s = out.stats;
                println!(
                    "  {threads} thread(s): {} episodes in {:.3} s = {:.0} episodes/s, {:.0} iterations/s, {:.2} M rollout steps/s; front {}",
                    s.episodes,
                    s.seconds,
                    s.episodes as f64 / s.seconds,
                    s.iterations as f64 / s.seconds,
                    s.rollout_steps as f64 / s.seconds / 1e6,
                    out.solutions.len()
                );
            }
        }
        "hv" => {
            let size: usize = arg(1, "5").parse().expect("size");
            let times: Vec<f64> = arg(2, "1,10,60").split(',').map(|t| t.parse().expect("seconds")).collect();
            let threads: usize = arg(3, "2").parse().expect("threads");
            let cube = soma_cube(size, 1);
            let (mdp, _) = mdp(&cube);
            println!("{size}x{size}x{size} Soma cube, {} parts, {threads} threads", cube.len());
            for t in times {
                let search = ParetoMcts::builder()
                    .episodes(usize::MAX / 2)
                    .threads(threads)
                    .seed(1)
                    .time_limit(Duration::from_secs_f64(t))
                    .build()
                    .expect("settings");
                let out = search.solve(&mdp).expect("search");
                println!(
                    "  after {t:>4} s: hypervolume {:.1} (reference {:?}), front {}, {} episodes, {} tree nodes",
                    out.value,
                    out.reference,
                    out.solutions.len(),
                    out.stats.episodes,
                    out.stats.tree_nodes
                );
            }
        }
        "exact" => {
            let size: usize = arg(1, "3").parse().expect("size");
            let count: u64 = arg(2, "20").parse().expect("count");
            // optional: search for this many seconds (episodes unbounded) on this many threads
            // instead of the default budget
            let time = args.get(3).map(|t| Duration::from_secs_f64(t.parse().expect("seconds")));
            let threads: usize = arg(4, "1").parse().expect("threads");
            let fractions: Vec<f64> = (0..count)
                .filter_map(|seed| exact_fraction(&format!("cube {seed}"), &soma_cube(size, seed), seed, time, threads))
                .collect();
            summary(&fractions);
        }
        "small" => {
            let mut instances = vec![("classic Soma cube".to_string(), asp_gen::SomaCube::classic().to_assembly(0.05, "classic"))];
            for (supports, seed) in [(1, 0), (2, 1)] {
                instances.push((format!("profiles, {supports} supports, seed {seed}"), small_profiles(supports, seed)));
            }
            let fractions: Vec<f64> = instances.iter().filter_map(|(name, a)| exact_fraction(name, a, 0, None, 1)).collect();
            summary(&fractions);
        }
        "maps" => {
            let double = asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::double_layer(), 1)
                .expect("profiles")
                .to_assembly("double layer");
            let models = [("6x6x6 Soma cube", soma_cube(6, 1)), ("double-layer profile assembly", double)];
            for (name, a) in models {
                let mut best = f64::INFINITY;
                for _ in 0..5 {
                    let t = Instant::now();
                    let maps = DistanceMaps::build(&a, &MapConfig::default()).expect("maps");
                    best = best.min(t.elapsed().as_secs_f64());
                    std::hint::black_box(maps);
                }
                let removable = a.parts.iter().filter(|p| !p.fixed).count();
                println!("{name}: {} parts ({removable} removable), all distance maps in {best:.3} s (best of 5)", a.len());
            }
        }
        "sweep" => {
            // exact fronts once, then Pareto-MCTS for SECONDS on THREADS with each exploration
            // constant and local search share of two lists:
            // `sweep SIZE COUNT SECONDS THREADS c1,c2,... share1,share2,...`
            let size: usize = arg(1, "4").parse().expect("size");
            let count: u64 = arg(2, "3").parse().expect("count");
            let time = Duration::from_secs_f64(arg(3, "10").parse().expect("seconds"));
            let threads: usize = arg(4, "1").parse().expect("threads");
            let cs: Vec<f64> = arg(5, "0.7071").split(',').map(|c| c.parse().expect("exploration")).collect();
            let shares: Vec<f64> = arg(6, "0.25").split(',').map(|c| c.parse().expect("local search share")).collect();
            let cubes: Vec<_> = (0..count)
                .map(|seed| {
                    let cube = soma_cube(size, seed);
                    let (mdp, _) = mdp(&cube);
                    let t = Instant::now();
                    let exact = exact_front(&mdp, 5_000_000).expect("exact front");
                    println!(
                        "cube {seed}: exact front {} points, {} states in {:.2} s",
                        exact.solutions.len(),
                        exact.states,
                        t.elapsed().as_secs_f64()
                    );
                    (seed, mdp, exact)
                })
                .collect();
            for (c, share) in cs.iter().flat_map(|&c| shares.iter().map(move |&s| (c, s))) {
                let mut fractions = Vec::new();
                for (seed, mdp, exact) in &cubes {
                    let reference: Vec<f64> = exact.worst.iter().map(|w| w - 1e-3 * w.abs().max(1.0)).collect();
                    let out = ParetoMcts::builder()
                        .seed(*seed)
                        .threads(threads)
                        .reference(reference.clone())
                        .episodes(usize::MAX)
                        .time_limit(time)
                        .exploration(c)
                        .polish(share)
                        .build()
                        .expect("settings")
                        .solve(mdp)
                        .expect("search");
                    let f = out.value / exact.hypervolume(&reference);
                    println!("  c {c}, polish {share}: cube {seed}: HV fraction {f:.4}, {} episodes, {} nodes, {} polish steps, {} polished, {} iterations + {} rollout steps", out.stats.episodes, out.stats.tree_nodes, out.stats.polish_steps, out.stats.polished, out.stats.iterations, out.stats.rollout_steps);
                    fractions.push(f);
                }
                summary(&fractions);
            }
        }
        other => eprintln!("unknown mode '{other}' (speed, hv, exact, sweep, small, maps)"),
    }
}

/// A small aluminium profile assembly (thesis 4.1): the base cuboid with `supports` support
/// profiles and no layers, its connectors fixed to the frame: 6 + 2 × `supports` removable
/// profiles.
fn small_profiles(supports: usize, seed: u64) -> Assembly {
    let params = asp_gen::ProfileParams { layers: 0, supports, ..asp_gen::ProfileParams::single_layer() };
    let mut a = asp_gen::ProfileAssembly::generate(&params, seed).expect("profiles").to_assembly("profiles");
    for p in a.parts.iter_mut().filter(|p| p.name.contains("connector")) {
        p.fixed = true;
    }
    a
}

/// Pareto-MCTS with the default budget (1000 episodes, 1 thread, `seed`) against the exact
/// front: the fraction of its hypervolume reached, with the tight reference point just below
/// the worst total of each objective over all feasible sequences. `None` when the exact front
/// is out of reach or there is no sequence.
/// The Pareto-MCTS hypervolume as a fraction of the exact front's: with the default budget, or
/// for `time` (episodes unbounded) on `threads`.
fn exact_fraction(name: &str, assembly: &Assembly, seed: u64, time: Option<Duration>, threads: usize) -> Option<f64> {
    let (mdp, _) = mdp(assembly);
    let t = Instant::now();
    let Ok(exact) = exact_front(&mdp, 5_000_000) else {
        println!("  {name}: too large for the exact front");
        return None;
    };
    let exact_seconds = t.elapsed().as_secs_f64();
    if exact.solutions.is_empty() {
        return None;
    }
    let reference: Vec<f64> = exact.worst.iter().map(|w| w - 1e-3 * w.abs().max(1.0)).collect();
    let mut builder = ParetoMcts::builder().seed(seed).threads(threads).reference(reference.clone());
    if let Some(t) = time {
        builder = builder.episodes(usize::MAX).time_limit(t);
    }
    let out = builder.build().expect("settings").solve(&mdp).expect("search");
    let fraction = out.value / exact.hypervolume(&reference);
    println!(
        "  {name}: {} parts, exact front {} points from {} states in {exact_seconds:.2} s; Pareto-MCTS {} points, HV fraction {fraction:.4}, {} episodes{}",
        assembly.len(),
        exact.solutions.len(),
        exact.states,
        out.solutions.len(),
        out.stats.episodes,
        if out.stats.exhausted { " (exhausted)" } else { "" }
    );
    Some(fraction)
}

fn summary(fractions: &[f64]) {
    let mean = fractions.iter().sum::<f64>() / fractions.len() as f64;
    let min = fractions.iter().copied().fold(f64::INFINITY, f64::min);
    println!("mean HV fraction {mean:.4}, minimum {min:.4} over {} instances", fractions.len());
}
