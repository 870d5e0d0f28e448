//! The optimiser's plug-in points: objectives with their own memory and step context, feasibility
//! filters, per-thread policies with expansion and prior hooks, plug-in errors, and the stop
//! token.

use crate::fixtures::{close, exact_instances, maps, problem, soma};
use asp_geom::distmap::DistanceMaps;
use asp_search::exact::exact_front;
use asp_search::objective::parse_objectives;
use asp_search::policy::{PolicyContext, PolicyWorker, SearchRng};
use asp_search::StopToken;
use asp_search::{ActionFilter, Mcts, Mdp, Objective, ParetoMcts, Policy, SearchError, StepContext, StepKind, Verdict};
use rand::RngExt;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Rewards a removal with 1 when the part's index has the parity of the part removed before it
/// (a history-dependent objective): memory word 0 is the last part + 1 (0 before the first
/// removal). With `key` false the word is not part of the state's key.
#[derive(Debug)]
struct SameParity {
    key: bool,
}

impl Objective for SameParity {
    fn name(&self) -> &str {
        "parity"
    }
    fn memory_words(&self) -> usize {
        1
    }
    fn key_words(&self) -> usize {
        usize::from(self.key)
    }
    fn reward(&self, step: &mut StepContext<'_, '_>, memory: &mut [u64]) -> f64 {
        let part = step.part() as u64;
        let r = if memory[0] != 0 && (memory[0] - 1) % 2 == part % 2 { 1.0 } else { 0.0 };
        memory[0] = part + 1;
        r
    }
    fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
        0.0
    }
}

#[test]
fn an_objective_with_its_own_memory_is_optimised_exactly() {
    // The parity objective depends on the history only through its memory word; with the word
    // in the key, the graph search and the exact programme see the same states and agree.
    let mut checked = 0;
    for (name, assembly) in exact_instances().into_iter().skip(1).take(4) {
        let maps = maps(&assembly, 5);
        let p = Mdp::new(maps.clone(), vec![Arc::new(SameParity { key: true })]).unwrap();
        let exact = exact_front(&p, 1_000_000).unwrap();
        let out = Mcts::builder().seed(4).build().unwrap().solve(&p).unwrap();
        let best = out.best().expect("a sequence");
        assert!(close(best.values[0], exact.solutions[0].values[0]), "{name}: {:?} vs {:?}", best.values, exact.solutions[0].values);
        // the value is the sequence's: count parity repeats by hand
        let by_hand = best.sequence.windows(2).filter(|w| w[0] % 2 == w[1] % 2).count() as f64;
        assert_eq!(best.values[0], by_hand, "{name}");
        // more states than the memoryless problem: the memory tells states apart
        let plain = exact_front(&problem(&maps, "access"), 1_000_000).unwrap();
        assert!(exact.states > plain.states, "{name}: {} vs {}", exact.states, plain.states);
        checked += 1;
    }
    assert_eq!(checked, 4);
}

#[test]
fn memory_outside_the_key_merges_states() {
    // The same objective with its word outside the key: states that differ only in the last
    // part are one state (a node keeps the memory of the path that reached it first), so the
    // exact programme and the explored graph have as many states as a memoryless problem's;
    // answers still replay to their reported values.
    let cube = soma(3, 4);
    let maps = maps(&cube, 5);
    let keyed = Mdp::new(maps.clone(), vec![Arc::new(SameParity { key: true })]).unwrap();
    let unkeyed = Mdp::new(maps.clone(), vec![Arc::new(SameParity { key: false })]).unwrap();
    let plain = problem(&maps, "access");
    let states = |p: &Mdp| exact_front(p, 1_000_000).unwrap().states;
    assert!(states(&keyed) > states(&plain));
    assert_eq!(states(&unkeyed), states(&plain));
    let run = |p: &Mdp| Mcts::builder().episodes(5000).seed(1).build().unwrap().solve(p).unwrap();
    let (k, u, a) = (run(&keyed), run(&unkeyed), run(&plain));
    assert!(k.stats.exhausted && u.stats.exhausted && a.stats.exhausted);
    assert!(k.stats.tree_nodes > u.stats.tree_nodes, "{} vs {}", k.stats.tree_nodes, u.stats.tree_nodes);
    assert_eq!(u.stats.tree_nodes, a.stats.tree_nodes);
    for s in &u.solutions {
        let (v, _) = unkeyed.evaluate(&s.sequence).unwrap();
        assert_eq!(v, s.values);
    }
}

