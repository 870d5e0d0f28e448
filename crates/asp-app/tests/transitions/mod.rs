//! Transitions recorded by the MCTS (`SearchBuilder::record_transitions`) and the
//! `asp-transitions` data set (`asp_app::collect_q`, docs/learning.md): recording changes no
//! answer, every transition replays through `Mdp::step`, the cap holds, the files are what the
//! format says and rebuild the same maps.

use crate::fixtures::{maps, problem, soma};
use asp_app::collect_q::{collect_transitions, TransitionSettings};
use asp_app::pipeline::{OptimiseSettings, PlanSettings};
use asp_geom::distmap::MapState;
use asp_geom::PartSet;
use asp_search::objective::DirHistory;
use asp_search::{Mcts, Mdp, ParetoMcts, SearchOutcome, StepKind, Transition};
use std::path::{Path, PathBuf};

fn same_answers(a: &SearchOutcome, b: &SearchOutcome, what: &str) {
    assert_eq!(a.solutions, b.solutions, "{what}: solutions");
    assert_eq!(a.value, b.value, "{what}: value");
    assert_eq!(a.stats.episodes, b.stats.episodes, "{what}: episodes");
    assert_eq!(a.stats.iterations, b.stats.iterations, "{what}: iterations");
    assert_eq!(a.stats.rollout_steps, b.stats.rollout_steps, "{what}: rollout steps");
    assert_eq!(a.stats.dead_rollouts, b.stats.dead_rollouts, "{what}: dead rollouts");
    assert_eq!(a.stats.tree_nodes, b.stats.tree_nodes, "{what}: tree nodes");
    let trace = |o: &SearchOutcome| o.trace.iter().map(|t| (t.episode, t.iterations, t.value)).collect::<Vec<_>>();
    assert_eq!(trace(a), trace(b), "{what}: trace");
}

#[test]
fn recording_changes_no_answer() {
    let cube = soma(4, 3);
    let maps = maps(&cube, 5);
    for (objectives, seed) in [("access", 1u64), ("dirchange", 2), ("access,dirchange", 3), ("access,pathlen", 4)] {
        let p = problem(&maps, objectives);
        let pareto = objectives.contains(',');
        let run = |record: Option<bool>, limit: usize| {
            if pareto {
                let mut b = ParetoMcts::builder().episodes(30).seed(seed);
                if let Some(r) = record {
                    b = b.record_transitions(r).record_transitions_limit(limit);
                }
                b.build().unwrap().solve(&p).unwrap()
            } else {
                let mut b = Mcts::builder().episodes(30).seed(seed);
                if let Some(r) = record {
                    b = b.record_transitions(r).record_transitions_limit(limit);
                }
                b.build().unwrap().solve(&p).unwrap()
            }
        };
        let plain = run(None, 1);
        let off = run(Some(false), 1_000_000);
        let on = run(Some(true), 1_000_000);
        let capped = run(Some(true), 25);
        same_answers(&plain, &off, objectives);
        same_answers(&plain, &on, objectives);
        same_answers(&plain, &capped, objectives);
        assert!(!plain.solutions.is_empty(), "{objectives}");
        assert!(plain.transitions.is_empty() && off.transitions.is_empty() && !off.transitions_capped);
        // every rollout step is recorded, and at least one expansion per iteration that expanded
        let simulated = on.transitions.iter().filter(|t| t.kind == StepKind::Simulation).count();
        assert_eq!(simulated as u64, on.stats.rollout_steps, "{objectives}");
        let expanded = on.transitions.iter().filter(|t| t.kind == StepKind::Expansion).count();
        assert!(expanded as u64 >= on.stats.tree_nodes - 1 && expanded as u64 <= on.stats.iterations, "{objectives}");
        assert!(!on.transitions_capped);
        // the cap: the first transitions, then no more
        assert!(capped.transitions_capped);
        assert_eq!(capped.transitions.len(), 25);
        assert_eq!(capped.transitions[..], on.transitions[..25]);
    }
}

