//! Exact references for small assemblies: the true Pareto front (and the true optimum for one
//! objective) by dynamic programming over disassembly states, and plain enumeration of every
//! feasible sequence. They are the yardstick for the tests and benchmarks of the searches.
//!
//! The dynamic programme works on states `(present parts, objective memories)`: the rewards of
//! the remaining removals depend only on that state (the memories carry the history the
//! direction-change objective needs), and adding the same vector to every point keeps dominance,
//! so the front of a state is the non-dominated union over its feasible removals `a` of
//! `r(s, a) + front(s \ a)`. States are told apart by their memories' key words
//! ([`crate::Objective::key_words`]), as in the search; the programme is exact when the key
//! holds everything the rewards depend on (true of the built-in objectives). Steps are
//! [`StepKind::Replay`] steps.

use crate::error::{Result, SearchError};
use crate::hypervolume::ParetoFront;
use crate::mdp::Mdp;
use crate::step::StepKind;
use asp_geom::distmap::MapState;
use asp_geom::PartSet;
use std::collections::HashMap;

/// A complete feasible disassembly sequence and its objective vector.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactSolution {
    /// Objective totals.
    pub values: Vec<f64>,
    /// Part indices in removal order.
    pub sequence: Vec<usize>,
}

/// The exact answer for a problem.
#[derive(Clone, Debug)]
pub struct ExactFront {
    /// The Pareto front, one sequence per distinct vector, sorted like
    /// [`crate::hypervolume::ParetoFront::sorted`] (for one objective: the optimum).
    pub solutions: Vec<ExactSolution>,
    /// The worst total of each objective over all complete feasible sequences (the nadir of
    /// the whole set, a tight hypervolume reference point). Empty when there is no sequence.
    pub worst: Vec<f64>,
    /// Number of distinct states the programme visited.
    pub states: usize,
}

impl ExactFront {
    /// The hypervolume of the exact front relative to `reference`.
    pub fn hypervolume(&self, reference: &[f64]) -> f64 {
        let mut f: ParetoFront<()> = ParetoFront::new(reference.len());
        for s in &self.solutions {
            f.insert(&s.values, || ());
        }
        f.hypervolume(reference)
    }
}

/// Present parts and the memories' key words.
type Key = (PartSet, Vec<u64>);

struct Entry {
    /// suffix vectors with (action, child entry, child point)
    front: ParetoFront<(usize, usize, usize)>,
    worst: Vec<f64>,
}

struct Dp<'p> {
    problem: &'p Mdp,
    memo: HashMap<Key, usize>,
    entries: Vec<Entry>,
    max_states: usize,
    /// Map states to reuse (one per level of the recursion in use).
    spare: Vec<MapState<'p>>,
}

impl<'p> Dp<'p> {
    fn solve(&mut self, present: &PartSet, memory: &[u64]) -> Result<usize> {
        let key = (present.clone(), self.problem.key_of(memory));
        if let Some(&e) = self.memo.get(&key) {
            return Ok(e);
        }
        if self.entries.len() >= self.max_states {
            return Err(SearchError::TooLarge { reason: format!("more than {} states", self.max_states) });
        }
        let m = self.problem.num_objectives();
        let problem = self.problem;
        let mut sim = self.spare.pop().unwrap_or_else(|| MapState::new(problem.maps()));
        sim.reset(present);
        let mut front: ParetoFront<(usize, usize, usize)> = ParetoFront::new(m);
        let mut worst = vec![f64::INFINITY; m];
        if sim.is_complete() {
            front.insert(&vec![0.0; m], || (usize::MAX, usize::MAX, usize::MAX));
            worst.iter_mut().for_each(|w| *w = 0.0);
        } else {
            let mut actions = Vec::new();
            let mut counts = problem.filter_counts();
            problem.feasible_actions(&mut sim, memory, StepKind::Replay, &mut actions, &mut counts);
            for a in actions {
                let mut mem = memory.to_vec();
                let mut rewards = vec![0.0; m];
                problem.rewards(&mut sim, &mut mem, a, StepKind::Replay, &mut rewards);
                let child = self.solve(&present.without(a), &mem)?;
                let c = &self.entries[child];
                let mut cand = vec![0.0; m];
                let points: Vec<(usize, Vec<f64>)> = c.front.iter().enumerate().map(|(i, (p, _))| (i, p.to_vec())).collect();
                for k in 0..m {
                    if c.worst[k].is_finite() {
                        worst[k] = worst[k].min(rewards[k] + c.worst[k]);
                    }
                }
                for (i, p) in points {
                    for k in 0..m {
                        cand[k] = rewards[k] + p[k];
                    }
                    front.insert(&cand, || (a, child, i));
                }
            }
        }
        self.spare.push(sim);
        let id = self.entries.len();
        self.entries.push(Entry { front, worst });
        self.memo.insert(key, id);
        Ok(id)
    }

