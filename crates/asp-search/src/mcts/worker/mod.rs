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

mod run;
mod steps;

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

    /// One greedy sequence of the policy per ranking from the assembled state (when it ranks
    /// removals: [`PolicyWorker::greedy`]), each offered to the archive and, as a seed, to the
    /// local search. It leaves the tree search as it was: it draws nothing from the search's
    /// random stream and does not widen the bounds that normalise the tree's returns, so with
    /// random rollouts and expansions (`QUse::Seed`) the tree grows exactly as vanilla's of the
    /// same seed (the local search, which also searches around the seeds, may not).
    fn greedy_seeds(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        for which in 0..policy.greedy_rankings() {
            self.greedy_seed(policy, which)?;
        }
        Ok(())
    }

    /// The greedy sequence of ranking `which` (see [`greedy_seeds`](Self::greedy_seeds)).
    fn greedy_seed(&mut self, policy: &mut dyn PolicyWorker, which: usize) -> Result<()> {
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
                policy.greedy(&mut ctx, &actions, which)?
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
            self.offer_sequence(&ret[..m], 0); // not to the bounds: the tree stays vanilla's
        }
        Ok(())
    }

    /// The current `sequence`, complete with returns `ret`: the bounds take its values, the
    /// local search its start, and the archive it when no sequence dominates it (recorded as
    /// found after `iterations` of the episode).
    fn complete_sequence(&mut self, ret: &[f64], iterations: u64) {
        self.bounds.update(ret);
        self.offer_sequence(ret, iterations);
    }

    /// The current `sequence`, complete with returns `ret`, to the local search and the archive
    /// (without the bounds: [`complete_sequence`](Self::complete_sequence)).
    fn offer_sequence(&mut self, ret: &[f64], iterations: u64) {
        let seq = &self.sequence;
        if let Some(p) = &mut self.polisher {
            p.seed(ret, seq);
        }
        if self.archive.insert(ret, || seq.clone()) {
            self.archive_changed = true;
            self.found.push((ret.to_vec(), self.start.elapsed().as_secs_f64(), iterations));
        }
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
