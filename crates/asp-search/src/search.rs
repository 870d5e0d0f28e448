//! The machinery shared by [`crate::Mcts`] and [`crate::ParetoMcts`]: settings and their
//! validating builder, the search tree, episodes with a search budget per step (thesis 5.4.2),
//! root-parallel threads, and the outcome with its trace.
//!
//! # Episodes and steps
//! An *episode* walks from the root to a complete disassembly. At each *search step* it runs
//! `budget` *iterations* from the current node — selection by the tree policy, expansion of one
//! untried removal (chosen at random), a rollout with the default policy until no part can be
//! removed, and backpropagation to the root — and then moves to the child the tree policy
//! picks. The next episode starts again at the root.
//!
//! # Solved and dead subtrees
//! A node whose removals have all been expanded and whose children are all finished is
//! *solved* (its subtree has been enumerated) or *dead* (no complete sequence under it).
//! Selection skips finished children; when the root is finished the search stops early: its
//! answer is then exact.
//!
//! # Threads
//! Root parallelism: each thread grows its own tree with its own random stream
//! (`seed`, thread index) and its share of the episodes; the answers are merged in thread order.
//! The output depends only on the seed, the settings and the thread count (not on timing)
//! unless a time limit stops the search. `threads = 1` runs on the calling thread.

