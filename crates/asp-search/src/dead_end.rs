//! Why an optimiser found no plan: the deepest dead end of a problem's removal tree on the
//! distance maps, and what holds each part there, in the depth-first planner's vocabulary
//! ([`Stuck`]), so an optimiser's `no_plan` is explained like the feasibility search's.

use crate::mdp::Mdp;
use crate::problem::{Stuck, StuckReason};
use crate::step::StepKind;
use asp_geom::distmap::MapState;
use asp_geom::{Motion, PartSet, Stability};
use std::collections::HashSet;

/// States the dead-end search of a tree search's `NoPlan` visits at most (a tree the search
/// exhausted is far smaller).
pub const DEAD_END_STATES: usize = 200_000;

/// The deepest dead end found: the removals that reach it (disassembly order, with their
/// motions), the parts present there and why each non-fixed one cannot leave.
#[derive(Clone, Debug, PartialEq)]
pub struct DeadEnd {
    /// The removals from the assembled state to the dead end.
    pub removals: Vec<(usize, Motion)>,
    /// The parts present at the dead end (fixed parts included; no floor).
    pub state: PartSet,
    /// Each present non-fixed part the maps hold (blocked, or needed for support) and why.
    pub stuck: Vec<Stuck>,
    /// The parts the maps let out but a feasibility filter of the problem (the robot, say)
    /// rejected, each with the filter's words ("is rejected by robot: ...").
    pub rejected: Vec<(usize, String)>,
    /// Whether every state was visited (else the deepest of `max_states` visited states).
    pub complete: bool,
}

/// Searches the removal tree of `problem` depth-first (each set of present parts once, at most
/// `max_states` of them) for the state with the fewest parts left from which no part can leave,
/// and explains it on the maps: a part that collides in every direction is
/// [`StuckReason::Blocked`] by the present parts (the floor, index `n`, included) that block
/// it in some direction; one whose removal would leave others floating is
/// [`StuckReason::WouldLeaveUnsupported`] by those. `None` when a complete sequence exists
/// among the visited states (there is no dead end to explain) or the assembled state has no
/// non-fixed part.
pub fn deepest_dead_end(problem: &Mdp, max_states: usize) -> Option<DeadEnd> {
    let maps = problem.maps();
    let n = maps.num_parts();
    let full = PartSet::full(n);
    let mut visited: HashSet<PartSet> = HashSet::new();
    // (present, memory, removals so far)
    let mut stack = vec![(full, problem.initial_memory(), Vec::<usize>::new())];
    let mut best: Option<(PartSet, Vec<u64>, Vec<usize>)> = None;
    let mut rewards = vec![0.0; problem.num_objectives()];
    let mut state = MapState::new(maps);
    let mut complete = true;
    while let Some((present, memory, path)) = stack.pop() {
        if !visited.insert(present.clone()) {
            continue;
        }
        if visited.len() > max_states {
            complete = false;
            break;
        }
        let actions = problem.feasible_in(&present, &memory);
        state.reset(&present);
        if state.is_complete() {
            return None;
        }
        if actions.is_empty() {
            if best.as_ref().is_none_or(|(_, _, b)| path.len() > b.len()) {
                best = Some((present, memory, path));
            }
            continue;
        }
        // pushed in reverse so the lowest part is taken first
        for &a in actions.iter().rev() {
            state.reset(&present);
            let mut next_memory = memory.clone();
            problem.step(&mut state, &mut next_memory, a, StepKind::Replay, &mut rewards);
            let mut next = present.clone();
            next.remove(a);
            let mut next_path = path.clone();
            next_path.push(a);
            stack.push((next, next_memory, next_path));
        }
    }
    let (present, memory, path) = best?;
    // the motions of the removals, as an answer's are replayed (every step was feasible)
    let (_, motions) = problem.replay(&path).expect("the dead-end search took feasible removals only");
    let removals: Vec<(usize, Motion)> = path.iter().copied().zip(motions).collect();
    let mut state = MapState::new(maps);
    state.reset(&present);
    let mut stuck = Vec::new();
    let mut rejected = Vec::new();
    for i in present.iter().filter(|&i| !maps.is_fixed(i)) {
        let reason = if !state.is_collision_free(i) {
            let mut by = PartSet::empty(n + 1);
            for j in present.iter().chain([n]).filter(|&j| j != i) {
                if !maps.blocked(i, j).is_empty() {
                    by.insert(j);
                }
            }
            StuckReason::Blocked(by)
        } else if !state.removal_keeps_stable(i) {
            let mut rest = present.clone();
            rest.remove(i);
            match maps.stability(&rest) {
                Stability::Unstable { floating } => StuckReason::WouldLeaveUnsupported(floating),
                Stability::Stable => StuckReason::WouldLeaveUnsupported(PartSet::empty(n)),
            }
        } else {
            // no part of a dead end can leave: the maps let this one out, so a filter did not
            let why = problem.why_infeasible(&mut state, &memory, i, StepKind::Replay);
            rejected.push((i, why.unwrap_or_else(|| "cannot leave".into())));
            continue;
        };
        stuck.push(Stuck { part: i, reason });
    }
    Some(DeadEnd { removals, state: present, stuck, rejected, complete })
}