/// Replays `t` from its state and memory through `Mdp::step` with its kind and checks the
/// recorded actions, rewards, memory, next actions and completeness.
fn replay(p: &Mdp, t: &Transition) {
    let mut state = MapState::new(p.maps());
    state.reset(&t.present);
    let mut counts = p.filter_counts();
    let mut actions = Vec::new();
    p.feasible_actions(&mut state, &t.memory, t.kind, &mut actions, &mut counts);
    assert_eq!(actions, t.actions, "actions of {:?}", t.present);
    assert!(t.actions.contains(&t.action));
    let mut memory = t.memory.clone();
    let mut rewards = vec![0.0; p.num_objectives()];
    p.step(&mut state, &mut memory, t.action, t.kind, &mut rewards);
    assert_eq!(rewards, t.rewards, "rewards of removing {} from {:?}", t.action, t.present);
    assert_eq!(memory, t.next_memory);
    let mut next = PartSet::from_indices(p.maps().num_parts(), t.present.iter());
    next.remove(t.action);
    assert_eq!(state.present(), next);
    p.feasible_actions(&mut state, &memory, t.kind, &mut actions, &mut counts);
    assert_eq!(actions, t.next_actions, "next actions after removing {} from {:?}", t.action, t.present);
    assert_eq!(state.is_complete(), t.complete);
}

#[test]
fn every_transition_replays_on_a_3x3x3_soma_cube() {
    let cube = soma(3, 7);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access,dirchange");
    let out = ParetoMcts::builder().episodes(60).seed(9).record_transitions(true).build().unwrap().solve(&p).unwrap();
    let ts = &out.transitions;
    assert!(ts.len() > 100, "{} transitions", ts.len());
    let n = maps.num_parts();
    let mut kinds = [0usize; 2];
    for (k, t) in ts.iter().enumerate() {
        replay(&p, t);
        kinds[usize::from(t.kind == StepKind::Simulation)] += 1;
        // a step from the assembled state starts without a direction history
        let h = DirHistory::load(&t.memory[p.memory_range(1)]);
        assert_eq!(h.active, t.present.len() < n, "H is set once a part has left");
        assert!(DirHistory::load(&t.next_memory[p.memory_range(1)]).active);
        // a rollout continues from where the step before it ended
        if k > 0 && t.kind == StepKind::Simulation {
            let before = &ts[k - 1];
            assert_eq!(before.episode, t.episode);
            let mut s = before.present.clone();
            s.remove(before.action);
            assert_eq!((s, &before.next_memory, &before.next_actions), (t.present.clone(), &t.memory, &t.actions));
        }
        if k > 0 {
            assert!(ts[k - 1].episode <= t.episode, "episodes in order");
        }
    }
    assert!(kinds[0] > 0 && kinds[1] > 0, "expansions and simulations: {kinds:?}");
    assert!(ts.iter().any(|t| t.complete) && ts.iter().any(|t| t.next_actions.is_empty() && t.complete));
    assert!(ts.last().unwrap().episode < out.stats.episodes);
    // one thread and a seed: the same transitions
    let again = ParetoMcts::builder().episodes(60).seed(9).record_transitions(true).build().unwrap().solve(&p).unwrap();
    assert_eq!(&again.transitions, ts);
}

/// Rejects removals of one part in rollouts only: the kinds' feasible sets differ.
#[derive(Debug)]
struct NotInRollouts(usize);

impl asp_search::ActionFilter for NotInRollouts {
    fn name(&self) -> &str {
        "not-in-rollouts"
    }
    fn reasons(&self) -> Vec<String> {
        vec!["rollout".into()]
    }
    fn check(&self, step: &mut asp_search::StepContext<'_, '_>, _memory: &[u64]) -> asp_search::Verdict {
        if step.kind() == StepKind::Simulation && step.part() == self.0 {
            asp_search::Verdict::Infeasible { reason: 0 }
        } else {
            asp_search::Verdict::Feasible
        }
    }
}