use crate::error::{Result, SearchError};
use crate::hypervolume::ParetoFront;
use crate::objective::Memory;
use crate::policy::{rng_for, Policy, PolicyContext, RandomPolicy, SearchRng};
use crate::mdp::{Mdp, MAX_OBJECTIVES};
use asp_geom::distmap::MapState;
use asp_geom::{Motion, PartSet};
use rand::RngExt;
use std::marker::PhantomData;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Default iterations per search step (the thesis' search budget of 5, 5.5 and 6.5).
pub const DEFAULT_BUDGET: usize = 5;
/// Default number of episodes (the thesis ran for a fixed time instead).
pub const DEFAULT_EPISODES: usize = 1000;
/// Default exploration constant `c` of UCT / MOUCB (the thesis does not state it): `1/√2`,
/// Kocsis and Szepesvári's choice for rewards in `[0, 1]`.
pub const DEFAULT_EXPLORATION: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Default cap on tree nodes per thread; beyond it iterations roll out without expanding.
pub const DEFAULT_MAX_NODES: usize = 1_000_000;

/// Settings of a tree search. Build with [`crate::Mcts::builder`] or
/// [`crate::ParetoMcts::builder`].
#[derive(Clone, Debug)]
pub struct SearchSettings {
    pub(crate) budget: usize,
    pub(crate) episodes: usize,
    pub(crate) threads: usize,
    pub(crate) seed: u64,
    pub(crate) exploration: f64,
    pub(crate) max_nodes: usize,
    pub(crate) time_limit: Option<Duration>,
    pub(crate) policy: Arc<dyn Policy>,
    pub(crate) reference: Option<Vec<f64>>,
}

impl Default for SearchSettings {
    fn default() -> Self {
        SearchSettings {
            budget: DEFAULT_BUDGET,
            episodes: DEFAULT_EPISODES,
            threads: 1,
            seed: 0,
            exploration: DEFAULT_EXPLORATION,
            max_nodes: DEFAULT_MAX_NODES,
            time_limit: None,
            policy: Arc::new(RandomPolicy),
            reference: None,
        }
    }
}

impl SearchSettings {
    /// Iterations per search step.
    pub fn budget(&self) -> usize {
        self.budget
    }
    /// Episodes (over all threads).
    pub fn episodes(&self) -> usize {
        self.episodes
    }
    /// Threads (root parallel).
    pub fn threads(&self) -> usize {
        self.threads
    }
    /// Seed of every random choice.
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// Exploration constant `c`.
    pub fn exploration(&self) -> f64 {
        self.exploration
    }
    /// Cap on tree nodes per thread.
    pub fn max_nodes(&self) -> usize {
        self.max_nodes
    }
    /// Wall-clock limit, if any.
    pub fn time_limit(&self) -> Option<Duration> {
        self.time_limit
    }
}

/// A validating builder of a search (`K` is [`crate::Mcts`] or [`crate::ParetoMcts`]).
#[derive(Clone, Debug)]
pub struct SearchBuilder<K> {
    settings: SearchSettings,
    kind: PhantomData<fn() -> K>,
}

impl<K: From<SearchSettings>> Default for SearchBuilder<K> {
    fn default() -> Self {
        SearchBuilder { settings: SearchSettings::default(), kind: PhantomData }
    }
}

impl<K: From<SearchSettings>> SearchBuilder<K> {
    /// Iterations per search step (default 5, ≥ 1).
    pub fn budget(mut self, budget: usize) -> Self {
        self.settings.budget = budget;
        self
    }

    /// Episodes over all threads (default 1000, ≥ 1).
    pub fn episodes(mut self, episodes: usize) -> Self {
        self.settings.episodes = episodes;
        self
    }

    /// Threads, each growing its own tree (default 1; 1..=256).
    pub fn threads(mut self, threads: usize) -> Self {
        self.settings.threads = threads;
        self
    }

    /// Seed of every random choice (default 0).
    pub fn seed(mut self, seed: u64) -> Self {
        self.settings.seed = seed;
        self
    }

    /// Exploration constant `c` (default 1/√2, finite and ≥ 0).
    pub fn exploration(mut self, c: f64) -> Self {
        self.settings.exploration = c;
        self
    }

    /// Cap on tree nodes per thread (default 1,000,000, ≥ 1).
    pub fn max_nodes(mut self, max_nodes: usize) -> Self {
        self.settings.max_nodes = max_nodes;
        self
    }

    /// Stops after this wall-clock time even if episodes remain (breaks reproducibility).
    pub fn time_limit(mut self, limit: Duration) -> Self {
        self.settings.time_limit = Some(limit);
        self
    }

    /// The rollout policy (default [`RandomPolicy`]).
    pub fn policy(mut self, policy: Arc<dyn Policy>) -> Self {
        self.settings.policy = policy;
        self
    }

    /// The hypervolume reference point (default: every objective's worst possible total).
    pub fn reference(mut self, reference: Vec<f64>) -> Self {
        self.settings.reference = Some(reference);
        self
    }

    /// Checks the settings.
    pub fn build(self) -> Result<K> {
        let s = &self.settings;
        if s.budget == 0 {
            return Err(SearchError::config("the search budget must be at least 1"));
        }
        if s.episodes == 0 {
            return Err(SearchError::config("episodes must be at least 1"));
        }
        if s.threads == 0 || s.threads > 256 {
            return Err(SearchError::config(format!("threads must be in 1..=256, got {}", s.threads)));
        }
        if !(s.exploration.is_finite() && s.exploration >= 0.0) {
            return Err(SearchError::config(format!(
                "the exploration constant must be finite and >= 0, got {}",
                s.exploration
            )));
        }
        if s.max_nodes == 0 {
            return Err(SearchError::config("max_nodes must be at least 1"));
        }
        if s.time_limit.is_some_and(|t| t.is_zero()) {
            return Err(SearchError::config("the time limit must be positive"));
        }
        if let Some(r) = &s.reference {
            if r.iter().any(|v| !v.is_finite()) {
                return Err(SearchError::config("the reference point must be finite"));
            }
        }
        Ok(K::from(self.settings))
    }
}

/// How a search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchStatus {
    /// At least one complete feasible sequence was found.
    Found,
    /// The whole tree was explored: no complete feasible sequence exists.
    NoPlan,
    /// The budget ran out before any complete sequence was found.
    BudgetExhausted,
}

/// One answer: a complete feasible disassembly sequence, its objective vector and its motions.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Objective totals, in the problem's objective order.
    pub values: Vec<f64>,
    /// Part indices in removal order.
    pub sequence: Vec<usize>,
    /// The removal motion of each step (straight lines).
    pub motions: Vec<Motion>,
}

