//! The optimiser's figures for `docs/benchmarks.md`: distance-map build time, Pareto-MCTS
//! episodes per second on 1 and 2 threads, and the hypervolume reached after given times, on
//! random Soma cubes; and the fraction of the exact hypervolume on small cubes.
//!
//! ```text
//! cargo run --release -p asp-search --example optimise_figures -- speed 5 400      # 5×5×5, 400 episodes
//! cargo run --release -p asp-search --example optimise_figures -- hv 6 1,10,60     # HV after 1, 10, 60 s
//! cargo run --release -p asp-search --example optimise_figures -- exact 3 20       # 20 3×3×3 cubes
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
                let search =
                    ParetoMcts::builder().episodes(episodes).threads(threads).seed(1).build().expect("settings");
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
            let (mut sum, mut min, mut runs) = (0.0, f64::INFINITY, 0);
            for seed in 0..count {
                let cube = soma_cube(size, seed);
                let (mdp, _) = mdp(&cube);
                let t = Instant::now();
                let Ok(exact) = exact_front(&mdp, 5_000_000) else {
                    println!("  cube {seed}: too large for the exact front");
                    continue;
                };
                let exact_seconds = t.elapsed().as_secs_f64();
                if exact.solutions.is_empty() {
                    continue;
                }
                let reference: Vec<f64> = exact.worst.iter().map(|w| w - 1e-3 * w.abs().max(1.0)).collect();
                let out = ParetoMcts::builder()
                    .seed(seed)
                    .reference(reference.clone())
                    .build()
                    .expect("settings")
                    .solve(&mdp)
                    .expect("search");
                let fraction = out.value / exact.hypervolume(&reference);
                println!(
                    "  cube {seed}: {} parts, exact front {} points from {} states in {exact_seconds:.2} s; Pareto-MCTS {} points, HV fraction {fraction:.4}, {} episodes{}",
                    cube.len(),
                    exact.solutions.len(),
                    exact.states,
                    out.solutions.len(),
                    out.stats.episodes,
                    if out.stats.exhausted { " (exhausted)" } else { "" }
                );
                sum += fraction;
                min = min.min(fraction);
                runs += 1;
            }
            println!("mean HV fraction {:.4}, minimum {min:.4} over {runs} cubes", sum / runs as f64);
        }
        other => eprintln!("unknown mode '{other}' (speed, hv, exact)"),
    }
}
