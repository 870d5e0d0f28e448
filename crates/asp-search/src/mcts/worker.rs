//! One thread's search: a [`Worker`] grows its graph episode by episode; an iteration is
//! [`Worker::select`], [`Worker::expand`], [`Worker::rollout`] and [`Worker::backup`].

use super::graph::{state_hash, Bounds, Edge, Node, NodeSets, SelectContext, Status, Tree, Variant, NONE, PENDING};
use super::outcome::{EpisodeEnd, EpisodeHook, Next, SearchStats, TracePoint};
use super::record::Recorder;
use super::settings::SearchSettings;
use crate::error::{Result, SearchError};
use crate::hypervolume::ParetoFront;
use crate::mdp::{FilterCounts, Mdp, MAX_OBJECTIVES};
use crate::policy::{rng_for, PolicyContext, PolicyWorker, SearchRng};
use crate::polish::{Ended, Polisher};
use crate::problem::StopToken;
use crate::step::StepKind;
use asp_geom::distmap::MapState;
use asp_geom::PartSet;
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// What [`Worker::expand`] did: the removal it took, whether it became an edge of the graph (and
/// the path moved to its child) and whether that child is new.
struct Expansion {
    action: usize,
    expanded: bool,
    new_child: bool,
}

/// What the threads share: the merged front and the trace.
pub(super) struct Shared {
    pub front: ParetoFront<()>,
    pub episodes: u64,
    pub iterations: u64,
    pub trace: Vec<TracePoint>,
    pub last_value: Option<f64>,
}

/// One thread's search over its own graph.
pub(super) struct Worker<'p, V: Variant> {
    problem: &'p Mdp,
    settings: &'p SearchSettings,
    m: usize,
    n: usize,
    /// Memory words per state.
    w: usize,
    pub tree: Tree<V::Value>,
    rng: SearchRng,
    sim: MapState<'p>,
    /// The thread's index.
    thread: usize,
    /// Whether the current policy gives priors.
    priors: bool,
    /// The PUCT weight the current policy's priors are meant for.
    policy_weight: Option<f64>,
    actions: Vec<usize>,
    candidates: Vec<u32>,
    /// Scratch: a node's untried actions and their priors, and the priors of new nodes.
    untried: Vec<usize>,
    untried_priors: Vec<f64>,
    prior_buf: Vec<f64>,
    /// Scratch: the memory words of the state being simulated.
    memory: Vec<u64>,
    /// The nodes of the current path from the root, the edges between them, and the returns
    /// collected up to each node (`m` per node).
    path: Vec<u32>,
    path_edges: Vec<u32>,
    path_prefix: Vec<f64>,
    sequence: Vec<u16>,
    bounds: Bounds,
    pub archive: ParetoFront<Vec<u16>>,
    archive_changed: bool,
    pub stats: SearchStats,
    pub filtered: FilterCounts,
    deadline: Option<Instant>,
    /// When the search started.
    start: Instant,
    /// The complete sequences' values that entered the archive during the current episode,
    /// with the seconds and the episode's iterations when they did (trace rows inside an
    /// episode).
    found: Vec<(Vec<f64>, f64, u64)>,
    /// Iterations of the current episode so far.
    episode_iterations: u64,
    stopped: bool,
    /// The first plug-in error; it stops this worker, and through `abort` the others.
    pub error: Option<SearchError>,
    abort: &'p StopToken,
    /// The recording, when the settings ask for it.
    pub record: Option<Recorder>,
    /// The local search, when the settings ask for one.
    polisher: Option<Polisher<'p>>,
}