/// One row of the trace: the answer's quality after some episodes and seconds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TracePoint {
    /// Episodes finished (all threads).
    pub episode: u64,
    /// Iterations run (all threads).
    pub iterations: u64,
    /// Seconds since the search started.
    pub seconds: f64,
    /// The hypervolume of the merged root fronts (Pareto) or the best total (single objective).
    pub value: f64,
    /// Number of points on the merged front (1 for single objective).
    pub front_size: usize,
}

/// What the search did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SearchStats {
    /// Episodes finished.
    pub episodes: u64,
    /// Iterations (selection, expansion, rollout, backpropagation).
    pub iterations: u64,
    /// Removals simulated in rollouts.
    pub rollout_steps: u64,
    /// Rollouts that ended with parts left that could not be removed.
    pub dead_rollouts: u64,
    /// Tree nodes (all threads).
    pub tree_nodes: u64,
    /// Wall-clock seconds of the search.
    pub seconds: f64,
    /// Whether the tree was fully explored (the answer is then exact).
    pub exhausted: bool,
    /// Threads used.
    pub threads: usize,
}

/// The result of a search.
#[derive(Clone, Debug)]
pub struct SearchOutcome {
    /// How the search ended.
    pub status: SearchStatus,
    /// The objectives' names.
    pub objectives: Vec<String>,
    /// The answers: the best sequence (single objective) or the Pareto front, sorted by the first
    /// objective (best first).
    pub solutions: Vec<Solution>,
    /// The hypervolume reference point.
    pub reference: Vec<f64>,
    /// Hypervolume of the front relative to `reference` (single objective: the best total).
    pub value: f64,
    /// Effort.
    pub stats: SearchStats,
    /// Quality over episodes and seconds (a row whenever it changed, and a last row).
    pub trace: Vec<TracePoint>,
}

impl SearchOutcome {
    /// The first solution (the best one for a single objective).
    pub fn best(&self) -> Option<&Solution> {
        self.solutions.first()
    }

    /// Writes the trace as CSV: `episode,iterations,seconds,value,front_size`.
    pub fn write_trace_csv(&self, mut w: impl std::io::Write) -> std::io::Result<()> {
        writeln!(w, "episode,iterations,seconds,value,front_size")?;
        for t in &self.trace {
            writeln!(w, "{},{},{:.6},{},{}", t.episode, t.iterations, t.seconds, t.value, t.front_size)?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// The tree

pub(crate) const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Status {
    Open,
    Solved,
    Dead,
}

#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub parent: u32,
    pub first_child: u32,
    pub next_sibling: u32,
    pub visits: u32,
    pub action: u16,
    pub status: Status,
    pub present: PartSet,
    /// Parts known to be collision-free here (they stay so in every descendant).
    pub free: PartSet,
    pub untried: PartSet,
}

/// The search tree: nodes, their values, the returns accumulated on the way to them and the
/// objectives' memories there.
pub(crate) struct Tree<V> {
    pub nodes: Vec<Node>,
    pub values: Vec<V>,
    prefix: Vec<f64>,
    memory: Vec<Memory>,
    m: usize,
}

impl<V: Default> Tree<V> {
    fn prefix(&self, n: u32) -> &[f64] {
        &self.prefix[n as usize * self.m..(n as usize + 1) * self.m]
    }

    fn memory(&self, n: u32) -> &[Memory] {
        &self.memory[n as usize * self.m..(n as usize + 1) * self.m]
    }

    pub fn children(&self, n: u32) -> ChildIter<'_, V> {
        ChildIter { tree: self, next: self.nodes[n as usize].first_child }
    }
}

pub(crate) struct ChildIter<'a, V> {
    tree: &'a Tree<V>,
    next: u32,
}

impl<V> Iterator for ChildIter<'_, V> {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        (self.next != NONE).then(|| {
            let c = self.next;
            self.next = self.tree.nodes[c as usize].next_sibling;
            c
        })
    }
}