/// Counts its calls by step kind and checks the step context on each.
#[derive(Debug, Default)]
struct KindCounter {
    expansion: AtomicU64,
    simulation: AtomicU64,
    replay: AtomicU64,
}

impl Objective for KindCounter {
    fn name(&self) -> &str {
        "kinds"
    }
    fn reward(&self, step: &mut StepContext<'_, '_>, _memory: &mut [u64]) -> f64 {
        let counter = match step.kind() {
            StepKind::Expansion => &self.expansion,
            StepKind::Simulation => &self.simulation,
            StepKind::Replay => &self.replay,
        };
        counter.fetch_add(1, Ordering::Relaxed);
        let part = step.part();
        assert!(step.present().contains(part), "the state is the one before the removal");
        // the motion is the maps' straight-line removal of the part
        let (d, travel) = step.clearance().expect("a feasible part has a free direction");
        assert!(step.state().free_mask(part).contains(d));
        assert!(travel >= 0.0);
        // the assembly is there (the pipeline and this test give it) and the seed is the step's
        assert_eq!(step.assembly().expect("with_assembly").parts.len(), step.maps().num_parts());
        assert_eq!(step.seed(), step.seed());
        -(travel as f64)
    }
    fn worst_total(&self, maps: &DistanceMaps, removals: usize) -> f64 {
        -(removals as f64) * 3f64.sqrt() * maps.diagonal() as f64
    }
}

#[test]
fn objectives_learn_which_step_of_the_search_calls_them() {
    let cube = soma(4, 2);
    let maps = maps(&cube, 5);
    let counter = Arc::new(KindCounter::default());
    let p = Mdp::new(maps, vec![counter.clone()]).unwrap().with_assembly(Arc::new(cube)).with_seed(3);
    // without the local search, whose moves are replay steps too (below)
    let out = Mcts::builder().episodes(30).seed(2).polish(0.0).build().unwrap().solve(&p).unwrap();
    // one expansion step per new edge (no edge without an expansion) and per iteration at most
    let expansions = counter.expansion.load(Ordering::Relaxed);
    assert!(expansions > 0 && expansions <= out.stats.iterations, "{expansions} vs {}", out.stats.iterations);
    assert_eq!(counter.simulation.load(Ordering::Relaxed), out.stats.rollout_steps);
    let replayed: usize = out.solutions.iter().map(|s| s.sequence.len()).sum();
    assert_eq!(counter.replay.load(Ordering::Relaxed), replayed as u64);
    // the pathlen-like values agree with the built-in pathlen objective on the same sequence
    let pathlen = problem(p.maps_arc(), "pathlen");
    let best = out.best().unwrap();
    assert!(close(pathlen.evaluate(&best.sequence).unwrap().0[0], best.values[0]));
    // the local search evaluates its moves by replay steps, never as expansions or simulations
    let before =
        (counter.expansion.load(Ordering::Relaxed), counter.simulation.load(Ordering::Relaxed), counter.replay.load(Ordering::Relaxed));
    let polished = Mcts::builder().episodes(30).seed(2).build().unwrap().solve(&p).unwrap();
    assert!(polished.stats.polish_steps > 0);
    assert_eq!(counter.expansion.load(Ordering::Relaxed) - before.0, expansions);
    assert_eq!(counter.simulation.load(Ordering::Relaxed) - before.1, polished.stats.rollout_steps);
    let replayed: usize = polished.solutions.iter().map(|s| s.sequence.len()).sum();
    assert!(counter.replay.load(Ordering::Relaxed) - before.2 > replayed as u64);
    assert!(polished.best().unwrap().values[0] >= best.values[0]);
}

