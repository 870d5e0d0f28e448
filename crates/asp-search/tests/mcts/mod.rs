//! Single-objective MCTS: finds the exact optimum on small instances within its default budget,
//! returns feasible sequences, is reproducible with one thread and a seed, validates settings.

use crate::fixtures::{close, exact_instances, figure_6_2, maps, problem, soma};
use asp_search::exact::exact_front;
use asp_search::Status;
use asp_search::{Mcts, SearchError};

#[test]
fn finds_the_optimum_of_figure_6_2() {
    let maps = maps(&figure_6_2(), 3);
    let p = problem(&maps, "access");
    let out = Mcts::builder().seed(3).build().unwrap().solve(&p).unwrap();
    assert_eq!(*out.status(), Status::Found);
    let best = out.best().unwrap();
    assert_eq!(best.sequence, vec![2, 1, 0]);
    assert!(out.stats.exhausted, "two sequences: the tree is fully explored");
}

#[test]
fn finds_the_exact_optimum_on_instances_with_exact_references() {
    for (name, assembly) in exact_instances() {
        let maps = maps(&assembly, 5);
        for (k, objective) in ["access", "dirchange", "pathlen"].into_iter().enumerate() {
            let p = problem(&maps, objective);
            let exact = exact_front(&p, 2_000_000).unwrap();
            let out = Mcts::builder().seed(k as u64).build().unwrap().solve(&p).unwrap();
            if exact.solutions.is_empty() {
                assert_ne!(*out.status(), Status::Found, "{name}");
                continue;
            }
            let best = out.best().expect("a sequence exists");
            let optimum = exact.solutions[0].values[0];
            assert!(
                close(best.values[0], optimum),
                "{name} ({} parts) {objective}: {} vs optimum {optimum}",
                maps.num_parts(),
                best.values[0]
            );
            // re-checked: feasible, and the reported value is the sequence's value
            let (v, _) = p.evaluate(&best.sequence).unwrap();
            assert!(close(v[0], best.values[0]));
            assert_eq!(best.motions.len(), best.sequence.len());
        }
    }
}

#[test]
fn one_thread_and_a_seed_reproduce_the_search() {
    let cube = soma(4, 11);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let run = |seed| Mcts::builder().episodes(40).seed(seed).build().unwrap().solve(&p).unwrap();
    let (a, b) = (run(5), run(5));
    assert_eq!(a.solutions, b.solutions);
    assert_eq!(a.stats.iterations, b.stats.iterations);
    assert_eq!(a.stats.rollout_steps, b.stats.rollout_steps);
    let values = |o: &asp_search::SearchOutcome| o.trace.iter().map(|t| (t.episode, t.value)).collect::<Vec<_>>();
    assert_eq!(values(&a), values(&b));
    let c = run(6);
    assert!(a.stats.rollout_steps != c.stats.rollout_steps || a.solutions != c.solutions);
}

#[test]
fn settings_are_validated() {
    assert!(matches!(Mcts::builder().budget(0).build(), Err(SearchError::Config { .. })));
    assert!(Mcts::builder().episodes(0).build().is_err());
    assert!(Mcts::builder().threads(0).build().is_err());
    assert!(Mcts::builder().exploration(-1.0).build().is_err());
    assert!(Mcts::builder().max_nodes(0).build().is_err());
    assert!(Mcts::builder().time_limit(std::time::Duration::ZERO).build().is_err());
    // two objectives are a configuration error for single-objective MCTS
    let maps = maps(&figure_6_2(), 3);
    let p = problem(&maps, "access,dirchange");
    assert!(matches!(Mcts::builder().build().unwrap().solve(&p), Err(SearchError::Config { .. })));
    let p1 = problem(&maps, "access");
    let wrong_reference = Mcts::builder().reference(vec![0.0, 0.0]).build().unwrap();
    assert!(wrong_reference.solve(&p1).is_err());
}

#[test]
fn node_cap_still_finds_sequences() {
    let cube = soma(4, 3);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "dirchange");
    let out = Mcts::builder().episodes(5).max_nodes(10).seed(1).build().unwrap().solve(&p).unwrap();
    assert!(out.stats.tree_nodes <= 10);
    let best = out.best().unwrap();
    p.evaluate(&best.sequence).unwrap();
}