/// Global bounds of the returns seen so far (per objective).
#[derive(Clone, Debug)]
pub(crate) struct Bounds {
    pub lo: [f64; MAX_OBJECTIVES],
    pub hi: [f64; MAX_OBJECTIVES],
    pub version: u64,
}

impl Bounds {
    fn new() -> Self {
        Bounds { lo: [f64::INFINITY; MAX_OBJECTIVES], hi: [f64::NEG_INFINITY; MAX_OBJECTIVES], version: 0 }
    }

    fn update(&mut self, ret: &[f64]) {
        let mut changed = false;
        for (k, &v) in ret.iter().enumerate() {
            if v < self.lo[k] {
                self.lo[k] = v;
                changed = true;
            }
            if v > self.hi[k] {
                self.hi[k] = v;
                changed = true;
            }
        }
        if changed {
            self.version += 1;
        }
    }

    /// `v` mapped to `[0, 1]` by the bounds of objective `k` (1 when the range is empty).
    #[inline]
    pub fn normalise(&self, k: usize, v: f64) -> f64 {
        let range = self.hi[k] - self.lo[k];
        if range > 0.0 {
            (v - self.lo[k]) / range
        } else {
            1.0
        }
    }
}

/// What the tree policy needs besides the tree.
pub(crate) struct SelectContext<'a> {
    pub exploration: f64,
    pub bounds: &'a Bounds,
    pub m: usize,
}

/// The variant-specific parts: the node value, its backup and the tree policy.
pub(crate) trait Variant: Send + Sync {
    /// What a node keeps of the returns through it.
    type Value: Default + Send;
    /// Records the return `ret` of a complete sequence through the node; false when
    /// backpropagation of values should stop here (the rest of the path only counts a visit).
    fn record(value: &mut Self::Value, ret: &[f64]) -> bool;
    /// The position in `candidates` (children of `parent`, not empty) the tree policy picks.
    fn select(tree: &mut Tree<Self::Value>, parent: u32, candidates: &[u32], ctx: &SelectContext<'_>)
        -> usize;
}

/// `c · sqrt(2 ln N(parent) / N(child))`.
#[inline]
pub(crate) fn exploration_term(c: f64, parent_visits: u32, child_visits: u32) -> f64 {
    let n = (parent_visits.max(1)) as f64;
    c * (2.0 * n.ln() / child_visits.max(1) as f64).sqrt()
}

struct Shared {
    front: ParetoFront<()>,
    episodes: u64,
    iterations: u64,
    trace: Vec<TracePoint>,
    last_value: Option<f64>,
}

struct Worker<'p, V: Variant> {
    problem: &'p Mdp,
    settings: &'p SearchSettings,
    m: usize,
    n: usize,
    tree: Tree<V::Value>,
    rng: SearchRng,
    sim: MapState<'p>,
    actions: Vec<usize>,
    candidates: Vec<u32>,
    sequence: Vec<u16>,
    bounds: Bounds,
    archive: ParetoFront<Vec<u16>>,
    archive_changed: bool,
    stats: SearchStats,
    deadline: Option<Instant>,
    stopped: bool,
}

impl<'p, V: Variant> Worker<'p, V> {
    fn new(problem: &'p Mdp, settings: &'p SearchSettings, thread: usize, start: Instant) -> Self {
        let m = problem.num_objectives();
        let maps = problem.maps();
        let n = maps.num_parts();
        let mut sim = MapState::new(maps);
        let mut actions = Vec::with_capacity(n);
        sim.feasible_actions(&mut actions);
        let full = PartSet::full(n);
        let complete = sim.is_complete();
        let root = Node {
            parent: NONE,
            first_child: NONE,
            next_sibling: NONE,
            visits: 0,
            action: u16::MAX,
            status: if complete {
                Status::Solved
            } else if actions.is_empty() {
                Status::Dead
            } else {
                Status::Open
            },
            present: full,
            free: sim.collision_free(),
            untried: PartSet::from_indices(n, actions.iter().copied()),
        };
        let tree = Tree {
            nodes: vec![root],
            values: vec![V::Value::default()],
            prefix: vec![0.0; m],
            memory: vec![Memory::default(); m],
            m,
        };
        Worker {
            problem,
            settings,
            m,
            n,
            tree,
            rng: rng_for(settings.seed, thread as u64),
            sim,
            actions,
            candidates: Vec::with_capacity(n),
            sequence: Vec::with_capacity(n),
            bounds: Bounds::new(),
            archive: ParetoFront::new(m),
            archive_changed: false,
            stats: SearchStats::default(),
            deadline: settings.time_limit.map(|t| start + t),
            stopped: false,
        }
    }