/// The feasible removals of `present` with `memory` for steps of `kind`.
fn actions_of(p: &Mdp, present: &PartSet, memory: &[u64], kind: StepKind) -> Vec<usize> {
    let mut state = MapState::new(p.maps());
    state.reset(present);
    let mut out = Vec::new();
    p.feasible_actions(&mut state, memory, kind, &mut out, &mut p.filter_counts());
    out
}

#[test]
fn with_a_filter_each_step_records_the_actions_of_its_kind() {
    let cube = soma(3, 2);
    let maps = maps(&cube, 5);
    let plain = problem(&maps, "access,dirchange");
    let first = plain.feasible_in(&PartSet::full(maps.num_parts()), &plain.initial_memory());
    let p = plain.with_filter(std::sync::Arc::new(NotInRollouts(first[0])));
    // a small node cap: expansions beyond it (no node added) are recorded too
    let out = ParetoMcts::builder().episodes(40).seed(5).max_nodes(60).record_transitions(true).build().unwrap().solve(&p).unwrap();
    let ts = &out.transitions;
    let (mut kinds_differ, mut from_new_node) = (0, 0);
    for (k, t) in ts.iter().enumerate() {
        let first_rollout_step = t.kind == StepKind::Simulation && k > 0 && ts[k - 1].kind == StepKind::Expansion;
        if first_rollout_step && t.actions == ts[k - 1].next_actions {
            // from a node just added: the node's set, computed at its expansion
            from_new_node += 1;
            let mut t = t.clone();
            t.actions = actions_of(&p, &t.present, &t.memory, StepKind::Simulation);
            if t.actions.contains(&t.action) {
                replay(&p, &t);
            }
        } else {
            replay(&p, t);
        }
        let mut next = t.present.clone();
        next.remove(t.action);
        let other = if t.kind == StepKind::Expansion { StepKind::Simulation } else { StepKind::Expansion };
        kinds_differ += usize::from(actions_of(&p, &next, &t.next_memory, other) != t.next_actions);
    }
    assert!(from_new_node > 0 && kinds_differ > 0, "{from_new_node} rollouts from new nodes, {kinds_differ} steps where the kinds differ");
    assert!(ts.iter().filter(|t| t.kind == StepKind::Simulation).count() > 0);
}

#[test]
fn threads_record_in_thread_order_with_their_own_episode_numbers() {
    let cube = soma(4, 5);
    let maps = maps(&cube, 5);
    let p = problem(&maps, "access");
    let out = Mcts::builder().episodes(11).threads(2).seed(4).record_transitions(true).build().unwrap().solve(&p).unwrap();
    let episodes: Vec<u64> = out.transitions.iter().map(|t| t.episode).collect();
    assert!(episodes.windows(2).all(|w| w[0] <= w[1]), "thread 0's episodes 0..6, then thread 1's 6..11");
    assert_eq!(episodes.first(), Some(&0));
    assert_eq!(episodes.last(), Some(&10));
    assert!(episodes.contains(&5) && episodes.contains(&6));
    // each thread gets its share of the limit
    let capped = Mcts::builder()
        .episodes(11)
        .threads(2)
        .seed(4)
        .record_transitions(true)
        .record_transitions_limit(7)
        .build()
        .unwrap()
        .solve(&p)
        .unwrap();
    assert!(capped.transitions_capped);
    assert_eq!(capped.transitions.len(), 7);
    assert_eq!(capped.transitions.iter().filter(|t| t.episode >= 6).count(), 3);
    assert!(Mcts::builder().record_transitions_limit(0).build().is_err());
}

fn soma_file(dir: &Path, seed: u64) -> PathBuf {
    let path = dir.join(format!("soma_{seed}.glb"));
    asp_geom::io::write_glb(&soma(3, seed), &path).unwrap();
    path
}

fn numbers(v: &serde_json::Value) -> Vec<usize> {
    v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as usize).collect()
}

