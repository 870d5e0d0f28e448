//! Pareto-MCTS: ≥ 99 % of the exact hypervolume within the default budget on instances with
//! exact fronts, feasible and mutually non-dominated answers, reproducible threads.

use crate::fixtures::{close, exact_instances, figure_6_2, maps, problem, soma};
use asp_search::exact::exact_front;
use asp_search::hypervolume::dominates;
use asp_search::ParetoMcts;
use asp_search::Status;

#[test]
fn figure_6_2_front() {
    let maps = maps(&figure_6_2(), 3);
    let p = problem(&maps, "access,dirchange");
    let out = ParetoMcts::builder().seed(1).build().unwrap().solve(&p).unwrap();
    assert_eq!(*out.status(), Status::Found);
    assert_eq!(out.solutions.len(), 1);
    assert_eq!(out.solutions[0].sequence, vec![2, 1, 0]);
    assert_eq!(out.solutions[0].values[1], 3.0);
}

#[test]
fn reaches_99_percent_of_the_exact_hypervolume_on_instances_with_exact_references() {
    let mut checked = 0;
    for (seed, (name, assembly)) in exact_instances().into_iter().enumerate() {
        let maps = maps(&assembly, 5);
        for objectives in ["access,dirchange", "access,pathlen", "access,dirchange,pathlen"] {
            let p = problem(&maps, objectives);
            let exact = exact_front(&p, 2_000_000).unwrap();
            if exact.solutions.is_empty() {
                continue;
            }
            // a tight reference: just below the worst total of every objective
            let reference: Vec<f64> = exact.worst.iter().map(|w| w - 1e-3 * w.abs().max(1.0)).collect();
            let out = ParetoMcts::builder().seed(seed as u64).reference(reference.clone()).build().unwrap().solve(&p).unwrap();
            let hv_exact = exact.hypervolume(&reference);
            assert!(
                out.value >= 0.99 * hv_exact,
                "{name} ({} parts) {objectives}: {} of exact {hv_exact} ({} of {} points, {} episodes)",
                maps.num_parts(),
                out.value,
                out.solutions.len(),
                exact.solutions.len(),
                out.stats.episodes
            );
            for (i, s) in out.solutions.iter().enumerate() {
                let (v, _) = p.evaluate(&s.sequence).unwrap();
                assert!(v.iter().zip(&s.values).all(|(a, b)| close(*a, *b)));
                for t in &out.solutions[i + 1..] {
                    assert!(!dominates(&s.values, &t.values) && !dominates(&t.values, &s.values));
                }
                // no answer lies beyond the exact front
                assert!(exact.solutions.iter().any(|e| e.values.iter().zip(&s.values).all(|(a, b)| *a >= *b - 1e-9 * b.abs().max(1.0))));
            }
            checked += 1;
        }
    }
    assert!(checked >= 25, "{checked}");
}

#[test]
fn threads_are_reproducible_and_merge_fronts() {
    let cube = soma(4, 21);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    let run = |threads| ParetoMcts::builder().episodes(20).threads(threads).seed(9).build().unwrap().solve(&p).unwrap();
    let (a, b) = (run(1), run(1));
    assert_eq!(a.solutions, b.solutions);
    let (c, d) = (run(2), run(2));
    assert_eq!(c.solutions, d.solutions);
    assert_eq!(c.stats.threads, 2);
    assert_eq!(c.stats.episodes, 20);
    for s in &c.solutions {
        p.evaluate(&s.sequence).unwrap();
    }
    // the trace is monotone in the hypervolume and ends with the answer's value
    let t = &c.trace;
    assert!(t.windows(2).all(|w| w[1].value >= w[0].value - 1e-9));
    assert!(close(t.last().unwrap().value, c.value));
    let mut csv = Vec::new();
    c.write_trace_csv(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    assert!(csv.starts_with("episode,iterations,seconds,value,front_size\n"));
    assert_eq!(csv.lines().count(), t.len() + 1);
}

#[test]
fn the_graph_read_out_is_exact_once_the_root_is_solved() {
    // 3×3×3 cubes: the graph is explored completely within the default budget, and the front
    // read off it equals the exact one point for point
    for seed in 0..3 {
        let cube = soma(3, seed);
        let maps = maps(&cube, 5);
        let p = problem(&maps, "access,dirchange");
        let exact = exact_front(&p, 1_000_000).unwrap();
        let out = ParetoMcts::builder().seed(seed).build().unwrap().solve(&p).unwrap();
        assert!(out.stats.exhausted, "seed {seed}");
        assert_eq!(out.solutions.len(), exact.solutions.len(), "seed {seed}");
        for (s, e) in out.solutions.iter().zip(&exact.solutions) {
            assert!(s.values.iter().zip(&e.values).all(|(a, b)| close(*a, *b)), "{:?} vs {:?}", s.values, e.values);
        }
    }
}

#[test]
fn local_search_lifts_the_front_and_its_answers_replay() {
    // a 4×4×4 cube after 100 episodes: block moves around the search's sequences find better
    // ones (the front's hypervolume grows), each answer replays to the values it reports, and
    // the polished search is as reproducible as the plain one
    let cube = soma(4, 21);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    let run = |share: f64| ParetoMcts::builder().episodes(100).seed(3).polish(share).build().unwrap().solve(&p).unwrap();
    let (plain, polished) = (run(0.0), run(0.25));
    assert_eq!(plain.stats.polish_steps, 0);
    assert!(polished.stats.polished > 0 && polished.stats.polish_steps > 0);
    // the tree search itself is the same search: the local search only adds to the archive
    assert_eq!(plain.stats.iterations, polished.stats.iterations);
    assert!(polished.value > plain.value * 1.01, "{} vs {}", polished.value, plain.value);
    for s in &polished.solutions {
        let (v, _) = p.evaluate(&s.sequence).unwrap();
        assert!(v.iter().zip(&s.values).all(|(a, b)| close(*a, *b)), "{v:?} vs {:?}", s.values);
    }
    // every plain answer is matched or beaten
    for s in &plain.solutions {
        assert!(polished.solutions.iter().any(|t| t.values.iter().zip(&s.values).all(|(a, b)| *a >= *b - 1e-9 * b.abs().max(1.0))));
    }
    assert_eq!(run(0.25).solutions, polished.solutions);
    assert!(ParetoMcts::builder().polish(-1.0).build().is_err());
}