    fn root_finished(&self) -> bool {
        self.tree.nodes[0].status != Status::Open
    }

    /// One episode: search steps from the root down to a complete sequence.
    fn episode(&mut self) {
        let mut current = 0u32;
        loop {
            let node = &self.tree.nodes[current as usize];
            if node.status == Status::Dead
                || (node.status == Status::Solved && node.first_child == NONE)
            {
                break;
            }
            for _ in 0..self.settings.budget {
                if self.tree.nodes[current as usize].status != Status::Open {
                    break;
                }
                self.iterate(current);
                self.stats.iterations += 1;
                if self.deadline.is_some_and(|d| Instant::now() >= d) {
                    self.stopped = true;
                    return;
                }
            }
            match self.commit(current) {
                Some(c) => current = c,
                None => break,
            }
        }
    }

    /// The child the tree policy moves to at the end of a search step (any unfinished or
    /// solved child).
    fn commit(&mut self, node: u32) -> Option<u32> {
        self.candidates.clear();
        let mut c = self.tree.nodes[node as usize].first_child;
        while c != NONE {
            if self.tree.nodes[c as usize].status != Status::Dead {
                self.candidates.push(c);
            }
            c = self.tree.nodes[c as usize].next_sibling;
        }
        if self.candidates.is_empty() {
            return None;
        }
        let ctx = SelectContext { exploration: self.settings.exploration, bounds: &self.bounds, m: self.m };
        let k = V::select(&mut self.tree, node, &self.candidates, &ctx);
        Some(self.candidates[k])
    }