#[test]
fn the_thesis_tree_without_transpositions_also_finds_optima() {
    for (name, assembly) in exact_instances().into_iter().take(2) {
        let maps = maps(&assembly, 5);
        let p = problem(&maps, "access");
        let exact = exact_front(&p, 100_000).unwrap();
        let search = Mcts::builder().transpositions(false).seed(2).build().unwrap();
        assert!(!search.settings().transpositions());
        let out = search.solve(&p).unwrap();
        let best = out.best().unwrap();
        assert!(close(best.values[0], exact.solutions[0].values[0]), "{name}");
        p.evaluate(&best.sequence).unwrap();
        // a tree holds one node per removal order tried, a graph one per state
        let graph = Mcts::builder().seed(2).build().unwrap().solve(&p).unwrap();
        assert!(graph.stats.tree_nodes <= out.stats.tree_nodes, "{name}");
    }
}

#[test]
fn a_guided_rollout_policy_plugs_in() {
    use asp_search::policy::{EpsilonGreedy, ImmediateReward};
    use std::sync::Arc;
    assert!(EpsilonGreedy::new(1.5, vec![Arc::new(ImmediateReward { objective: 0 })]).is_err());
    assert!(EpsilonGreedy::new(0.2, vec![]).is_err());
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let exact = exact_front(&p, 1_000_000).unwrap();
    // ε = 0: always the part with the largest immediate accessibility
    let greedy = EpsilonGreedy::new(0.0, vec![Arc::new(ImmediateReward { objective: 0 })]).unwrap();
    let out = Mcts::builder().policy(Arc::new(greedy)).seed(1).build().unwrap().solve(&p).unwrap();
    let best = out.best().unwrap();
    p.evaluate(&best.sequence).unwrap();
    assert!(close(best.values[0], exact.solutions[0].values[0]));
    // the guided rollouts are deterministic given the seed
    let again = Mcts::builder()
        .policy(Arc::new(EpsilonGreedy::new(0.0, vec![Arc::new(ImmediateReward { objective: 0 })]).unwrap()))
        .seed(1)
        .build()
        .unwrap()
        .solve(&p)
        .unwrap();
    assert_eq!(out.stats.rollout_steps, again.stats.rollout_steps);
    assert_eq!(out.solutions, again.solutions);
}

/// A Q-function that prefers larger part indices and counts its evaluations.
#[derive(Debug, Default)]
struct LargestIndex(std::sync::atomic::AtomicUsize);

impl asp_search::QFunction for LargestIndex {
    fn q_values(&self, _: &mut asp_search::PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        for (o, &a) in out.iter_mut().zip(actions) {
            *o = 1.0 + a as f64;
        }
        Ok(())
    }
}

#[test]
fn q_guided_expansions_follow_the_priors_and_leave_rollouts_random() {
    use asp_search::policy::{EpsilonGreedy, QUse};
    use asp_search::StepKind;
    use std::sync::atomic::Ordering;
    use std::sync::Arc;
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let run_cached = |uses: QUse, cache_bytes: usize| {
        let q = Arc::new(LargestIndex::default());
        let policy = EpsilonGreedy::new(0.0, vec![q.clone()]).unwrap().using(uses).cache_bytes(cache_bytes);
        // one episode, one iteration per step: every expansion is its node's first
        let out = Mcts::builder()
            .policy(Arc::new(policy))
            .seed(3)
            .episodes(1)
            .budget(1)
            .record_transitions(true)
            .build()
            .unwrap()
            .solve(&p)
            .unwrap();
        (out, q.0.load(Ordering::Relaxed))
    };
    // without the cache of values by state, so every evaluation is counted
    let run = |uses: QUse| run_cached(uses, 0);
    let greedy = |t: &asp_search::Transition| t.action == *t.actions.iter().max().unwrap();
    let (out, calls) = run(QUse::Expansions);
    let expansions: Vec<_> = out.transitions.iter().filter(|t| t.kind == StepKind::Expansion).collect();
    let rollouts: Vec<_> = out.transitions.iter().filter(|t| t.kind == StepKind::Simulation).collect();
    assert!(!expansions.is_empty() && !rollouts.is_empty());
    assert!(expansions.iter().all(|t| greedy(t)), "every expansion adds the removal with the largest prior");
    assert!(!rollouts.iter().filter(|t| t.actions.len() > 1).all(|t| greedy(t)), "rollouts stay random");
    // one evaluation per node added (the root's included), none per rollout step
    assert!(calls <= expansions.len() + 1, "{calls} evaluations for {} expansions", expansions.len());
    assert!(rollouts.len() > calls, "{} rollout steps, {calls} evaluations", rollouts.len());
    // rollouts: the other way round
    let (out, calls) = run(QUse::Rollouts);
    let rollouts: Vec<_> = out.transitions.iter().filter(|t| t.kind == StepKind::Simulation).collect();
    assert!(rollouts.iter().filter(|t| t.actions.len() > 1).all(|t| greedy(t)));
    assert!(calls >= rollouts.iter().filter(|t| t.actions.len() > 1).count());
    // the cache of values by state: the same search with fewer evaluations (the greedy rollouts
    // of consecutive steps pass through the same states)
    let (cached, cached_calls) = run_cached(QUse::Rollouts, 1 << 20);
    assert_eq!(cached.solutions, out.solutions);
    assert_eq!(cached.transitions, out.transitions);
    assert!(cached_calls < calls, "{cached_calls} evaluations with the cache, {calls} without");
    // both: greedy everywhere
    let (out, _) = run(QUse::Both);
    assert!(out.transitions.iter().filter(|t| t.actions.len() > 1).all(greedy));
    assert!("expansions".parse::<QUse>().unwrap() == QUse::Expansions && "sideways".parse::<QUse>().is_err());
}

