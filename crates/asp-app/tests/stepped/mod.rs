//! The stepped search: `solve_stepped` and `SteppedSearch` run the same loop as
//! `solve` and `asp plan --objective`, episode by episode, and a policy swapped in between two
//! episodes guides exactly the episodes after it.

use crate::fixtures::{maps, problem, soma};
use asp_app::pipeline::{self, OptimiseSettings, PlanSettings};
use asp_app::stepped::SteppedSearch;
use asp_geom::distmap::MapState;
use asp_search::policy::{argmax, EpsilonGreedy, ImmediateReward, Policy};
use asp_search::{EpisodeEnd, Mcts, Mdp, Next, ParetoMcts, SearchOutcome, StepKind, Transition};
use std::sync::Arc;

fn same(a: &SearchOutcome, b: &SearchOutcome, what: &str) {
    assert_eq!(a.solutions, b.solutions, "{what}: solutions");
    assert_eq!(a.value, b.value, "{what}: value");
    assert_eq!(a.stats.episodes, b.stats.episodes, "{what}: episodes");
    assert_eq!(a.stats.iterations, b.stats.iterations, "{what}: iterations");
    assert_eq!(a.stats.rollout_steps, b.stats.rollout_steps, "{what}: rollout steps");
    assert_eq!(a.stats.tree_nodes, b.stats.tree_nodes, "{what}: tree nodes");
    let trace = |o: &SearchOutcome| o.trace.iter().map(|t| (t.episode, t.iterations, t.value)).collect::<Vec<_>>();
    assert_eq!(trace(a), trace(b), "{what}: trace");
}

/// Runs `episodes` episodes of the search of `objectives` stepped, the hook swapping in
/// `swap.1` before episode `swap.0` (counting from 0); returns the outcome and the reports.
fn stepped(p: &Mdp, pareto: bool, seed: u64, episodes: usize, swap: Option<(u64, Arc<dyn Policy>)>) -> (SearchOutcome, Vec<EpisodeEnd>) {
    let mut reports = Vec::new();
    let mut hook = |end: EpisodeEnd| {
        let next = match &swap {
            Some((at, p)) if end.episodes == *at && !end.finished => Next::Policy(p.clone()),
            _ => Next::Continue,
        };
        reports.push(end);
        Ok(next)
    };
    let out = if pareto {
        ParetoMcts::builder().episodes(episodes).seed(seed).record_transitions(true).build().unwrap().solve_stepped(p, &mut hook)
    } else {
        Mcts::builder().episodes(episodes).seed(seed).record_transitions(true).build().unwrap().solve_stepped(p, &mut hook)
    }
    .unwrap();
    (out, reports)
}

#[test]
fn the_stepped_search_without_swaps_is_the_plain_search() {
    let cube = soma(4, 3);
    let maps = maps(&cube, 5);
    for (objectives, seed) in [("access", 1u64), ("access,dirchange", 3)] {
        let p = problem(&maps, objectives);
        let pareto = objectives.contains(',');
        let plain = if pareto {
            ParetoMcts::builder().episodes(25).seed(seed).record_transitions(true).build().unwrap().solve(&p).unwrap()
        } else {
            Mcts::builder().episodes(25).seed(seed).record_transitions(true).build().unwrap().solve(&p).unwrap()
        };
        let (out, reports) = stepped(&p, pareto, seed, 25, None);
        same(&plain, &out, objectives);
        // one report per episode, the last one final; their transitions are the recording's
        assert_eq!(reports.len(), 25, "{objectives}");
        assert!(reports.last().unwrap().finished && reports[..24].iter().all(|r| !r.finished));
        for (k, r) in reports.iter().enumerate() {
            assert_eq!(r.episodes, k as u64 + 1);
            assert!(r.transitions.iter().all(|t| t.episode == k as u64), "{objectives}: episode {k}");
        }
        let all: Vec<Transition> = reports.into_iter().flat_map(|r| r.transitions).collect();
        assert_eq!(all, plain.transitions, "{objectives}: transitions");
    }
}

#[test]
fn a_stepped_search_on_several_threads_is_refused() {
    let cube = soma(3, 1);
    let maps = maps(&cube, 3);
    let p = problem(&maps, "access");
    let err = Mcts::builder().threads(2).build().unwrap().solve_stepped(&p, &mut |_| Ok(Next::Continue)).unwrap_err();
    assert!(err.to_string().contains("one thread"), "{err}");
}