    /// Selection, expansion, rollout and backpropagation from `start`.
    fn iterate(&mut self, start: u32) {
        let m = self.m;
        // Selection: descend through fully expanded nodes.
        let mut node = start;
        loop {
            let nd = &self.tree.nodes[node as usize];
            if nd.status != Status::Open {
                return;
            }
            if !nd.untried.is_empty() {
                break;
            }
            self.candidates.clear();
            let mut c = nd.first_child;
            while c != NONE {
                if self.tree.nodes[c as usize].status == Status::Open {
                    self.candidates.push(c);
                }
                c = self.tree.nodes[c as usize].next_sibling;
            }
            if self.candidates.is_empty() {
                self.refresh_status(node);
                return;
            }
            let ctx = SelectContext { exploration: self.settings.exploration, bounds: &self.bounds, m };
            let k = V::select(&mut self.tree, node, &self.candidates, &ctx);
            node = self.candidates[k];
        }

        // Expansion: a random untried removal.
        let parent = node;
        let pn = &self.tree.nodes[parent as usize];
        self.sim.reset_with_free(&pn.present, &pn.free);
        let mut memories = [Memory::default(); MAX_OBJECTIVES];
        memories[..m].copy_from_slice(self.tree.memory(parent));
        let mut ret = [0.0f64; MAX_OBJECTIVES];
        ret[..m].copy_from_slice(self.tree.prefix(parent));
        let untried = &self.tree.nodes[parent as usize].untried;
        let pick = self.rng.random_range(0..untried.len());
        let action = untried.iter().nth(pick).expect("pick < len");
        let mut rewards = [0.0f64; MAX_OBJECTIVES];
        self.problem.step(&mut self.sim, &mut memories[..m], action, &mut rewards[..m]);
        for k in 0..m {
            ret[k] += rewards[k];
        }
        let expanded = self.tree.nodes.len() < self.settings.max_nodes;
        let leaf = if expanded {
            self.tree.nodes[parent as usize].untried.remove(action);
            self.sim.feasible_actions(&mut self.actions);
            let status = if self.sim.is_complete() {
                Status::Solved
            } else if self.actions.is_empty() {
                Status::Dead
            } else {
                Status::Open
            };
            let id = self.tree.nodes.len() as u32;
            let first = self.tree.nodes[parent as usize].first_child;
            self.tree.nodes.push(Node {
                parent,
                first_child: NONE,
                next_sibling: first,
                visits: 0,
                action: action as u16,
                status,
                present: self.sim.present(),
                free: self.sim.collision_free(),
                untried: PartSet::from_indices(self.n, self.actions.iter().copied()),
            });
            self.tree.nodes[parent as usize].first_child = id;
            self.tree.values.push(V::Value::default());
            self.tree.prefix.extend_from_slice(&ret[..m]);
            self.tree.memory.extend_from_slice(&memories[..m]);
            id
        } else {
            parent
        };

        // The sequence so far: the tree path to the leaf (and the unexpanded action).
        self.sequence.clear();
        let mut a = leaf;
        while a != 0 {
            self.sequence.push(self.tree.nodes[a as usize].action);
            a = self.tree.nodes[a as usize].parent;
        }
        self.sequence.reverse();
        if !expanded {
            self.sequence.push(action as u16);
        }

        // Rollout with the default policy.
        let policy = &*self.settings.policy;
        loop {
            self.sim.feasible_actions(&mut self.actions);
            if self.actions.is_empty() {
                break;
            }
            let k = {
                let mut ctx = PolicyContext {
                    state: &mut self.sim,
                    memories: &memories[..m],
                    problem: self.problem,
                };
                policy.choose(&mut ctx, &self.actions, &mut self.rng)
            };
            let p = self.actions[k];
            self.problem.step(&mut self.sim, &mut memories[..m], p, &mut rewards[..m]);
            for k in 0..m {
                ret[k] += rewards[k];
            }
            self.sequence.push(p as u16);
            self.stats.rollout_steps += 1;
        }
        let complete = self.sim.is_complete();
        if complete {
            self.bounds.update(&ret[..m]);
        } else {
            self.stats.dead_rollouts += 1;
        }

        // Backpropagation: visits along the whole path, values until a node rejects them.
        let mut propagate = complete;
        let mut b = leaf;
        loop {
            let i = b as usize;
            self.tree.nodes[i].visits += 1;
            if propagate {
                propagate = V::record(&mut self.tree.values[i], &ret[..m]);
            }
            if b == 0 {
                break;
            }
            b = self.tree.nodes[i].parent;
        }
        if propagate {
            let seq = &self.sequence;
            if self.archive.insert(&ret[..m], || seq.clone()) {
                self.archive_changed = true;
            }
        }
        if expanded && self.tree.nodes[leaf as usize].status != Status::Open {
            self.refresh_status(parent);
        }
    }

