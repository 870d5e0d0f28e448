//! Hypervolume: exact 2-D against hand values, the general-d recursion against the 2-D sweep
//! on 2-D inputs, and against inclusion–exclusion and Monte Carlo on small 3-D and 4-D sets.

use asp_search::hypervolume::{dominates, hypervolume, hypervolume_2d, ParetoFront};
use rand::{RngExt, SeedableRng};

fn rng(seed: u64) -> rand_chacha::ChaCha8Rng {
    rand_chacha::ChaCha8Rng::seed_from_u64(seed)
}

/// Σ over non-empty subsets S of (-1)^{|S|+1} · vol(box(reference, min over S)).
fn inclusion_exclusion(points: &[Vec<f64>], reference: &[f64]) -> f64 {
    let n = points.len();
    let mut total = 0.0;
    for mask in 1u32..(1 << n) {
        let mut corner: Vec<f64> = vec![f64::INFINITY; reference.len()];
        for (i, p) in points.iter().enumerate() {
            if mask & (1 << i) != 0 {
                for (c, v) in corner.iter_mut().zip(p) {
                    *c = c.min(*v);
                }
            }
        }
        let vol: f64 = corner.iter().zip(reference).map(|(c, r)| (c - r).max(0.0)).product();
        total += if mask.count_ones() % 2 == 1 { vol } else { -vol };
    }
    total
}

#[test]
fn two_d_hand_values() {
    // an L of two points from (0,0): 4×1 + 1×(3-1) = 6
    assert_eq!(hypervolume_2d(&[[4.0, 1.0], [1.0, 3.0]], [0.0, 0.0]), 6.0);
    // negative coordinates and a reference below: (-1 - -3)(2 - 0) + (-2 - -3)(5 - 2) = 4 + 3
    assert_eq!(hypervolume_2d(&[[-1.0, 2.0], [-2.0, 5.0]], [-3.0, 0.0]), 7.0);
    // equal x, different y: only the higher one counts
    assert_eq!(hypervolume_2d(&[[2.0, 1.0], [2.0, 3.0]], [0.0, 0.0]), 6.0);
}

#[test]
fn general_d_equals_2d_sweep() {
    let mut r = rng(1);
    for _ in 0..200 {
        let n = r.random_range(1..20);
        let pts: Vec<[f64; 2]> = (0..n).map(|_| [r.random_range(-1.0..5.0), r.random_range(-1.0..5.0)]).collect();
        let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
        let a = hypervolume(&refs, &[0.0, 0.0]);
        let b = hypervolume_2d(&pts, [0.0, 0.0]);
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
}

#[test]
fn three_and_four_d_equal_inclusion_exclusion() {
    let mut r = rng(2);
    for d in [3, 4] {
        for _ in 0..100 {
            let n = r.random_range(1..9);
            let pts: Vec<Vec<f64>> = (0..n).map(|_| (0..d).map(|_| r.random_range(0.0..3.0)).collect()).collect();
            let reference = vec![0.5; d];
            let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
            let a = hypervolume(&refs, &reference);
            let b = inclusion_exclusion(&pts, &reference);
            assert!((a - b).abs() < 1e-9, "d={d}: {a} vs {b}");
        }
    }
}

#[test]
fn three_d_matches_monte_carlo() {
    let mut r = rng(3);
    let pts: Vec<Vec<f64>> = (0..30).map(|_| (0..3).map(|_| r.random_range(0.0..1.0)).collect()).collect();
    let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
    let exact = hypervolume(&refs, &[0.0, 0.0, 0.0]);
    let samples = 200_000;
    let mut hits = 0;
    for _ in 0..samples {
        let z: [f64; 3] = [r.random(), r.random(), r.random()];
        if pts.iter().any(|p| p.iter().zip(&z).all(|(a, b)| a >= b)) {
            hits += 1;
        }
    }
    let estimate = hits as f64 / samples as f64;
    // standard error ≤ 0.5/√n ≈ 0.0011
    assert!((estimate - exact).abs() < 0.006, "{estimate} vs {exact}");
}

#[test]
fn front_keeps_only_non_dominated_points() {
    let mut r = rng(4);
    let mut front = ParetoFront::new(3);
    let mut all = Vec::new();
    for i in 0..300 {
        let p: Vec<f64> = (0..3).map(|_| r.random_range(0.0..10.0f64).floor()).collect();
        front.insert(&p, || i);
        all.push(p);
    }
    for (p, _) in front.iter() {
        assert!(!all.iter().any(|q| dominates(q, p)));
    }
    for q in &all {
        assert!(front.covers(q));
    }
    let refs: Vec<&[f64]> = all.iter().map(|p| p.as_slice()).collect();
    let hv_all = hypervolume(&refs, &[0.0; 3]);
    assert!((front.hypervolume(&[0.0; 3]) - hv_all).abs() < 1e-9);
}
