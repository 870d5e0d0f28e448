//! The generic RRT-Connect on toy planar spaces.

use super::*;
use rand::RngExt;

/// The unit square with a wall at x = 0.5 from y = 0 to 0.8.
struct Square;

impl Space for Square {
    type State = [f64; 2];
    fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        [rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)]
    }
    fn valid(&self, s: &[f64; 2]) -> bool {
        !((s[0] - 0.5).abs() < 0.02 && s[1] < 0.8)
    }
    fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
        [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
    }
    fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
    }
    fn edge_resolution(&self) -> f64 {
        0.005
    }
}

#[test]
fn goes_around_the_wall_and_is_deterministic() {
    let cfg = RrtConnectConfig { step: 0.1, seed: 3, ..Default::default() };
    let path = rrt_connect(&Square, &[0.2, 0.1], &[0.8, 0.1], &cfg).unwrap();
    assert_eq!(path.first(), Some(&[0.2, 0.1]));
    assert_eq!(path.last(), Some(&[0.8, 0.1]));
    for w in path.windows(2) {
        assert!(Square.edge_valid(&w[0], &w[1]));
    }
    // it must pass above the wall
    assert!(path.iter().any(|s| s[1] > 0.78), "{path:?}");
    assert_eq!(path, rrt_connect(&Square, &[0.2, 0.1], &[0.8, 0.1], &cfg).unwrap());
    assert_eq!(rrt_connect(&Square, &[0.5, 0.1], &[0.8, 0.1], &cfg), Err(RrtFailure::InvalidStart));
}

/// The unit square with a ring around (0.8, 0.8): its inside cannot be reached.
struct Boxed;

impl Space for Boxed {
    type State = [f64; 2];
    fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        Square.sample(rng)
    }
    fn valid(&self, s: &[f64; 2]) -> bool {
        let r = ((s[0] - 0.8).powi(2) + (s[1] - 0.8).powi(2)).sqrt();
        !(0.1..0.15).contains(&r)
    }
    fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
        Square.interpolate(a, b, t)
    }
    fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
        Square.distance(a, b)
    }
    fn edge_resolution(&self) -> f64 {
        0.005
    }
}

#[test]
fn an_enclosed_goal_is_not_reached() {
    let cfg = RrtConnectConfig { step: 0.1, max_iterations: 300, seed: 1, lazy: false };
    assert_eq!(rrt_connect(&Boxed, &[0.1, 0.1], &[0.8, 0.8], &cfg), Err(RrtFailure::Exhausted));
}

/// The goal tree grows from every goal root: the path ends at the one outside the ring (the
/// SE(3) planner's goal roots, one per direction).
#[test]
fn the_trees_meet_at_a_reachable_goal_root() {
    let growth = Growth { step: 0.1, max_iterations: 300, deadline: None };
    let goals = [[0.8, 0.8], [0.1, 0.9]];
    let path = connect_trees(&Boxed, &[[0.1, 0.1]], &goals, &growth, &mut ChaCha8Rng::seed_from_u64(1)).expect("the second goal is free");
    assert_eq!(path.first(), Some(&[0.1, 0.1]));
    assert_eq!(path.last(), Some(&[0.1, 0.9]));
    for w in path.windows(2) {
        assert!(Boxed.distance(&w[0], &w[1]) <= 0.1 + 1e-12 && Boxed.step_valid(&w[0], &w[1]), "{path:?}");
    }
    // the enclosed goal alone is not reached
    assert_eq!(connect_trees(&Boxed, &[[0.1, 0.1]], &goals[..1], &growth, &mut ChaCha8Rng::seed_from_u64(1)), None);
}

/// A deadline already past: no sample is drawn, no path; without it the same search succeeds.
#[test]
fn a_past_deadline_stops_before_the_first_sample() {
    struct Counted(std::cell::Cell<usize>);
    impl Space for Counted {
        type State = [f64; 2];
        fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
            self.0.set(self.0.get() + 1);
            Square.sample(rng)
        }
        fn valid(&self, s: &[f64; 2]) -> bool {
            Square.valid(s)
        }
        fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
            Square.interpolate(a, b, t)
        }
        fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
            Square.distance(a, b)
        }
        fn edge_resolution(&self) -> f64 {
            0.005
        }
    }
    let space = Counted(std::cell::Cell::new(0));
    let now = Instant::now();
    std::thread::sleep(std::time::Duration::from_millis(2));
    let past = Growth { step: 0.1, max_iterations: 2000, deadline: Some(now) };
    assert_eq!(connect_trees(&space, &[[0.2, 0.1]], &[[0.8, 0.1]], &past, &mut ChaCha8Rng::seed_from_u64(3)), None);
    assert_eq!(space.0.get(), 0);
    let open = Growth { deadline: None, ..past };
    assert!(connect_trees(&space, &[[0.2, 0.1]], &[[0.8, 0.1]], &open, &mut ChaCha8Rng::seed_from_u64(3)).is_some());
    assert!(space.0.get() > 0);
}