    /// Recomputes the status of `node` from its children, and of its ancestors while it changes.
    fn refresh_status(&mut self, mut node: u32) {
        loop {
            let nd = &self.tree.nodes[node as usize];
            if !nd.untried.is_empty() {
                return;
            }
            let (mut open, mut solved) = (false, false);
            for c in self.tree.children(node) {
                match self.tree.nodes[c as usize].status {
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
            if node == 0 {
                return;
            }
            node = self.tree.nodes[node as usize].parent;
        }
    }

    /// Publishes the archive to the shared front and the trace.
    fn sync(&mut self, shared: &Mutex<Shared>, reference: &[f64], start: Instant, iterations: u64) {
        let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
        s.episodes += 1;
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

    /// Runs `episodes` episodes (or until the time limit or the root is finished).
    fn run(&mut self, episodes: usize, shared: &Mutex<Shared>, reference: &[f64], start: Instant) {
        for _ in 0..episodes {
            if self.stopped || self.root_finished() {
                break;
            }
            let before = self.stats.iterations;
            self.episode();
            if !self.stopped {
                self.stats.episodes += 1;
            }
            self.sync(shared, reference, start, self.stats.iterations - before);
        }
        self.stats.tree_nodes = self.tree.nodes.len() as u64;
        self.stats.exhausted = self.root_finished();
    }
}

/// The hypervolume of `front` (several objectives) or its best value (one objective).
fn front_value<P>(front: &ParetoFront<P>, reference: &[f64]) -> f64 {
    if front.dim() == 1 {
        front.iter().map(|(p, _)| p[0]).fold(f64::NEG_INFINITY, f64::max)
    } else {
        front.hypervolume(reference)
    }
}

/// Runs the search of variant `V` on `problem`.
pub(crate) fn run<V: Variant>(problem: &Mdp, settings: &SearchSettings) -> Result<SearchOutcome> {
    let m = problem.num_objectives();
    let reference = match &settings.reference {
        Some(r) if r.len() != m => {
            return Err(SearchError::config(format!(
                "the reference point has {} coordinates, the problem {m} objectives",
                r.len()
            )))
        }
        Some(r) => r.clone(),
        None => problem.reference_point(),
    };
    if problem.maps().num_parts() > u16::MAX as usize {
        return Err(SearchError::config("too many parts"));
    }
    let start = Instant::now();
    let shared = Mutex::new(Shared {
        front: ParetoFront::new(m),
        episodes: 0,
        iterations: 0,
        trace: Vec::new(),
        last_value: None,
    });
    let threads = settings.threads;
    let share = |t: usize| settings.episodes / threads + usize::from(t < settings.episodes % threads);
    let results: Vec<(ParetoFront<Vec<u16>>, SearchStats, Status)> = if threads == 1 {
        let mut w = Worker::<V>::new(problem, settings, 0, start);
        w.run(share(0), &shared, &reference, start);
        vec![(w.archive, w.stats, w.tree.nodes[0].status)]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    let shared = &shared;
                    let reference = &reference;
                    scope.spawn(move || {
                        let mut w = Worker::<V>::new(problem, settings, t, start);
                        w.run(share(t), shared, reference, start);
                        (w.archive, w.stats, w.tree.nodes[0].status)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().expect("search threads do not panic")).collect()
        })
    };
    let seconds = start.elapsed().as_secs_f64();

    // Merge in thread order (deterministic).
    let mut merged: ParetoFront<Vec<u16>> = ParetoFront::new(m);
    let mut stats = SearchStats { threads, seconds, exhausted: false, ..Default::default() };
    let mut dead = true;
    for (archive, s, status) in &results {
        for (p, seq) in archive.iter() {
            merged.insert(p, || seq.clone());
        }
        stats.episodes += s.episodes;
        stats.iterations += s.iterations;
        stats.rollout_steps += s.rollout_steps;
        stats.dead_rollouts += s.dead_rollouts;
        stats.tree_nodes += s.tree_nodes;
        stats.exhausted |= s.exhausted;
        dead &= *status == Status::Dead;
    }
    let mut solutions = Vec::with_capacity(merged.len());
    for (_, seq) in merged.sorted() {
        let sequence: Vec<usize> = seq.iter().map(|&p| p as usize).collect();
        let (values, motions) = problem.evaluate(&sequence)?;
        solutions.push(Solution { values, sequence, motions });
    }
    let value = front_value(&merged, &reference);
    let mut shared = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    let last = TracePoint {
        episode: stats.episodes,
        iterations: stats.iterations,
        seconds,
        value: if merged.is_empty() { 0.0 } else { value },
        front_size: merged.len(),
    };
    shared.trace.push(last);
    let status = if !solutions.is_empty() {
        SearchStatus::Found
    } else if dead {
        SearchStatus::NoPlan
    } else {
        SearchStatus::BudgetExhausted
    };
    Ok(SearchOutcome {
        status,
        objectives: problem.objective_names(),
        solutions,
        reference,
        value: if merged.is_empty() { 0.0 } else { value },
        stats,
        trace: shared.trace,
    })
}