    fn sequence(&self, mut entry: usize, mut point: usize) -> Vec<usize> {
        let mut seq = Vec::new();
        loop {
            let &(a, child, p) = self.entries[entry].front.payload(point);
            if a == usize::MAX {
                return seq;
            }
            seq.push(a);
            entry = child;
            point = p;
        }
    }
}

/// The exact Pareto front of `problem` (for one objective: the optimum) by dynamic programming,
/// visiting at most `max_states` states.
pub fn exact_front(problem: &Mdp, max_states: usize) -> Result<ExactFront> {
    let maps = problem.maps();
    let mut dp = Dp { problem, memo: HashMap::new(), entries: Vec::new(), max_states, spare: Vec::new() };
    let root = dp.solve(&PartSet::full(maps.num_parts()), &problem.initial_memory())?;
    let e = &dp.entries[root];
    let mut solutions: Vec<ExactSolution> =
        e.front.iter().enumerate().map(|(i, (p, _))| ExactSolution { values: p.to_vec(), sequence: dp.sequence(root, i) }).collect();
    solutions.sort_by(|a, b| {
        for (x, y) in a.values.iter().zip(&b.values) {
            match y.total_cmp(x) {
                std::cmp::Ordering::Equal => continue,
                o => return o,
            }
        }
        std::cmp::Ordering::Equal
    });
    let worst = if solutions.is_empty() { Vec::new() } else { e.worst.clone() };
    Ok(ExactFront { solutions, worst, states: dp.entries.len() })
}

/// Every complete feasible disassembly sequence with its objective vector (depth-first, in
/// increasing part order), at most `limit` of them.
pub fn enumerate_sequences(problem: &Mdp, limit: usize) -> Result<Vec<ExactSolution>> {
    let maps = problem.maps();
    let m = problem.num_objectives();
    let mut out = Vec::new();
    let mut seq = Vec::new();
    let mut totals = vec![0.0; m];
    enumerate(problem, &PartSet::full(maps.num_parts()), &problem.initial_memory(), &mut seq, &mut totals, &mut out, limit)?;
    Ok(out)
}

fn enumerate(
    problem: &Mdp,
    present: &PartSet,
    memory: &[u64],
    seq: &mut Vec<usize>,
    totals: &mut [f64],
    out: &mut Vec<ExactSolution>,
    limit: usize,
) -> Result<()> {
    let mut sim = MapState::new(problem.maps());
    sim.reset(present);
    if sim.is_complete() {
        if out.len() >= limit {
            return Err(SearchError::TooLarge { reason: format!("more than {limit} sequences") });
        }
        out.push(ExactSolution { values: totals.to_vec(), sequence: seq.clone() });
        return Ok(());
    }
    let mut actions = Vec::new();
    let mut counts = problem.filter_counts();
    problem.feasible_actions(&mut sim, memory, StepKind::Replay, &mut actions, &mut counts);
    for a in actions {
        let mut mem = memory.to_vec();
        let mut rewards = vec![0.0; problem.num_objectives()];
        problem.rewards(&mut sim, &mut mem, a, StepKind::Replay, &mut rewards);
        for (t, r) in totals.iter_mut().zip(&rewards) {
            *t += r;
        }
        seq.push(a);
        enumerate(problem, &present.without(a), &mem, seq, totals, out, limit)?;
        seq.pop();
        for (t, r) in totals.iter_mut().zip(&rewards) {
            *t -= r;
        }
    }
    Ok(())
}