#[test]
fn step_seeds_depend_on_the_problem_seed_the_state_and_the_part_only() {
    let cube = soma(3, 1);
    let maps = maps(&cube, 5);
    let seeds = |seed: u64, present: &asp_geom::PartSet, part: usize| {
        let p = problem(&maps, "access").with_seed(seed);
        let mut state = asp_geom::distmap::MapState::new(&maps);
        state.reset(present);
        let a = StepContext::new(&p, &mut state, part, StepKind::Expansion).seed();
        let b = StepContext::new(&p, &mut state, part, StepKind::Simulation).seed();
        assert_eq!(a, b);
        a
    };
    let full = asp_geom::PartSet::full(maps.num_parts());
    assert_eq!(seeds(1, &full, 2), seeds(1, &full, 2));
    assert_ne!(seeds(1, &full, 2), seeds(2, &full, 2));
    assert_ne!(seeds(1, &full, 2), seeds(1, &full, 3));
    assert_ne!(seeds(1, &full, 2), seeds(1, &full.without(5), 2));
}

/// Part `later` may not leave while part `first` is present (a precedence the maps do not
/// know, as a robot that cannot reach a part under another would add).
#[derive(Debug)]
struct After {
    first: usize,
    later: usize,
}

impl ActionFilter for After {
    fn name(&self) -> &str {
        "after"
    }
    fn reasons(&self) -> Vec<String> {
        vec!["unused".into(), "its predecessor is present".into()]
    }
    fn check(&self, step: &mut StepContext<'_, '_>, _memory: &[u64]) -> Verdict {
        if step.part() == self.later && step.state().contains(self.first) {
            Verdict::Infeasible { reason: 1 }
        } else {
            Verdict::Feasible
        }
    }
}

#[test]
fn a_feasibility_filter_removes_actions_everywhere() {
    let cube = soma(3, 0);
    let maps = maps(&cube, 5);
    let plain = problem(&maps, "access,dirchange");
    // a precedence the vanilla front violates and some sequence keeps: the exact front's
    // first sequence removes `later` first, another feasible sequence removes `first` first
    let front = exact_front(&plain, 1_000_000).unwrap();
    let seq = &front.solutions[0].sequence;
    let later = seq[0];
    let all = asp_search::exact::enumerate_sequences(&plain, 5_000_000).unwrap();
    let first = all.iter().map(|s| s.sequence[0]).find(|&p| p != later).expect("another first removal");
    let p = plain.clone().with_filter(Arc::new(After { first, later }));
    let exact = exact_front(&p, 1_000_000).unwrap();
    assert!(!exact.solutions.is_empty());
    let before = |s: &[usize]| s.iter().position(|&x| x == first) < s.iter().position(|&x| x == later);
    assert!(exact.solutions.iter().all(|s| before(&s.sequence)));
    assert!(p.evaluate(seq).is_err(), "the filter rejects the vanilla answer on replay");
    for threads in [1, 2] {
        let out = ParetoMcts::builder().threads(threads).seed(5).build().unwrap().solve(&p).unwrap();
        assert!(!out.solutions.is_empty());
        for s in &out.solutions {
            assert!(before(&s.sequence), "{:?}", s.sequence);
            p.evaluate(&s.sequence).unwrap();
        }
        // rejections are counted under the filter's reason
        assert_eq!(out.stats.filtered.len(), 1, "{:?}", out.stats.filtered);
        assert_eq!(out.stats.filtered[0].filter, "after");
        assert_eq!(out.stats.filtered[0].reason, "its predecessor is present");
        assert!(out.stats.filtered[0].count > 0);
        // small instance: the graph is explored and the front is exact
        assert!(out.stats.exhausted);
        let hv = |v: &[Vec<f64>]| {
            let mut f = asp_search::hypervolume::ParetoFront::new(2);
            for p in v {
                f.insert(p, || ());
            }
            f.hypervolume(&[-1.0, -1.0])
        };
        let got: Vec<Vec<f64>> = out.solutions.iter().map(|s| s.values.clone()).collect();
        let want: Vec<Vec<f64>> = exact.solutions.iter().map(|s| s.values.clone()).collect();
        assert!(close(hv(&got), hv(&want)));
    }
    // without the filter, nothing is counted
    let out = ParetoMcts::builder().episodes(50).seed(5).build().unwrap().solve(&plain).unwrap();
    assert!(out.stats.filtered.is_empty());
}