/// Whether a rollout step took the removal with the largest immediate access reward.
fn greedy(p: &Mdp, t: &Transition) -> bool {
    let mut rewards = Vec::new();
    for &a in &t.actions {
        let mut state = MapState::new(p.maps());
        state.reset(&t.present);
        let mut memory = t.memory.clone();
        let mut r = vec![0.0; p.num_objectives()];
        p.step(&mut state, &mut memory, a, StepKind::Simulation, &mut r);
        rewards.push(r[0]);
    }
    t.actions[argmax(&rewards)] == t.action
}

#[test]
fn a_swapped_policy_guides_the_episodes_after_the_swap() {
    let cube = soma(4, 5);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let guided: Arc<dyn Policy> = Arc::new(EpsilonGreedy::new(0.0, vec![Arc::new(ImmediateReward { objective: 0 })]).unwrap());
    let (out, reports) = stepped(&p, false, 2, 8, Some((3, guided.clone())));
    let simulations = |r: &EpisodeEnd| r.transitions.iter().filter(|t| t.kind == StepKind::Simulation).cloned().collect::<Vec<_>>();
    // before the swap rollouts are random (some step is not greedy), after it every step is
    let before: Vec<Transition> = reports[..3].iter().flat_map(simulations).collect();
    let after: Vec<Transition> = reports[3..].iter().flat_map(simulations).collect();
    assert!(!before.is_empty() && !after.is_empty());
    assert!(before.iter().any(|t| t.actions.len() > 1 && !greedy(&p, t)), "random rollouts before the swap");
    assert!(after.iter().all(|t| greedy(&p, t)), "greedy rollouts after the swap");
    // the same seed and sequence of policies: the same search
    let (again, _) = stepped(&p, false, 2, 8, Some((3, guided)));
    same(&out, &again, "again");
    let (unswapped, _) = stepped(&p, false, 2, 8, None);
    assert_ne!(unswapped.stats.rollout_steps + unswapped.stats.tree_nodes, 0);
    assert!(unswapped.transitions != out.transitions || unswapped.solutions != out.solutions);
}

#[test]
fn stepped_search_handle_gives_the_plan_of_asp_plan() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("soma.glb");
    asp_geom::io::write_glb(&soma(4, 8), &path).unwrap();
    let o = OptimiseSettings {
        objectives: vec!["access".into(), "dirchange".into()],
        pareto: true,
        episodes: 6,
        threads: Some(1),
        resolution: 5,
        ..OptimiseSettings::default()
    };
    let settings = PlanSettings { seed: 4, optimise: Some(o.clone()), ..PlanSettings::default() };
    let mut search = SteppedSearch::start(&path, &settings, true).unwrap();
    assert_eq!(search.index().objectives, vec!["access".to_string(), "dirchange".to_string()]);
    assert_eq!(search.index().assemblies[0].reward_ranges.len(), 2);
    let mut transitions = 0;
    for k in 0..6 {
        let end = search.episode().unwrap();
        assert_eq!(end.episodes, k + 1);
        assert!(!end.transitions.is_empty());
        transitions += end.transitions.len();
        assert_eq!(end.finished, k == 5, "the sixth episode is the last of 6");
    }
    assert!(search.ended() && search.episode().is_err());
    let stepped = search.finish().unwrap();
    let assembly = Arc::new(pipeline::load(&path, &settings).unwrap());
    let plain = pipeline::optimise(assembly, &settings, &o).unwrap();
    let (a, b) = (stepped.report.optimisation.as_ref().unwrap(), plain.report.optimisation.as_ref().unwrap());
    assert_eq!(
        (a.episodes, a.iterations, a.tree_nodes, &a.values, a.hypervolume),
        (b.episodes, b.iterations, b.tree_nodes, &b.values, b.hypervolume)
    );
    assert_eq!(stepped.report.pareto_front, plain.report.pareto_front);
    assert_eq!(stepped.report.disassembly_sequence, plain.report.disassembly_sequence);
    assert!(transitions > 0);
    // ended early on request: the episodes run so far
    let mut search = SteppedSearch::start(&path, &settings, false).unwrap();
    let end = search.episode().unwrap();
    assert!(end.transitions.is_empty() && !end.finished);
    let early = search.finish().unwrap();
    assert_eq!(early.report.optimisation.as_ref().unwrap().episodes, 1);
}
