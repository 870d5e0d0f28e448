//! A worker's run: episodes until its share or the budget is spent, the archive published to the
//! threads' shared front, the local search, and the final graph read back into sequences.

use super::*;

impl<'p, V: Variant> Worker<'p, V> {
    /// Publishes the archive to the shared front and the trace.
    pub(super) fn sync(&mut self, shared: &Mutex<Shared>, reference: &[f64], start: Instant, iterations: u64, episode: bool) {
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
            if let Err(e) = self.greedy_seeds(&mut *policy) {
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
    pub(super) fn polish(&mut self, last: bool) -> bool {
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
    pub(super) fn fail(&mut self, e: SearchError) {
        self.error = Some(e);
        self.stopped = true;
        self.finish();
    }

    /// What the episode just run did, for the stepped search's hook: its transitions (taken out
    /// of the recording, whose limit is then per episode), and the front so far.
    pub(super) fn report(&mut self, shared: &Mutex<Shared>, start: Instant, last: &mut (u64, Duration), last_call: bool) -> EpisodeEnd {
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
    pub(super) fn finish(&mut self) {
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
    pub(super) fn read_graph(&mut self) {
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