impl<'p, V: Variant> Worker<'p, V> {
    pub fn new(
        problem: &'p Mdp,
        settings: &'p SearchSettings,
        thread: usize,
        start: Instant,
        abort: &'p StopToken,
        first_episode: u64,
    ) -> Result<Self> {
        let m = problem.num_objectives();
        let maps = problem.maps();
        let n = maps.num_parts();
        let memory = problem.initial_memory();
        let w = memory.len();
        let mut sim = MapState::new(maps);
        let mut filtered = problem.filter_counts();
        let mut actions = Vec::with_capacity(n);
        problem.feasible_actions(&mut sim, &memory, StepKind::Expansion, &mut actions, &mut filtered);
        let full = PartSet::full(n);
        let complete = sim.is_complete();
        let root = Node {
            first_edge: NONE,
            visits: 0,
            status: if complete {
                Status::Solved
            } else if actions.is_empty() {
                Status::Dead
            } else {
                Status::Open
            },
            next_same: NONE,
            untried_left: actions.len() as u16,
        };
        let root_sets = NodeSets { present: full, free: sim.collision_free(), untried: PartSet::from_indices(n, actions.iter().copied()) };
        let mut tree = Tree {
            nodes: vec![root],
            sets: vec![root_sets],
            values: vec![V::Value::default()],
            edges: Vec::new(),
            rewards: Vec::new(),
            memory: memory.clone(),
            w,
            index: HashMap::default(),
            m,
            prior_spans: Vec::new(),
            node_priors: Vec::new(),
            edge_priors: Vec::new(),
        };
        if settings.transpositions {
            tree.index.insert(state_hash(&tree.sets[0].present, tree.memory(0), problem), 0);
        }
        let worker = Worker {
            problem,
            settings,
            m,
            n,
            w,
            tree,
            rng: rng_for(settings.seed, thread as u64),
            sim,
            thread,
            priors: false,
            policy_weight: None,
            actions,
            candidates: Vec::with_capacity(n),
            untried: Vec::with_capacity(n),
            untried_priors: Vec::with_capacity(n),
            prior_buf: Vec::with_capacity(n),
            memory,
            path: Vec::with_capacity(n + 1),
            path_edges: Vec::with_capacity(n),
            path_prefix: Vec::with_capacity((n + 1) * m),
            sequence: Vec::with_capacity(n),
            bounds: Bounds::new(),
            archive: ParetoFront::new(m),
            archive_changed: false,
            stats: SearchStats::default(),
            filtered,
            deadline: settings.time_limit.map(|t| start + t),
            start,
            found: Vec::new(),
            episode_iterations: 0,
            stopped: false,
            error: None,
            abort,
            record: settings.record.then(|| Recorder {
                transitions: Vec::new(),
                limit: share_of(settings.record_limit, settings.threads, thread),
                capped: false,
                episode: first_episode,
                pending: None,
                actions: Vec::with_capacity(n),
                counts: problem.filter_counts(),
            }),
            polisher: (settings.polish > 0.0).then(|| Polisher::new(problem)),
        };
        Ok(worker)
    }

    /// Takes `policy` (this thread's worker of the search's policy, or of a policy swapped in
    /// between episodes) as the one the next episodes use. A policy that gives priors is asked
    /// for a node's when the search first expands from it (the root's too); nodes added while the
    /// policy gave none have none ([`Tree::prior_of`]).
    fn adopt(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        self.priors = policy.has_priors();
        self.policy_weight = policy.prior_weight();
        if !self.priors {
            return Ok(());
        }
        if self.tree.prior_spans.is_empty() && self.tree.nodes.len() == 1 && self.stats.iterations == 0 {
            self.tree.prior_spans.push(PENDING);
            return Ok(());
        }
        self.tree.prior_spans.resize(self.tree.nodes.len(), (NONE, NONE));
        self.tree.edge_priors.resize(self.tree.edges.len(), 0.0);
        Ok(())
    }

    /// Asks the policy for the priors of `node`'s feasible removals `actions` in the simulated
    /// state (which must be that node's) and keeps them for that node. Priors are asked for
    /// lazily, when the search first expands from a node, so a node it never expands from costs
    /// no evaluation; they are a function of the state, so the search is the same as if they had
    /// been asked for when the node was added.
    fn record_priors(&mut self, policy: &mut dyn PolicyWorker, node: u32, actions: &[usize]) -> Result<()> {
        let count = actions.len();
        self.prior_buf.clear();
        self.prior_buf.resize(count, 0.0);
        let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
        policy.priors(&mut ctx, actions, &mut self.prior_buf)?;
        let from = self.tree.node_priors.len() as u32;
        self.tree.node_priors.extend(actions.iter().zip(&self.prior_buf).map(|(&a, &p)| (a as u16, p as f32)));
        self.tree.prior_spans[node as usize] = (from, self.tree.node_priors.len() as u32);
        Ok(())
    }

    fn root_finished(&self) -> bool {
        self.tree.nodes[0].status != Status::Open
    }

    /// Moves the path along edge `e` to its child.
    fn push(&mut self, e: u32) {
        let m = self.m;
        let child = self.tree.edges[e as usize].child;
        let base = self.path_prefix.len() - m;
        for k in 0..m {
            let v = self.path_prefix[base + k] + self.tree.rewards[e as usize * m + k];
            self.path_prefix.push(v);
        }
        self.path.push(child);
        self.path_edges.push(e);
    }

    /// Cuts the path back to its first `len` nodes.
    fn truncate(&mut self, len: usize) {
        self.path.truncate(len);
        self.path_edges.truncate(len - 1);
        self.path_prefix.truncate(len * self.m);
    }

    /// Whether the time limit or the stop token says to stop.
    #[inline]
    fn should_stop(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
            || self.settings.stop.as_ref().is_some_and(StopToken::is_stopped)
            || self.abort.is_stopped()
    }