/// A random rollout policy that records which threads asked for workers, the expansions'
/// untried sets with their priors, and can misbehave on request.
#[derive(Debug, Default)]
struct Probe {
    threads: Mutex<Vec<usize>>,
    /// priors: the part index (so the largest index is expanded first)
    priors: bool,
    expansions: AtomicUsize,
    bad_index_after: Option<usize>,
    panic_after: Option<usize>,
    choices: AtomicUsize,
}

struct ProbeWorker<'a>(&'a Probe);

impl Policy for Probe {
    fn for_worker(&self, thread: usize) -> asp_search::Result<Box<dyn PolicyWorker + '_>> {
        self.threads.lock().unwrap().push(thread);
        Ok(Box::new(ProbeWorker(self)))
    }
}

impl PolicyWorker for ProbeWorker<'_> {
    fn choose(&mut self, _ctx: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> asp_search::Result<usize> {
        let n = self.0.choices.fetch_add(1, Ordering::Relaxed);
        if self.0.bad_index_after.is_some_and(|k| n >= k) {
            return Ok(actions.len());
        }
        if self.0.panic_after.is_some_and(|k| n >= k) {
            panic!("probe policy panics");
        }
        Ok(rng.random_range(0..actions.len()))
    }

    fn expand(
        &mut self,
        ctx: &mut PolicyContext<'_, '_>,
        untried: &[usize],
        priors: Option<&[f64]>,
        rng: &mut SearchRng,
    ) -> asp_search::Result<usize> {
        self.0.expansions.fetch_add(1, Ordering::Relaxed);
        assert!(untried.windows(2).all(|w| w[0] < w[1]), "increasing part order");
        assert!(untried.iter().all(|&a| ctx.state.contains(a)));
        match priors {
            Some(p) => {
                assert!(self.0.priors);
                // the engine hands back the priors this worker gave, aligned with `untried`
                assert_eq!(p, untried.iter().map(|&a| a as f64).collect::<Vec<_>>());
                // the default choice is the largest prior
                let k = asp_search::policy::argmax(p);
                assert_eq!(untried[k], *untried.iter().max().unwrap());
                Ok(k)
            }
            None => {
                assert!(!self.0.priors);
                Ok(rng.random_range(0..untried.len()))
            }
        }
    }

    fn has_priors(&self) -> bool {
        self.0.priors
    }

    fn priors(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        let mut feasible = Vec::new();
        ctx.state.feasible_actions(&mut feasible);
        assert_eq!(actions, &feasible[..], "priors are asked for the new state's feasible actions");
        for (o, &a) in out.iter_mut().zip(actions) {
            *o = a as f64;
        }
        Ok(())
    }
}

#[test]
fn every_thread_gets_its_own_policy_worker() {
    let cube = soma(4, 1);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let probe = Arc::new(Probe::default());
    let out = Mcts::builder().policy(probe.clone()).threads(3).episodes(9).seed(1).build().unwrap().solve(&p).unwrap();
    let mut threads = probe.threads.lock().unwrap().clone();
    threads.sort();
    assert_eq!(threads, vec![0, 1, 2]);
    assert!(probe.expansions.load(Ordering::Relaxed) > 0);
    // the probe's random choices are the default policy's: the same answer as vanilla
    let vanilla = Mcts::builder().threads(3).episodes(9).seed(1).build().unwrap().solve(&p).unwrap();
    assert_eq!(out.solutions, vanilla.solutions);
    assert_eq!(out.stats.rollout_steps, vanilla.stats.rollout_steps);
}

