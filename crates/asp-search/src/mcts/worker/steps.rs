//! The four steps of an iteration: [`Worker::select`] descends by the tree policy,
//! [`Worker::expand`] adds one removal, [`Worker::rollout`] finishes the episode by the policy and
//! [`Worker::backup`] carries the returns up the path.

use super::*;

impl<'p, V: Variant> Worker<'p, V> {
    /// Selection: descends through fully expanded nodes by the tree policy, from the end of the
    /// path to a node with untried removals. False when there is none below (the path's nodes'
    /// statuses are then brought up to date).
    pub(super) fn select(&mut self) -> bool {
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
    pub(super) fn expand(&mut self, policy: &mut dyn PolicyWorker, parent: u32, ret: &mut [f64; MAX_OBJECTIVES]) -> Result<Expansion> {
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
    pub(super) fn rollout(&mut self, policy: &mut dyn PolicyWorker, known: bool, ret: &mut [f64; MAX_OBJECTIVES]) -> Result<bool> {
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
            self.complete_sequence(&ret[..m], self.episode_iterations + 1);
        } else {
            self.stats.dead_rollouts += 1;
        }
        Ok(complete)
    }

    /// Backpropagation along the path: visits everywhere, the suffix values of a `complete`
    /// sequence with returns `ret` until a node adds nothing (without transpositions) or
    /// everywhere (with them).
    pub(super) fn backup(&mut self, complete: bool, ret: &[f64; MAX_OBJECTIVES]) {
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
    pub(super) fn refresh_path_status(&mut self) {
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
}