#[test]
fn q_priors_seed_the_search_with_the_greedy_sequence() {
    use asp_geom::distmap::MapState;
    use asp_search::policy::{EpsilonGreedy, QUse};
    use std::sync::Arc;
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let run = |uses: QUse| {
        let policy = EpsilonGreedy::new(0.0, vec![Arc::new(LargestIndex::default())]).unwrap().using(uses);
        Mcts::builder().policy(Arc::new(policy)).seed(3).episodes(2).budget(2).build().unwrap().solve(&p).unwrap()
    };
    // the sequence that removes the largest feasible part index at each step
    let mut state = MapState::new(p.maps());
    let mut actions = Vec::new();
    let mut greedy = Vec::new();
    loop {
        state.feasible_actions(&mut actions);
        let Some(&a) = actions.iter().max() else { break };
        state.remove(a);
        greedy.push(a);
    }
    assert!(state.is_complete() && greedy.len() >= 5, "{greedy:?}");
    let (values, _) = p.evaluate(&greedy).unwrap();
    // with priors the search offers that sequence before its first iteration
    let out = run(QUse::Priors);
    assert_eq!(out.trace[0].iterations, 0, "{:?}", out.trace[0]);
    assert!(close(out.trace[0].value, values[0]), "{:?} vs {values:?}", out.trace[0]);
    // without, its first sequence comes from an iteration
    let out = run(QUse::Expansions);
    assert!(out.trace[0].iterations > 0, "{:?}", out.trace[0]);
}

/// A Q-function that values every removal alike and counts its evaluations.
#[derive(Debug, Default)]
struct Flat(std::sync::atomic::AtomicUsize);

impl asp_search::QFunction for Flat {
    fn q_values(&self, _: &mut asp_search::PolicyContext<'_, '_>, _: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        out.fill(1.0);
        Ok(())
    }
}

/// `seed`: before the first iteration one greedy sequence per ranking (the product of the
/// Q-values, then each objective's own) goes to the front; after them the Q-functions are
/// never asked again and expansions and rollouts are random.
#[test]
fn q_seed_offers_each_ranking_s_greedy_sequence_then_searches_at_random() {
    use asp_geom::distmap::MapState;
    use asp_search::hypervolume::dominates;
    use asp_search::policy::{EpsilonGreedy, QUse};
    use asp_search::{ParetoMcts, StepKind};
    use std::sync::atomic::Ordering;
    use std::sync::Arc;
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    // the greedy sequences: largest feasible index first (the product's ranking and the first
    // objective's), and the first feasible removal (the flat second objective's: ties go first)
    let greedy = |pick: fn(&[usize]) -> usize| {
        let mut state = MapState::new(p.maps());
        let (mut actions, mut seq) = (Vec::new(), Vec::new());
        loop {
            state.feasible_actions(&mut actions);
            if actions.is_empty() {
                break;
            }
            let a = pick(&actions);
            state.remove(a);
            seq.push(a);
        }
        assert!(state.is_complete() && seq.len() >= 5, "{seq:?}");
        seq
    };
    let largest_first = greedy(|a| *a.iter().max().unwrap());
    let first = greedy(|a| a[0]);
    assert_ne!(largest_first, first);
    let (largest, flat) = (Arc::new(LargestIndex::default()), Arc::new(Flat::default()));
    let policy = EpsilonGreedy::new(0.0, vec![largest.clone(), flat.clone()]).unwrap().using(QUse::Seed);
    let run = |policy: Option<Arc<EpsilonGreedy>>, polish: f64, episodes: usize, budget: usize| {
        let mut b = ParetoMcts::builder().seed(3).episodes(episodes).budget(budget).polish(polish).record_transitions(true);
        if let Some(policy) = policy {
            b = b.policy(policy);
        }
        b.build().unwrap().solve(&p).unwrap()
    };
    let policy = Arc::new(policy);
    let out = run(Some(policy.clone()), 0.25, 3, 2);
    assert_eq!(out.trace[0].iterations, 0, "{:?}", out.trace[0]);
    // each seed is on the front or dominated by what is
    for seq in [&largest_first, &first] {
        let (values, _) = p.evaluate(seq).unwrap();
        assert!(
            out.solutions.iter().any(|s| s.values == values || dominates(&s.values, &values)),
            "{seq:?} ({values:?}) is neither on nor below the front"
        );
    }
    // one evaluation per step of the seeds that use each function, none after
    assert_eq!(largest.0.load(Ordering::Relaxed), 2 * largest_first.len());
    assert_eq!(flat.0.load(Ordering::Relaxed), largest_first.len() + first.len());
    let chosen: Vec<_> = out.transitions.iter().filter(|t| t.actions.len() > 1 && t.kind == StepKind::Simulation).collect();
    assert!(!chosen.is_empty() && !chosen.iter().all(|t| t.action == *t.actions.iter().max().unwrap()), "rollouts stay random");
    // the seeds leave the tree search as it was: the same steps as vanilla's of the same seed,
    // so (without the local search) a front that holds vanilla's and the seeds' sequences
    let (seeded, vanilla) = (run(Some(policy), 0.0, 40, 5), run(None, 0.0, 40, 5));
    let steps = |o: &asp_search::SearchOutcome| o.transitions.iter().map(|t| (t.episode, t.kind, t.action)).collect::<Vec<_>>();
    assert!(steps(&seeded) == steps(&vanilla), "the seeded tree search took other steps than vanilla's");
    assert_eq!((seeded.stats.iterations, seeded.stats.tree_nodes), (vanilla.stats.iterations, vanilla.stats.tree_nodes));
    for v in &vanilla.solutions {
        assert!(seeded.solutions.iter().any(|s| s.values == v.values || dominates(&s.values, &v.values)), "{:?} lost", v.values);
    }
}