#[test]
fn priors_order_expansions_and_weigh_in_the_tree_policy() {
    let cube = soma(4, 1);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    let run = |weight: f64| {
        let probe = Arc::new(Probe { priors: true, ..Probe::default() });
        let out = ParetoMcts::builder().policy(probe.clone()).prior_weight(weight).episodes(20).seed(1).build().unwrap().solve(&p).unwrap();
        assert!(probe.expansions.load(Ordering::Relaxed) > 0);
        for s in &out.solutions {
            p.evaluate(&s.sequence).unwrap();
        }
        out
    };
    let (a, b) = (run(0.0), run(5.0));
    // the PUCT bonus changes which children selection visits
    assert!(a.stats.rollout_steps != b.stats.rollout_steps || a.solutions != b.solutions);
    assert!(ParetoMcts::builder().prior_weight(-1.0).build().is_err());
    assert!(ParetoMcts::builder().prior_weight(f64::NAN).build().is_err());
}

#[test]
fn a_policy_that_breaks_its_contract_is_an_error_not_a_panic() {
    let cube = soma(3, 3);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    for threads in [1, 2] {
        let bad = Arc::new(Probe { bad_index_after: Some(10), ..Probe::default() });
        let err = Mcts::builder().policy(bad).threads(threads).seed(1).build().unwrap().solve(&p).unwrap_err();
        match &err {
            SearchError::Plugin { what, reason } => {
                assert_eq!(what, "rollout policy");
                assert!(reason.contains("chose action"), "{reason}");
            }
            other => panic!("{other:?}"),
        }
        let panicking = Arc::new(Probe { panic_after: Some(10), ..Probe::default() });
        let err = Mcts::builder().policy(panicking).threads(threads).seed(1).build().unwrap().solve(&p).unwrap_err();
        assert!(err.to_string().contains("probe policy panics"), "{err}");
    }
}

#[test]
fn a_stop_token_ends_a_search_early_with_its_answer_so_far() {
    let cube = soma(5, 1);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    let token = StopToken::new();
    let stopper = {
        let token = token.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(300));
            token.stop();
        })
    };
    let start = Instant::now();
    let search = ParetoMcts::builder().episodes(100_000_000).threads(2).seed(1).stop_token(token.clone()).build().unwrap();
    let out = search.solve(&p).unwrap();
    stopper.join().unwrap();
    assert!(start.elapsed() < Duration::from_secs(20), "{:?}", start.elapsed());
    assert!(out.stats.stopped);
    assert!(out.stats.episodes < 100_000_000);
    assert!(!out.solutions.is_empty());
    // a stopped token stops the next search at once
    let again = ParetoMcts::builder().episodes(1000).stop_token(token).build().unwrap().solve(&p).unwrap();
    assert_eq!(again.stats.episodes, 0);
    assert!(again.stats.stopped);
    // a search that runs out of episodes was not stopped
    let plain = ParetoMcts::builder().episodes(5).build().unwrap().solve(&p).unwrap();
    assert!(!plain.stats.stopped);
}

#[test]
fn objectives_from_an_extension_resolve_by_name() {
    use asp_search::extension::{check_objective_names, resolve_objectives};
    use asp_search::extension::{MdpExtension, ModelContext};
    #[derive(Debug)]
    struct Parity;
    impl MdpExtension for Parity {
        fn objective_names(&self) -> Vec<String> {
            vec!["parity".into()]
        }
        fn objective(&self, name: &str, _model: &ModelContext<'_>) -> asp_search::Result<Option<Arc<dyn Objective>>> {
            Ok((name == "parity").then(|| Arc::new(SameParity { key: true }) as Arc<dyn Objective>))
        }
    }
    let ext: Vec<Arc<dyn MdpExtension>> = vec![Arc::new(Parity)];
    check_objective_names(&["access", "parity"], &ext).unwrap();
    let err = check_objective_names(&["access", "speed"], &ext).unwrap_err();
    assert!(err.to_string().contains("parity"), "the message lists the extension's names: {err}");
    assert!(check_objective_names(&["parity"], &[]).is_err());
    let cube = Arc::new(soma(3, 1));
    let maps = maps(&cube, 5);
    let model = ModelContext { assembly: &cube, maps: &maps, seed: 0 };
    let objectives = resolve_objectives(&["parity", " access"], &ext, &model).unwrap();
    assert_eq!(objectives.iter().map(|o| o.name()).collect::<Vec<_>>(), vec!["parity", "access"]);
    assert!(resolve_objectives(&["parity", "parity"], &ext, &model).is_err());
    assert_eq!(parse_objectives("access").unwrap().len(), 1);
}