#[test]
fn the_data_set_has_the_documented_files_and_rebuilds_the_maps() {
    let dir = tempfile::tempdir().unwrap();
    let models = vec![soma_file(dir.path(), 1), soma_file(dir.path(), 2)];
    let settings = TransitionSettings {
        seed: 3,
        plan: PlanSettings { tolerance: Some(1e-5), ..PlanSettings::default() },
        optimise: OptimiseSettings {
            objectives: vec!["access".into(), "dirchange".into()],
            episodes: 12,
            resolution: 5,
            ..OptimiseSettings::default()
        },
        ..TransitionSettings::default()
    };
    let out = dir.path().join("q");
    let index = collect_transitions(&models, &out, &settings, &|_| {}).unwrap();
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
    assert_eq!(json["format"], "asp-transitions");
    assert_eq!(json["version"], 1);
    assert_eq!(json["features"], "asp-q/1 directions=25 neighbours=8");
    assert_eq!((json["node_dim"].as_u64(), json["edge_dim"].as_u64()), (Some(28 + 50), Some(5 + 50)));
    assert_eq!(json["objectives"], serde_json::json!(["access", "dirchange"]));
    assert_eq!((json["seed"].as_u64(), json["episodes"].as_u64()), (Some(3), Some(12)));
    let entries = json["assemblies"].as_array().unwrap();
    assert_eq!(entries.len(), 2);
    for (entry, path) in entries.iter().zip(&models) {
        assert_eq!(entry["model"], std::fs::canonicalize(path).unwrap().display().to_string());
        assert_eq!(entry["load"], serde_json::json!({"unit": null, "up": null, "fixed": []}));
        assert_eq!(
            entry["maps"],
            serde_json::json!({"objective": "access,dirchange", "resolution": 5, "d_max": null, "support": "below",
                               "tolerance": 1e-5, "contact_distance": null, "overlaps": "strict"})
        );
        // the maps rebuilt from the entry's arguments, as Python rebuilds them
        let load: asp_app::collect_q::LoadArgs = serde_json::from_value(entry["load"].clone()).unwrap();
        let plan = PlanSettings {
            unit: load.unit.as_deref().map(|u| asp_geom::Units::parse(u).unwrap()),
            up: load.up.as_deref().map(|a| asp_geom::math::Axis::parse(a).unwrap()),
            fixed: load.fixed,
            tolerance: entry["maps"]["tolerance"].as_f64(),
            ..PlanSettings::default()
        };
        let assembly = std::sync::Arc::new(asp_app::pipeline::load(Path::new(entry["model"].as_str().unwrap()), &plan).unwrap());
        let o = OptimiseSettings {
            // the index names the objectives comma-separated
            objectives: entry["maps"]["objective"].as_str().unwrap().split(',').map(String::from).collect(),
            pareto: true,
            resolution: entry["maps"]["resolution"].as_u64().unwrap() as usize,
            ..OptimiseSettings::default()
        };
        let p = asp_app::pipeline::optimiser_problem(&assembly, &plan, &o).unwrap().mdp;
        let n = p.maps().num_parts();
        assert_eq!(entry["parts"].as_u64().unwrap() as usize, n);
        assert_eq!(entry["removable"].as_u64().unwrap() as usize, p.removals());
        let d_max = p.maps().d_max() as f64;
        assert_eq!(entry["reward_ranges"], serde_json::json!([[0.0, 25.0 * d_max], [0.0, 25.0]]));
        let text = std::fs::read_to_string(out.join(entry["dir"].as_str().unwrap()).join("transitions.jsonl")).unwrap();
        let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        assert_eq!(lines.len(), entry["transitions"].as_u64().unwrap() as usize);
        assert!(lines.len() > 50);
        assert_eq!(entry["capped"], false);
        for l in &lines {
            let keys: Vec<&str> = l.as_object().unwrap().keys().map(|k| k.as_str()).collect();
            let mut want =
                ["episode", "kind", "present", "history", "actions", "action", "rewards", "next_history", "next_actions", "complete"];
            want.sort_unstable();
            let mut keys = keys;
            keys.sort_unstable();
            assert_eq!(keys, want);
            assert!(l["kind"] == "expansion" || l["kind"] == "simulation");
        }
        // every fifth line replays on the rebuilt maps: rewards, history, next actions
        for (l, raw) in lines.iter().zip(text.lines()).step_by(5) {
            let present = numbers(&l["present"]);
            assert!(present.windows(2).all(|w| w[0] < w[1]));
            let mut state = MapState::new(p.maps());
            state.reset(&PartSet::from_indices(n, present.iter().copied()));
            let mut memory = p.initial_memory();
            let history = numbers(&l["history"]);
            let h = DirHistory {
                mask: {
                    let mut m = asp_geom::distmap::DirMask::EMPTY;
                    history.iter().for_each(|&d| m.insert(d));
                    m
                },
                active: present.len() < n,
            };
            h.store(&mut memory[p.memory_range(1)]);
            let kind = if l["kind"] == "expansion" { StepKind::Expansion } else { StepKind::Simulation };
            let mut counts = p.filter_counts();
            let mut actions = Vec::new();
            p.feasible_actions(&mut state, &memory, kind, &mut actions, &mut counts);
            assert_eq!(actions, numbers(&l["actions"]));
            let mut rewards = vec![0.0; 2];
            p.step(&mut state, &mut memory, l["action"].as_u64().unwrap() as usize, kind, &mut rewards);
            // exactly the written digits (serde_json's default parser may be 1 ulp off; Python's
            // is exact, so compare the text)
            let written = format!("\"rewards\":{}", serde_json::to_string(&rewards).unwrap());
            assert!(raw.contains(&written), "{raw} holds {written}");
            let next: Vec<usize> = DirHistory::load(&memory[p.memory_range(1)]).mask.iter().collect();
            assert_eq!(next, numbers(&l["next_history"]));
            p.feasible_actions(&mut state, &memory, kind, &mut actions, &mut counts);
            assert_eq!(actions, numbers(&l["next_actions"]));
            assert_eq!(l["complete"].as_bool().unwrap(), state.is_complete());
        }
    }
    assert_eq!(index.assemblies.len(), 2);
    // deterministic per seed; another seed, other transitions
    let again = dir.path().join("again");
    collect_transitions(&models, &again, &settings, &|_| {}).unwrap();
    let other = dir.path().join("other");
    collect_transitions(&models, &other, &TransitionSettings { seed: 4, ..settings.clone() }, &|_| {}).unwrap();
    let lines = |root: &Path| std::fs::read(root.join("soma_2").join("transitions.jsonl")).unwrap();
    assert_eq!(lines(&out), lines(&again));
    assert_ne!(lines(&out), lines(&other));
}

#[test]
fn collection_errors_name_the_cause() {
    let dir = tempfile::tempdir().unwrap();
    let model = soma_file(dir.path(), 1);
    let out = dir.path().join("q");
    let with = |objectives: &[&str], episodes: usize| TransitionSettings {
        optimise: OptimiseSettings {
            objectives: objectives.iter().map(|s| s.to_string()).collect(),
            episodes,
            ..OptimiseSettings::default()
        },
        ..TransitionSettings::default()
    };
    let err = collect_transitions(std::slice::from_ref(&model), &out, &with(&["speed"], 5), &|_| {}).unwrap_err();
    assert!(err.to_string().contains("speed"), "{err}");
    let err = collect_transitions(std::slice::from_ref(&model), &out, &with(&["access"], 0), &|_| {}).unwrap_err();
    assert!(err.to_string().contains("episodes"), "{err}");
    let missing = dir.path().join("missing.glb");
    let err = collect_transitions(&[model, missing], &out, &with(&["access"], 5), &|_| {}).unwrap_err();
    assert!(err.to_string().contains("missing.glb"), "{err}");
}