/// A random rollout policy whose first choice on each thread waits (up to 20 s) until every
/// thread has made its first choice: it sees whether the search threads run at the same time
/// (`alone`: some thread waited in vain).
#[derive(Debug)]
struct MeetingPolicy {
    threads: usize,
    arrived: std::sync::Mutex<usize>,
    all: std::sync::Condvar,
    alone: std::sync::atomic::AtomicBool,
}

struct MeetingWorker<'a> {
    policy: &'a MeetingPolicy,
    waited: bool,
}

impl asp_search::Policy for MeetingPolicy {
    fn for_worker(&self, _thread: usize) -> asp_search::Result<Box<dyn asp_search::PolicyWorker + '_>> {
        Ok(Box::new(MeetingWorker { policy: self, waited: false }))
    }
}

impl asp_search::PolicyWorker for MeetingWorker<'_> {
    fn choose(
        &mut self,
        _: &mut asp_search::PolicyContext<'_, '_>,
        actions: &[usize],
        rng: &mut asp_search::policy::SearchRng,
    ) -> asp_search::Result<usize> {
        if !std::mem::replace(&mut self.waited, true) {
            let p = self.policy;
            let mut arrived = p.arrived.lock().unwrap();
            *arrived += 1;
            p.all.notify_all();
            let (arrived, _) = p.all.wait_timeout_while(arrived, std::time::Duration::from_secs(20), |n| *n < p.threads).unwrap();
            if *arrived < p.threads {
                p.alone.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        }
        use rand::RngExt;
        Ok(rng.random_range(0..actions.len()))
    }
}

/// Root-parallel threads search at the same time (a lock held for a whole thread's run once
/// made two threads take as long as one, with the same answers).
#[test]
fn search_threads_run_at_the_same_time() {
    use std::sync::Arc;
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    for pareto in [false, true] {
        let p = problem(&maps, if pareto { "access,dirchange" } else { "access" });
        let policy =
            Arc::new(MeetingPolicy { threads: 2, arrived: Default::default(), all: Default::default(), alone: Default::default() });
        let out = if pareto {
            asp_search::ParetoMcts::builder().threads(2).episodes(8).seed(1).policy(policy.clone()).build().unwrap().solve(&p)
        } else {
            Mcts::builder().threads(2).episodes(8).seed(1).policy(policy.clone()).build().unwrap().solve(&p)
        };
        assert!(out.is_ok());
        assert_eq!(*policy.arrived.lock().unwrap(), 2, "pareto {pareto}: both threads made rollouts");
        assert!(
            !policy.alone.load(std::sync::atomic::Ordering::SeqCst),
            "pareto {pareto}: one thread ran its rollouts while the other waited"
        );
    }
}