#[test]
fn every_reward_lies_in_its_objectives_range() {
    use asp_geom::distmap::MapState;
    use rand::SeedableRng;
    let cube = soma(4, 7);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange,pathlen");
    let ranges: Vec<(f64, f64)> = p.objectives().iter().map(|o| o.reward_range(&maps).expect("built-in")).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let (mut lowest, mut highest) = (vec![f64::INFINITY; 3], vec![f64::NEG_INFINITY; 3]);
    for _ in 0..100 {
        let mut state = MapState::new(&maps);
        let mut memory = p.initial_memory();
        let mut counts = p.filter_counts();
        let mut actions = Vec::new();
        let mut rewards = [0.0; 3];
        loop {
            p.feasible_actions(&mut state, &memory, StepKind::Simulation, &mut actions, &mut counts);
            if actions.is_empty() {
                break;
            }
            let a = actions[rng.random_range(0..actions.len())];
            p.step(&mut state, &mut memory, a, StepKind::Simulation, &mut rewards);
            for k in 0..3 {
                assert!(ranges[k].0 <= rewards[k] && rewards[k] <= ranges[k].1, "{k}: {} not in {:?}", rewards[k], ranges[k]);
                lowest[k] = lowest[k].min(rewards[k]);
                highest[k] = highest[k].max(rewards[k]);
            }
        }
    }
    // the ranges are bounds, not wild guesses: the rewards use a good part of them
    for k in 0..3 {
        assert!(highest[k] - lowest[k] > 0.05 * (ranges[k].1 - ranges[k].0), "{k}: {lowest:?} {highest:?} {ranges:?}");
    }
}

#[test]
fn a_dead_end_a_filter_makes_names_the_filter_not_the_geometry() {
    // figure 6.2 comes apart as 2, 1, 0 or 1, 2, 0; filters that keep the top (1) while the
    // ball (2) is present and the ball while the top is present leave no sequence: the dead end
    // is the assembled state, where the maps let both out and the filters do not, and the base
    // would leave them floating
    let maps = maps(&crate::fixtures::figure_6_2(), 3);
    let p =
        problem(&maps, "access").with_filter(Arc::new(After { first: 1, later: 2 })).with_filter(Arc::new(After { first: 2, later: 1 }));
    let out = Mcts::builder().seed(1).build().unwrap().solve(&p).unwrap();
    let end = asp_search::dead_end::deepest_dead_end(&p, 1_000).expect("a dead end");
    // the search's own outcome is explained by the same dead end, at the source
    match out.status() {
        asp_search::Status::NoPlan { stuck, state } => assert_eq!((stuck, state), (&end.stuck, &end.state)),
        s => panic!("{s:?}"),
    }
    assert_eq!(out.rejected, end.rejected);
    assert!(end.complete && end.removals.is_empty());
    let why = "is rejected by after: its predecessor is present".to_string();
    assert_eq!(end.rejected, vec![(1, why.clone()), (2, why)]);
    assert_eq!(end.stuck.len(), 1, "{:?}", end.stuck);
    assert_eq!(end.stuck[0].part, 0);
    assert_eq!(end.stuck[0].reason, asp_search::StuckReason::WouldLeaveUnsupported(asp_geom::PartSet::from_indices(3, [1, 2])));
    // without the filters there is a sequence: nothing to explain
    assert!(asp_search::dead_end::deepest_dead_end(&problem(&maps, "access"), 1_000).is_none());
}