/// A space whose step check covers the new node (the SE(3) planner's exact edges) is never asked
/// for [`Space::valid`] while the trees grow: here every configuration is "invalid", and the
/// trees still meet because only [`Space::step_valid`] is consulted.
#[test]
fn the_step_check_replaces_the_node_and_edge_checks() {
    struct ExactEdges;
    impl Space for ExactEdges {
        type State = [f64; 2];
        fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
            Square.sample(rng)
        }
        fn valid(&self, _: &[f64; 2]) -> bool {
            false
        }
        fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
            Square.interpolate(a, b, t)
        }
        fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
            Square.distance(a, b)
        }
        fn edge_resolution(&self) -> f64 {
            f64::INFINITY
        }
        fn step_valid(&self, _: &[f64; 2], _: &[f64; 2]) -> bool {
            true
        }
    }
    let growth = Growth { step: 0.1, max_iterations: 50, deadline: None };
    let path =
        connect_trees(&ExactEdges, &[[0.2, 0.1]], &[[0.8, 0.1]], &growth, &mut ChaCha8Rng::seed_from_u64(0)).expect("every step is free");
    assert_eq!((path.first(), path.last()), (Some(&[0.2, 0.1]), Some(&[0.8, 0.1])));
}

/// A wall at `|x − 0.5| < half`, `y < 0.8` in the unit square, checked every 2 mm along edges;
/// counts the configurations checked.
struct Wall {
    half: f64,
    checks: std::cell::Cell<usize>,
}

impl Wall {
    fn new(half: f64) -> Wall {
        Wall { half, checks: std::cell::Cell::new(0) }
    }
}

impl Space for Wall {
    type State = [f64; 2];
    fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        Square.sample(rng)
    }
    fn valid(&self, s: &[f64; 2]) -> bool {
        self.checks.set(self.checks.get() + 1);
        !((s[0] - 0.5).abs() < self.half && s[1] < 0.8)
    }
    fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
        Square.interpolate(a, b, t)
    }
    fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
        Square.distance(a, b)
    }
    fn edge_resolution(&self) -> f64 {
        0.002
    }
}

/// Plans around `space`'s wall with and without lazy edges; every path returned passes every
/// edge check, goes around the wall and is the same for the same seed. Returns the
/// configurations checked, eager then lazy.
fn around_the_wall(half: f64, seed: u64) -> [usize; 2] {
    [false, true].map(|lazy| {
        let space = Wall::new(half);
        let cfg = RrtConnectConfig { step: 0.1, max_iterations: 3000, seed, lazy };
        let path = rrt_connect(&space, &[0.2, 0.1], &[0.8, 0.1], &cfg).expect("a path around the wall");
        let checks = space.checks.get();
        assert_eq!((path.first(), path.last()), (Some(&[0.2, 0.1]), Some(&[0.8, 0.1])));
        for w in path.windows(2) {
            assert!(space.edge_valid(&w[0], &w[1]), "lazy {lazy}: {path:?}");
        }
        assert!(path.iter().any(|s| s[1] > 0.79), "lazy {lazy}: through the wall: {path:?}");
        assert_eq!(path, rrt_connect(&Wall::new(half), &[0.2, 0.1], &[0.8, 0.1], &cfg).unwrap());
        checks
    })
}

/// Lazy edges: a wall thinner than a step lets nodes stand on both sides of it, so the trees
/// meet across it and only the check of the path's edges finds the crossing, which it cuts off;
/// the path returned still passes every edge check, around the wall.
#[test]
fn lazy_edges_cut_what_crosses_a_thin_wall() {
    for seed in 0..4 {
        around_the_wall(0.003, seed);
    }
}

/// Lazy edges check fewer configurations where the trees grow edges no path uses: around a
/// wall thicker than a step, every seed.
#[test]
fn lazy_edges_check_fewer_configurations() {
    for seed in 0..4 {
        let [eager, lazy] = around_the_wall(0.15, seed);
        assert!(lazy < eager, "seed {seed}: lazy {lazy} checks, eager {eager}");
    }
}