    /// One episode: search steps from the root down to a complete sequence.
    fn episode(&mut self, policy: &mut dyn PolicyWorker) {
        self.episode_iterations = 0;
        self.path.clear();
        self.path_edges.clear();
        self.path_prefix.clear();
        self.path.push(0);
        self.path_prefix.extend(std::iter::repeat_n(0.0, self.m));
        loop {
            let current = *self.path.last().expect("the path starts at the root");
            let node = &self.tree.nodes[current as usize];
            if node.status == Status::Dead || (node.status == Status::Solved && node.first_edge == NONE) {
                break;
            }
            for _ in 0..self.settings.budget {
                if self.tree.nodes[current as usize].status != Status::Open {
                    break;
                }
                if let Err(e) = self.iterate(policy) {
                    self.error = Some(e);
                    self.stopped = true;
                    return;
                }
                self.stats.iterations += 1;
                self.episode_iterations += 1;
                if self.should_stop() {
                    self.stopped = true;
                    return;
                }
            }
            match self.commit(current) {
                Some(e) => self.push(e),
                None => break,
            }
        }
    }

    /// The tree policy's context at the end of the path.
    fn select_context(&self) -> SelectContext<'_> {
        let m = self.m;
        SelectContext {
            exploration: self.settings.exploration,
            bounds: &self.bounds,
            prefix: &self.path_prefix[self.path_prefix.len() - m..],
            priors: self.prior_weight().map(|w| (w, &self.tree.edge_priors[..])),
        }
    }

    /// The PUCT weight of the policy's priors: the search's, else the one the policy asks for
    /// (`None` without priors or with a weight of 0).
    fn prior_weight(&self) -> Option<f64> {
        let w = if self.settings.prior_weight > 0.0 { self.settings.prior_weight } else { self.policy_weight.unwrap_or(0.0) };
        (self.priors && w > 0.0).then_some(w)
    }

    /// One greedy sequence of the policy from the assembled state (when it ranks removals:
    /// [`PolicyWorker::greedy`]), offered to the archive and, as a seed, to the local search.
    /// Deterministic: it draws nothing from the search's random stream.
    fn greedy_seed(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        let m = self.m;
        let root = &self.tree.sets[0];
        self.sim.reset_with_free(&root.present, &root.free);
        self.memory.copy_from_slice(self.tree.memory(0));
        self.sequence.clear();
        let mut ret = [0.0f64; MAX_OBJECTIVES];
        let mut rewards = [0.0f64; MAX_OBJECTIVES];
        let mut actions = Vec::with_capacity(self.n);
        loop {
            self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Simulation, &mut actions, &mut self.filtered);
            if actions.is_empty() {
                break;
            }
            let pick = {
                let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
                policy.greedy(&mut ctx, &actions)?
            };
            let Some(k) = pick else { return Ok(()) };
            let Some(&p) = actions.get(k) else {
                return Err(SearchError::plugin("greedy policy", format!("chose action {k} of {}", actions.len())));
            };
            self.problem.step(&mut self.sim, &mut self.memory, p, StepKind::Simulation, &mut rewards[..m]);
            for k in 0..m {
                ret[k] += rewards[k];
            }
            self.sequence.push(p as u16);
        }
        if self.sim.is_complete() {
            self.bounds.update(&ret[..m]);
            let seq = &self.sequence;
            if let Some(p) = &mut self.polisher {
                p.seed(&ret[..m], seq);
            }
            if self.archive.insert(&ret[..m], || seq.clone()) {
                self.archive_changed = true;
                self.found.push((ret[..m].to_vec(), self.start.elapsed().as_secs_f64(), 0));
            }
        }
        Ok(())
    }

    /// The edge the tree policy takes at the end of a search step (to any child that is not
    /// dead).
    fn commit(&mut self, node: u32) -> Option<u32> {
        self.candidates.clear();
        for e in self.tree.edges_of(node) {
            let child = self.tree.edges[e as usize].child;
            if self.tree.nodes[child as usize].status != Status::Dead {
                self.candidates.push(e);
            }
        }
        if self.candidates.is_empty() {
            return None;
        }
        let k = V::select(&self.tree, node, &self.candidates, &self.select_context());
        Some(self.candidates[k])
    }

    /// Selection, expansion, rollout and backpropagation from the end of the path.
    fn iterate(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        let m = self.m;
        let base = self.path.len();
        if !self.select() {
            self.truncate(base);
            return Ok(());
        }
        let parent = *self.path.last().expect("path");
        // the returns so far: the path's, then the expansion's and the rollout's rewards
        let mut ret = [0.0f64; MAX_OBJECTIVES];
        ret[..m].copy_from_slice(&self.path_prefix[self.path_prefix.len() - m..]);
        let step = self.expand(policy, parent, &mut ret)?;

        // The sequence so far: the path's removals (and the unexpanded action).
        self.sequence.clear();
        self.sequence.extend(self.path_edges.iter().map(|&e| self.tree.edges[e as usize].action));
        if !step.expanded {
            self.sequence.push(step.action as u16);
        }

        let complete = self.rollout(policy, step.new_child, &mut ret)?;
        self.backup(complete, &ret);
        let leaf = *self.path.last().expect("path");
        if step.new_child && self.tree.nodes[leaf as usize].status != Status::Open || self.tree.nodes[parent as usize].untried_left == 0 {
            self.refresh_path_status();
        }
        self.truncate(base);
        Ok(())
    }

    /// Selection: descends through fully expanded nodes by the tree policy, from the end of the
    /// path to a node with untried removals. False when there is none below (the path's nodes'
    /// statuses are then brought up to date).
    fn select(&mut self) -> bool {
        loop {
            let node = *self.path.last().expect("path");
            let nd = &self.tree.nodes[node as usize];
            if nd.status != Status::Open {
                return false;
            }
            if nd.untried_left != 0 {
                return true;
            }
            self.candidates.clear();
            for e in self.tree.edges_of(node) {
                let child = self.tree.edges[e as usize].child;
                if self.tree.nodes[child as usize].status == Status::Open {
                    self.candidates.push(e);
                }
            }
            if self.candidates.is_empty() {
                self.refresh_path_status();
                return false;
            }
            let k = V::select(&self.tree, node, &self.candidates, &self.select_context());
            let e = self.candidates[k];
            self.push(e);
        }
    }

    /// Expansion: an untried removal of `parent` (the end of the path), chosen by the policy (at
    /// random by default), taken in the simulated state; its rewards are added to `ret`. Below
    /// the node cap (or onto an existing node) it becomes an edge to the child, which the path
    /// moves to.
    fn expand(&mut self, policy: &mut dyn PolicyWorker, parent: u32, ret: &mut [f64; MAX_OBJECTIVES]) -> Result<Expansion> {
        let m = self.m;
        let w = self.w;
        let ps = &self.tree.sets[parent as usize];
        self.sim.reset_with_free(&ps.present, &ps.free);
        self.memory.copy_from_slice(self.tree.memory(parent));
        self.untried.clear();
        self.untried.extend(self.tree.sets[parent as usize].untried.iter());
        if self.priors && self.tree.priors_pending(parent) {
            // first expansion from the node: nothing expanded yet, so its untried removals are
            // all its feasible ones
            let untried = std::mem::take(&mut self.untried);
            let r = self.record_priors(policy, parent, &untried);
            self.untried = untried;
            r?;
        }
        let untried_priors = if self.priors && self.tree.has_priors(parent) {
            self.untried_priors.clear();
            for &a in &self.untried {
                self.untried_priors.push(self.tree.prior_of(parent, a) as f64);
            }
            Some(&self.untried_priors[..])
        } else {
            None
        };
        let pick = {
            let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
            policy.expand(&mut ctx, &self.untried, untried_priors, &mut self.rng)?
        };
        let Some(&action) = self.untried.get(pick) else {
            return Err(SearchError::plugin("expansion policy", format!("chose untried action {pick} of {}", self.untried.len())));
        };
        if let Some(rec) = &mut self.record {
            if rec.active() {
                let mut actions = std::mem::take(&mut rec.actions);
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Expansion, &mut actions, &mut rec.counts);
                rec.begin(StepKind::Expansion, self.sim.present(), &self.memory, &actions, action);
                rec.actions = actions;
            }
        }
        let mut rewards = [0.0f64; MAX_OBJECTIVES];
        self.problem.step(&mut self.sim, &mut self.memory, action, StepKind::Expansion, &mut rewards[..m]);
        for k in 0..m {
            ret[k] += rewards[k];
        }
        if let Some(rec) = &mut self.record {
            rec.taken(&rewards[..m], &self.memory, self.sim.is_complete());
        }
        let present = self.sim.present();
        // The child: an existing node with the same state, or a new one.
        let hash = if self.settings.transpositions { state_hash(&present, &self.memory, self.problem) } else { 0 };
        let mut existing = NONE;
        if self.settings.transpositions {
            let mut c = self.tree.index.get(&hash).copied().unwrap_or(NONE);
            while c != NONE {
                if self.tree.is(c, &present, &self.memory, self.problem) {
                    existing = c;
                    break;
                }
                c = self.tree.nodes[c as usize].next_same;
            }
        }
        let expanded = existing != NONE || self.tree.nodes.len() < self.settings.max_nodes;
        let mut new_child = false;
        if expanded {
            self.tree.sets[parent as usize].untried.remove(action);
            self.tree.nodes[parent as usize].untried_left -= 1;
            let child = if existing != NONE {
                existing
            } else {
                new_child = true;
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Expansion, &mut self.actions, &mut self.filtered);
                let status = if self.sim.is_complete() {
                    Status::Solved
                } else if self.actions.is_empty() {
                    Status::Dead
                } else {
                    Status::Open
                };
                let id = self.tree.nodes.len() as u32;
                let next_same = if self.settings.transpositions { self.tree.index.insert(hash, id).unwrap_or(NONE) } else { NONE };
                self.tree.nodes.push(Node { first_edge: NONE, visits: 0, status, next_same, untried_left: self.actions.len() as u16 });
                self.tree.sets.push(NodeSets {
                    present,
                    free: self.sim.collision_free(),
                    untried: PartSet::from_indices(self.n, self.actions.iter().copied()),
                });
                self.tree.values.push(V::Value::default());
                self.tree.memory.extend_from_slice(&self.memory[..w]);
                if self.priors {
                    self.tree.prior_spans.push(PENDING);
                }
                id
            };
            let e = self.tree.edges.len() as u32;
            let first = self.tree.nodes[parent as usize].first_edge;
            self.tree.edges.push(Edge { child, next: first, visits: 0, action: action as u16 });
            self.tree.rewards.extend_from_slice(&rewards[..m]);
            if self.priors {
                let p = self.tree.prior_of(parent, action);
                self.tree.edge_priors.push(p);
            }
            self.tree.nodes[parent as usize].first_edge = e;
            self.push(e);
        }

        // The recorded step's s': a new child's feasible actions are in `actions` (the rollout
        // completes the record), the rollout computes them for simulation otherwise, which is
        // the same set unless filters tell the kinds apart.
        if !new_child && !self.problem.filters().is_empty() {
            if let Some(rec) = self.record.as_mut().filter(|r| r.pending.is_some()) {
                let mut actions = std::mem::take(&mut rec.actions);
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Expansion, &mut actions, &mut rec.counts);
                rec.finish(&actions);
                rec.actions = actions;
            }
        }
        Ok(Expansion { action, expanded, new_child })
    }

    /// Rollout with the rollout policy from the simulated state (from a transposed child too:
    /// more evidence) until no removal is admitted; its rewards are added to `ret` and its
    /// removals to the sequence. A new child's feasible removals are in `actions` already
    /// (`known`). With lazy filters the other states offer the maps' candidates and the filters
    /// are asked about the drawn one. A complete sequence is offered to the archive (and the
    /// local search); returns whether the sequence is complete.
    fn rollout(&mut self, policy: &mut dyn PolicyWorker, known: bool, ret: &mut [f64; MAX_OBJECTIVES]) -> Result<bool> {
        let m = self.m;
        let mut rewards = [0.0f64; MAX_OBJECTIVES];
        let lazy = self.settings.lazy_filters && !self.problem.filters().is_empty();
        let mut known = known;
        loop {
            let filtered = known || !lazy;
            if !known {
                if lazy {
                    self.problem.candidate_actions(&mut self.sim, &mut self.actions);
                } else {
                    self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Simulation, &mut self.actions, &mut self.filtered);
                }
            }
            known = false;
            // the recording needs the state's admitted removals: with lazy filters it filters
            // them on its own (the filters' verdicts depend on the step only, so the search
            // draws the same removals either way)
            let recording = self.record.as_mut().is_some_and(|r| r.pending.is_some() || r.active());
            let mut admitted = Vec::new();
            if recording && !filtered {
                let rec = self.record.as_mut().expect("recording");
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Simulation, &mut admitted, &mut rec.counts);
            }
            if let Some(rec) = &mut self.record {
                rec.finish(if filtered { &self.actions } else { &admitted });
            }
            let mut chosen = None;
            while !self.actions.is_empty() {
                let k = {
                    let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
                    policy.choose(&mut ctx, &self.actions, &mut self.rng)?
                };
                let Some(&p) = self.actions.get(k) else {
                    return Err(SearchError::plugin("rollout policy", format!("chose action {k} of {}", self.actions.len())));
                };
                if filtered || self.problem.admits(&mut self.sim, &self.memory, p, StepKind::Simulation, &mut self.filtered) {
                    chosen = Some(p);
                    break;
                }
                self.actions.remove(k);
            }
            let Some(p) = chosen else { break };
            if let Some(rec) = &mut self.record {
                if rec.active() {
                    rec.begin(StepKind::Simulation, self.sim.present(), &self.memory, if filtered { &self.actions } else { &admitted }, p);
                }
            }
            self.problem.step(&mut self.sim, &mut self.memory, p, StepKind::Simulation, &mut rewards[..m]);
            if let Some(rec) = &mut self.record {
                rec.taken(&rewards[..m], &self.memory, self.sim.is_complete());
            }
            for k in 0..m {
                ret[k] += rewards[k];
            }
            self.sequence.push(p as u16);
            self.stats.rollout_steps += 1;
        }
        let complete = self.sim.is_complete();
        if complete {
            self.bounds.update(&ret[..m]);
            let seq = &self.sequence;
            if let Some(p) = &mut self.polisher {
                p.seed(&ret[..m], seq);
            }
            if self.archive.insert(&ret[..m], || seq.clone()) {
                self.archive_changed = true;
                let seconds = self.start.elapsed().as_secs_f64();
                self.found.push((ret[..m].to_vec(), seconds, self.episode_iterations + 1));
            }
        } else {
            self.stats.dead_rollouts += 1;
        }
        Ok(complete)
    }

    /// Backpropagation along the path: visits everywhere, the suffix values of a `complete`
    /// sequence with returns `ret` until a node adds nothing (without transpositions) or
    /// everywhere (with them).
    fn backup(&mut self, complete: bool, ret: &[f64; MAX_OBJECTIVES]) {
        let m = self.m;
        let mut propagate = complete;
        let mut suffix = [0.0f64; MAX_OBJECTIVES];
        for i in (0..self.path.len()).rev() {
            let node = self.path[i] as usize;
            self.tree.nodes[node].visits += 1;
            if i > 0 {
                self.tree.edges[self.path_edges[i - 1] as usize].visits += 1;
            }
            if propagate {
                for k in 0..m {
                    suffix[k] = ret[k] - self.path_prefix[i * m + k];
                }
                let added = V::record(&mut self.tree.values[node], &suffix[..m]);
                if !added && !self.settings.transpositions {
                    propagate = false;
                }
            }
        }
    }

    /// Recomputes the status of the path's nodes from their children, from the end up, while
    /// they change.
    fn refresh_path_status(&mut self) {
        for i in (0..self.path.len()).rev() {
            let node = self.path[i];
            let nd = &self.tree.nodes[node as usize];
            if nd.first_edge == NONE {
                continue; // a leaf: its status is its own
            }
            if nd.untried_left != 0 {
                return; // open, and so are its ancestors
            }
            let (mut open, mut solved) = (false, false);
            for e in self.tree.edges_of(node) {
                match self.tree.nodes[self.tree.edges[e as usize].child as usize].status {
                    Status::Open => open = true,
                    Status::Solved => solved = true,
                    Status::Dead => {}
                }
            }
            let status = if open {
                Status::Open
            } else if solved {
                Status::Solved
            } else {
                Status::Dead
            };
            if status == self.tree.nodes[node as usize].status {
                return;
            }
            self.tree.nodes[node as usize].status = status;
        }
    }

    /// Publishes the archive to the shared front and the trace.
    fn sync(&mut self, shared: &Mutex<Shared>, reference: &[f64], start: Instant, iterations: u64, episode: bool) {
        let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
        // the improvements inside the episode first, each as it was found
        for (point, seconds, at) in std::mem::take(&mut self.found) {
            if !s.front.insert(&point, || ()) {
                continue;
            }
            let value = front_value(&s.front, reference);
            if s.last_value != Some(value) && !s.front.is_empty() && at < iterations {
                s.last_value = Some(value);
                let point =
                    TracePoint { episode: s.episodes + 1, iterations: s.iterations + at, seconds, value, front_size: s.front.len() };
                s.trace.push(point);
            }
        }
        if episode {
            s.episodes += 1;
        }
        s.iterations += iterations;
        if self.archive_changed {
            for (p, _) in self.archive.iter() {
                s.front.insert(p, || ());
            }
            self.archive_changed = false;
        }
        let value = front_value(&s.front, reference);
        if s.last_value != Some(value) && !s.front.is_empty() {
            s.last_value = Some(value);
            let point = TracePoint {
                episode: s.episodes,
                iterations: s.iterations,
                seconds: start.elapsed().as_secs_f64(),
                value,
                front_size: s.front.len(),
            };
            s.trace.push(point);
        }
    }

    /// Runs `episodes` episodes (or until the time limit, a stop or the root is finished) with
    /// the settings' policy. With a `hook` (the stepped search) the hook is asked before every
    /// episode after the first, with what the previous one did, whether to go on, swap the
    /// policy or stop, and once more when the search ends.
    pub fn run(
        &mut self,
        episodes: usize,
        shared: &Mutex<Shared>,
        reference: &[f64],
        start: Instant,
        mut hook: Option<&mut EpisodeHook<'_>>,
    ) {
        let mut current = self.settings.policy.clone();
        let mut policy = match current.for_worker(self.thread) {
            Ok(p) => p,
            Err(e) => return self.fail(e),
        };
        if let Err(e) = self.adopt(&mut *policy) {
            return self.fail(e);
        }
        if self.stats.iterations == 0 && !self.root_finished() {
            if let Err(e) = self.greedy_seed(&mut *policy) {
                return self.fail(e);
            }
        }
        let mut last = (self.stats.iterations, start.elapsed());
        for k in 0..episodes {
            if self.stopped || self.root_finished() {
                break;
            }
            if self.settings.stop.as_ref().is_some_and(StopToken::is_stopped) || self.abort.is_stopped() {
                self.stopped = true;
                break;
            }
            if let (Some(h), true) = (hook.as_deref_mut(), k > 0) {
                let report = self.report(shared, start, &mut last, false);
                match h(report) {
                    Ok(Next::Continue) => {}
                    Ok(Next::Stop) => break,
                    Ok(Next::Policy(p)) => {
                        drop(policy);
                        current = p;
                        policy = match current.for_worker(self.thread) {
                            Ok(p) => p,
                            Err(e) => return self.fail(e),
                        };
                        if let Err(e) = self.adopt(&mut *policy) {
                            return self.fail(e);
                        }
                    }
                    Err(e) => return self.fail(e),
                }
            }
            let before = self.stats.iterations;
            self.episode(&mut *policy);
            if let Some(rec) = &mut self.record {
                rec.episode += 1;
            }
            if !self.stopped {
                self.stats.episodes += 1;
                self.polish(false);
            }
            self.sync(shared, reference, start, self.stats.iterations - before, true);
        }
        if self.error.is_none() && !self.should_stop() && self.polish(true) {
            self.sync(shared, reference, start, 0, false);
        }
        if let Some(h) = hook {
            let report = self.report(shared, start, &mut last, true);
            if let Err(e) = h(report) {
                return self.fail(e);
            }
        }
        self.finish();
    }

    /// Local search around the archive's sequences not searched yet ([`crate::polish`]), while
    /// its work stays within its share of the tree search's (`last`: up to as much work as the
    /// tree search, when the episodes are done). Returns whether it added anything.
    fn polish(&mut self, last: bool) -> bool {
        let Some(mut polisher) = self.polisher.take() else { return false };
        // its work in both of the search's currencies: map steps, and checks by the problem's
        // feasibility filters (a robot's plans a path; they cost far more than a step)
        let share = if last { self.settings.polish.max(1.0) } else { self.settings.polish };
        let cap = (self.stats.iterations + self.stats.rollout_steps) as f64 * share;
        let check_cap = self.filtered.checks() as f64 * share;
        let filters = !self.problem.filters().is_empty();
        let over_checks = move |checks: u64| filters && checks as f64 >= check_cap;
        let over = move |steps: u64, checks: u64| steps as f64 >= cap || over_checks(checks);
        let (deadline, stop, abort) = (self.deadline, self.settings.stop.as_ref(), self.abort);
        let should_stop = || deadline.is_some_and(|d| Instant::now() >= d) || stop.is_some_and(StopToken::is_stopped) || abort.is_stopped();
        let mut added = 0u64;
        while !over(polisher.steps, polisher.checks()) {
            let Some((seq, seed, from)) = polisher.queue.pop() else { break };
            if !seed && !self.archive.iter().any(|(_, s)| *s == seq) {
                continue; // dominated since the local search found it
            }
            let (found, start) = (&mut self.found, self.start);
            let ended = polisher.search_around(
                &seq,
                from,
                &mut self.archive,
                |values| {
                    added += 1;
                    found.push((values.to_vec(), start.elapsed().as_secs_f64(), u64::MAX));
                },
                // map steps are cheap: a search around a sequence may finish past their limit
                // (it stays deterministic); filter checks may not be
                |_, checks| over_checks(checks) || should_stop(),
            );
            if let Ended::Stopped(at) = ended {
                polisher.queue.push((seq, seed, at));
                break;
            }
        }
        self.stats.polish_steps = polisher.steps;
        self.stats.polished += added;
        self.archive_changed |= added > 0;
        self.polisher = Some(polisher);
        added > 0
    }

    /// Ends the run with a plug-in's (or the hook's) error.
    fn fail(&mut self, e: SearchError) {
        self.error = Some(e);
        self.stopped = true;
        self.finish();
    }

    /// What the episode just run did, for the stepped search's hook: its transitions (taken out
    /// of the recording, whose limit is then per episode), and the front so far.
    fn report(&mut self, shared: &Mutex<Shared>, start: Instant, last: &mut (u64, Duration), last_call: bool) -> EpisodeEnd {
        let (transitions, transitions_capped) = match &mut self.record {
            Some(rec) => {
                let capped = std::mem::replace(&mut rec.capped, false);
                (std::mem::take(&mut rec.transitions), capped)
            }
            None => (Vec::new(), false),
        };
        let s = shared.lock().unwrap_or_else(|e| e.into_inner());
        let now = start.elapsed();
        let report = EpisodeEnd {
            episodes: self.stats.episodes,
            iterations: self.stats.iterations - last.0,
            seconds: (now - last.1).as_secs_f64(),
            value: if s.front.is_empty() { 0.0 } else { s.last_value.unwrap_or(0.0) },
            front_size: s.front.len(),
            transitions,
            transitions_capped,
            finished: last_call,
            exhausted: self.root_finished(),
            stopped: self.stopped,
        };
        *last = (self.stats.iterations, now);
        report
    }

    /// The statistics and the graph's answers at the end of a run.
    fn finish(&mut self) {
        if let Some(p) = &self.polisher {
            self.filtered.add(p.counts());
        }
        self.stats.tree_nodes = self.tree.nodes.len() as u64;
        self.stats.exhausted = self.root_finished();
        let c = self.sim.counters();
        self.stats.removal_tests = c.blocked + c.gravity_tests;
        self.stats.failed_collision = c.blocked;
        self.stats.failed_gravity = c.unsupported;
        self.stats.stopped = self.stopped && self.error.is_none();
        if self.error.is_some() {
            self.abort.stop();
        } else if self.settings.transpositions {
            self.read_graph();
        }
    }

    /// Adds to the archive the non-dominated complete sequences that lie wholly in the graph:
    /// with transpositions the best suffix of a state may have been found after reaching it on
    /// another path, so the archive alone can miss combinations. Dynamic programming over the
    /// graph's complete paths (exact when the root is finished).
    fn read_graph(&mut self) {
        let m = self.m;
        let count = self.tree.nodes.len();
        // fronts[node]: suffix vectors of complete paths in the graph, with (edge, child point)
        let mut fronts: Vec<Option<ParetoFront<(u32, u32)>>> = vec![None; count];
        // post-order without recursion
        let mut stack: Vec<(u32, bool)> = vec![(0, false)];
        let mut point = vec![0.0f64; m];
        while let Some((node, expanded)) = stack.pop() {
            if fronts[node as usize].is_some() {
                continue;
            }
            if !expanded {
                stack.push((node, true));
                for e in self.tree.edges_of(node) {
                    let child = self.tree.edges[e as usize].child;
                    if fronts[child as usize].is_none() {
                        stack.push((child, false));
                    }
                }
                continue;
            }
            let mut front = ParetoFront::new(m);
            let nd = &self.tree.nodes[node as usize];
            if nd.first_edge == NONE && nd.status == Status::Solved {
                front.insert(&vec![0.0; m], || (NONE, NONE));
            }
            for e in self.tree.edges_of(node) {
                let child = self.tree.edges[e as usize].child as usize;
                let Some(cf) = &fronts[child] else { continue };
                for (k, (p, _)) in cf.iter().enumerate() {
                    for j in 0..m {
                        point[j] = self.tree.rewards[e as usize * m + j] + p[j];
                    }
                    front.insert(&point, || (e, k as u32));
                }
            }
            fronts[node as usize] = Some(front);
        }
        let Some(root) = &fronts[0] else { return };
        for (k, (p, _)) in root.iter().enumerate() {
            if self.archive.covers(p) {
                continue;
            }
            let mut seq = Vec::with_capacity(self.n);
            let (mut node, mut at) = (0usize, k);
            loop {
                let &(e, next) = fronts[node].as_ref().expect("computed").payload(at);
                if e == NONE {
                    break;
                }
                seq.push(self.tree.edges[e as usize].action);
                node = self.tree.edges[e as usize].child as usize;
                at = next as usize;
            }
            self.archive.insert(p, || seq);
        }
    }
}

/// The hypervolume of `front` (several objectives) or its best value (one objective).
pub(super) fn front_value<P>(front: &ParetoFront<P>, reference: &[f64]) -> f64 {
    if front.dim() == 1 {
        front.iter().map(|(p, _)| p[0]).fold(f64::NEG_INFINITY, f64::max)
    } else {
        front.hypervolume(reference)
    }
}

/// Thread `t`'s share of `total` episodes (or transitions) over `threads` threads.
pub(super) fn share_of(total: usize, threads: usize, t: usize) -> usize {
    total / threads + usize::from(t < total % threads)
}
