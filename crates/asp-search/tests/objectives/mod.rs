//! Objectives hand-computed on the figure 6.2 fixture (N_M = 3: four horizontal axes, four
//! horizontal diagonals and up; d_max = the diagonal of the 3×3×3 box, 3√3).
//!
//! Free directions: top {up} in the full state, {up, +x} once the ball is gone; ball {+x}
//! always; base every direction once alone. Minimum-map sums (a = d_max): top a, ball a in the
//! full state; ball a + 1 without the top (it slides one cell along -x to the base's wall); top
//! 2a without the ball; base 9a alone. Two sequences are feasible (the base supports the others):
//!   top, ball, base: access a + (a + 1) + 9a = 11a + 1; dirchange 1 + 0 (H = {up} and {+x} do
//!   not meet: a direction change resets H to {+x}) + 1 = 2
//!   ball, top, base: access a + 2a + 9a = 12a; dirchange 1 + 1 + 1 = 3

use crate::fixtures::{close, figure_6_2, maps, problem};
use asp_geom::distmap::MapState;
use asp_search::exact::{enumerate_sequences, exact_front};
use asp_search::objective::direction_changes;
use asp_search::{DirHistory, DirectionChanges, Objective, SearchError, StepContext, StepKind};

#[test]
fn figure_6_2_by_hand() {
    let maps = maps(&figure_6_2(), 3);
    let a = 27f64.sqrt();
    assert!(close(maps.d_max() as f64, a) || (maps.d_max() as f64 - a).abs() < 1e-5);
    let a = maps.d_max() as f64;
    let p = problem(&maps, "access,dirchange");
    let (v1, _) = p.evaluate(&[1, 2, 0]).unwrap();
    let (v2, motions) = p.evaluate(&[2, 1, 0]).unwrap();
    assert!((v1[0] - (11.0 * a + 1.0)).abs() < 1e-4, "{v1:?}");
    assert_eq!(v1[1], 2.0);
    assert!((v2[0] - 12.0 * a).abs() < 1e-4, "{v2:?}");
    assert_eq!(v2[1], 3.0);
    // one direction change in the first sequence (top up, then the ball along +x)
    assert_eq!(direction_changes(&maps, &[1, 2, 0]), 1);
    assert_eq!(direction_changes(&maps, &[2, 1, 0]), 0);
    // the ball leaves along +x first
    match &motions[0] {
        asp_geom::Motion::Linear { direction, .. } => assert!((direction.x - 1.0).abs() < 1e-6),
        other => panic!("{other:?}"),
    }
    // removing the base before the others drops them; incomplete sequences are rejected
    assert!(matches!(p.evaluate(&[0, 1, 2]), Err(SearchError::Infeasible { .. })));
    assert!(matches!(p.evaluate(&[1, 0, 2]), Err(SearchError::Infeasible { .. })));
    assert!(matches!(p.evaluate(&[1, 2]), Err(SearchError::Infeasible { .. })));
    // exactly two feasible sequences, and the second dominates
    let all = enumerate_sequences(&p, 100).unwrap();
    let seqs: Vec<Vec<usize>> = all.iter().map(|s| s.sequence.clone()).collect();
    assert_eq!(seqs, vec![vec![1, 2, 0], vec![2, 1, 0]]);
    let front = exact_front(&p, 1000).unwrap();
    assert_eq!(front.solutions.len(), 1);
    assert_eq!(front.solutions[0].sequence, vec![2, 1, 0]);
    assert!((front.worst[0] - (11.0 * a + 1.0)).abs() < 1e-4);
    assert_eq!(front.worst[1], 2.0);
}

#[test]
fn direction_change_resets_h_step_by_step() {
    let maps = maps(&figure_6_2(), 3);
    let h = maps.hemisphere();
    let up = h.up_index();
    let plus_x = h.nearest(asp_geom::math::Vec3::X);
    let mut state = MapState::new(&maps);
    let p = problem(&maps, "dirchange");
    let mut memory = [0u64; DirHistory::WORDS];
    let o = DirectionChanges;
    let reward = |part: usize, state: &mut MapState<'_>, memory: &mut [u64]| {
        o.reward(&mut StepContext::new(&p, state, part, StepKind::Simulation), memory)
    };
    // top: H = {up}, Ĥ = 1
    assert_eq!(reward(1, &mut state, &mut memory), 1.0);
    assert_eq!(DirHistory::load(&memory).mask.iter().collect::<Vec<_>>(), vec![up]);
    state.remove(1);
    // ball: {+x} ∩ {up} = ∅ → a direction change: Ĥ = 0 and H restarts as {+x}
    assert_eq!(reward(2, &mut state, &mut memory), 0.0);
    assert_eq!(DirHistory::load(&memory).mask.iter().collect::<Vec<_>>(), vec![plus_x]);
    state.remove(2);
    // base: all nine directions ∩ {+x} = {+x}: Ĥ = 1
    assert_eq!(reward(0, &mut state, &mut memory), 1.0);
}

#[test]
fn path_length_by_hand() {
    let maps = maps(&figure_6_2(), 3);
    let p = problem(&maps, "pathlen");
    // ball first: +x, clears the others' box (x up to 3) after 1; top: up or +x, clears the
    // base's box (z and x up to 3) after 2; base alone: 0
    let (v, _) = p.evaluate(&[2, 1, 0]).unwrap();
    assert!((v[0] + 3.0).abs() < 1e-6, "{v:?}");
    // top first: only up, 2; ball: +x, 1; base 0
    let (v, _) = p.evaluate(&[1, 2, 0]).unwrap();
    assert!((v[0] + 3.0).abs() < 1e-6, "{v:?}");
}
