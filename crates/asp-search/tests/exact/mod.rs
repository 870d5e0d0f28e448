//! The exact references agree with brute force: the dynamic programme's front is the
//! non-dominated set of all enumerated sequences, its optimum their maximum, its worst point their
//! minimum.

use crate::fixtures::{close, exact_instances, maps, problem, soma};
use asp_search::exact::{enumerate_sequences, exact_front};
use asp_search::hypervolume::{weakly_dominates, ParetoFront};

#[test]
fn dynamic_programme_equals_enumeration() {
    let mut checked = 0;
    for (seed, (_, cube)) in exact_instances().into_iter().enumerate() {
        let maps = maps(&cube, 5);
        for objectives in ["access,dirchange", "access,dirchange,pathlen", "access", "dirchange", "pathlen"] {
            let p = problem(&maps, objectives);
            let Ok(all) = enumerate_sequences(&p, 200_000) else { continue };
            let exact = exact_front(&p, 1_000_000).unwrap();
            if all.is_empty() {
                assert!(exact.solutions.is_empty());
                continue;
            }
            checked += 1;
            // every sequence is feasible and its vector is what evaluate says
            for s in all.iter().take(50) {
                let (v, _) = p.evaluate(&s.sequence).unwrap();
                assert!(v.iter().zip(&s.values).all(|(a, b)| close(*a, *b)));
            }
            let mut brute: ParetoFront<()> = ParetoFront::new(p.num_objectives());
            for s in &all {
                brute.insert(&s.values, || ());
            }
            assert_eq!(brute.len(), exact.solutions.len(), "seed {seed} {objectives}");
            for s in &exact.solutions {
                let (v, _) = p.evaluate(&s.sequence).unwrap();
                assert!(v.iter().zip(&s.values).all(|(a, b)| close(*a, *b)), "{v:?} vs {:?}", s.values);
                assert!(brute.iter().any(|(q, _)| q.iter().zip(&s.values).all(|(a, b)| close(*a, *b))));
            }
            // nothing enumerated beats the front; the worst point bounds everything from below
            for s in &all {
                assert!(exact
                    .solutions
                    .iter()
                    .any(|e| { e.values.iter().zip(&s.values).all(|(a, b)| *a >= *b - 1e-9 * b.abs().max(1.0)) }));
                assert!(weakly_dominates(&s.values, &exact.worst.iter().map(|w| w - 1e-9 * w.abs().max(1.0)).collect::<Vec<_>>()));
            }
            for k in 0..p.num_objectives() {
                let min = all.iter().map(|s| s.values[k]).fold(f64::INFINITY, f64::min);
                assert!(close(min, exact.worst[k]), "{min} vs {}", exact.worst[k]);
            }
        }
    }
    assert!(checked >= 30, "only {checked} instances were small enough");
}

#[test]
fn limits_are_errors() {
    let cube = soma(3, 1);
    let maps = maps(&cube, 3);
    let p = problem(&maps, "access");
    assert!(enumerate_sequences(&p, 1).is_err());
    assert!(exact_front(&p, 1).is_err());
}
