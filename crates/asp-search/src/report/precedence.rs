//! The precedence graph of a found plan (`asp plan --precedence`, plan format 1.12): the
//! partial order of its assembly steps that keeps every step feasible with its own motion.
//!
//! Step A goes in before step B when a part of B, in place, would block A's motion (the pair
//! test of the plan's own collision world, along A's straight or screw motion; along each segment
//! of a path), or when B needs A for support. Support is conservative: each step gets edges from
//! steps placed before it in the plan, added (those it touches, lowest level first) until every
//! part of it reaches a base part through contacts among the base, the step itself and those
//! steps; a step's supporters are supported in turn, so every state of every order the graph
//! allows stands under the contact criterion, though some orders it forbids would stand too.
//! Under `--stability physics` every earlier step it touches is a supporter (and the contact
//! criterion is still all the graph ensures; the JSON says so).
//!
//! A screw step also goes in after its threaded partner (or the fit it turns on): its motion
//! turns on it.
//!
//! `levels` groups the steps by their longest chain of predecessors (a level's steps may go in
//! in parallel once the levels before are done), `critical_path` is a longest chain. Each step's
//! `distance` is the travel that clears the bounds of every part that may be in place when it
//! goes in in some order the graph allows (at least the plan's own travel).

use crate::problem::Step;
use asp_geom::{Motion, PartSet, World};
use serde::{Deserialize, Serialize};

/// The precedence graph (plan format 1.12).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PrecedenceEntry {
    /// How support was turned into edges.
    pub stability: PrecedenceStability,
    /// Every assembly step (index into `assembly_sequence`) with its level.
    pub steps: Vec<PrecedenceStep>,
    /// `before` goes in before `after` (step indices), with why.
    pub edges: Vec<PrecedenceEdge>,
    /// Steps by level: every predecessor of a level's step is in an earlier level.
    pub levels: Vec<Vec<usize>>,
    /// A longest chain of steps, first to last.
    pub critical_path: Vec<usize>,
}

/// What the support edges ensure.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PrecedenceStability {
    /// The plan's stability criterion (`contact` or `physics`).
    pub criterion: String,
    /// Always true: support edges may forbid orders that would stand (never the reverse under
    /// the contact criterion).
    pub conservative: bool,
    /// Whether every order the graph allows stands under the plan's own criterion (true for
    /// `contact`; for `physics` only the contact criterion is ensured).
    pub guaranteed: bool,
}

/// One step of the graph.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PrecedenceStep {
    /// Index into `assembly_sequence`.
    pub step: usize,
    /// The step's part (a subassembly's base).
    pub part: usize,
    /// Its name.
    pub name: String,
    /// Its level (0: no predecessor).
    pub level: usize,
    /// Straight and screw motions: the insertion travel, model units, that clears every part
    /// that may be in place before it in some order the graph allows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
}

/// Why one step goes before another.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PrecedenceReason {
    /// A part of `after`, in place, would block the motion of `before`.
    Blocks,
    /// `before` holds `after` up (contact support).
    Supports,
    /// `after` screws onto `before` (its threaded partner, or the fit it turns on): its screw
    /// motion needs it in place.
    Thread,
}

/// One edge.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PrecedenceEdge {
    /// The step that goes in first.
    pub before: usize,
    /// The step that goes in after it.
    pub after: usize,
    /// Why (one or both).
    pub reasons: Vec<PrecedenceReason>,
}

impl PrecedenceEntry {
    /// The graph of a found plan's `removals` in `world` (`physics`: the plan's stability is the
    /// physics check). `None` when a step moves other parts (grid plans) or nothing is removed.
    pub fn of(world: &World, removals: &[Step], physics: bool) -> Option<PrecedenceEntry> {
        if removals.is_empty() || removals.iter().any(|s| !s.moves.is_empty()) {
            return None;
        }
        let n = world.num_parts();
        let steps: Vec<&Step> = removals.iter().rev().collect();
        let k = steps.len();
        let parts: Vec<Vec<usize>> = steps.iter().map(|s| s.parts()).collect();
        let mut step_of = vec![None; n + 1];
        for (i, ps) in parts.iter().enumerate() {
            for &p in ps {
                step_of[p] = Some(i);
            }
        }
        let mut reasons: std::collections::BTreeMap<(usize, usize), Vec<PrecedenceReason>> = Default::default();
        fn add(a: usize, b: usize, r: PrecedenceReason, reasons: &mut std::collections::BTreeMap<(usize, usize), Vec<PrecedenceReason>>) {
            let e = reasons.entry((a, b)).or_default();
            if !e.contains(&r) {
                e.push(r);
                e.sort();
            }
        }
        // blocking: B's part in place blocks A's motion → A before B (B after A in the plan)
        for a in 0..k {
            for b in a + 1..k {
                if blocks(world, &parts[a], &steps[a].motion, &parts[b]) {
                    add(a, b, PrecedenceReason::Blocks, &mut reasons);
                }
            }
        }
        // a screw step turns on its threaded partner (or a fit it turns on), which it needs in place
        for (c, step) in steps.iter().enumerate() {
            let Motion::Screw { direction, .. } = step.motion else { continue };
            let p = step.part;
            for (b, earlier) in parts.iter().enumerate().take(c) {
                let partner = earlier.iter().any(|&q| {
                    world.overlaps().fits().thread(p, q).is_some_and(|t| t.axis.direction.dot(direction).abs() > 0.9999)
                        || world.overlaps().fits().between(p, q).iter().any(|f| f.turns == Some(p) && f.axis.dot(direction).abs() > 0.9999)
                });
                if partner {
                    add(b, c, PrecedenceReason::Thread, &mut reasons);
                }
            }
        }
        // support, in assembly order (levels of earlier steps are known)
        let fixed = world.contacts().fixed().clone();
        let mut level = vec![0usize; k];
        for c in 0..k {
            let touching: Vec<usize> = {
                let mut t: Vec<usize> = parts[c]
                    .iter()
                    .flat_map(|&p| world.contacts().of(p).iter().collect::<Vec<_>>())
                    .filter_map(|q| step_of.get(q).copied().flatten())
                    .filter(|&b| b < c)
                    .collect();
                t.sort_unstable();
                t.dedup();
                t
            };
            if physics {
                for &b in &touching {
                    add(b, c, PrecedenceReason::Supports, &mut reasons);
                }
            } else {
                let mut held = fixed.clone();
                let mut chosen: Vec<usize> = Vec::new();
                loop {
                    let mut present = held.clone();
                    for &p in &parts[c] {
                        present.insert(p);
                    }
                    let reached = held.intersection(&present).reached_within(&present, |i| world.contacts().of(i).iter());
                    let unreached: Vec<usize> = parts[c].iter().copied().filter(|&p| !reached.contains(p)).collect();
                    if unreached.is_empty() {
                        break;
                    }
                    let best = touching
                        .iter()
                        .copied()
                        .filter(|b| !chosen.contains(b))
                        .filter(|&b| parts[b].iter().any(|&q| unreached.iter().any(|&p| world.contacts().of(p).contains(q))))
                        .min_by_key(|&b| (level[b], std::cmp::Reverse(b)));
                    match best {
                        Some(b) => {
                            chosen.push(b);
                            for &q in &parts[b] {
                                held.insert(q);
                            }
                        }
                        None => {
                            // cannot happen for a plan that stood; the safe answer: every earlier step
                            let rest: Vec<usize> = (0..c).filter(|b| !chosen.contains(b)).collect();
                            chosen.extend(rest);
                            break;
                        }
                    }
                }
                for b in chosen {
                    add(b, c, PrecedenceReason::Supports, &mut reasons);
                }
            }
            level[c] = reasons.keys().filter(|(_, after)| *after == c).map(|(before, _)| level[*before] + 1).max().unwrap_or(0);
        }
        let edges: Vec<PrecedenceEdge> =
            reasons.into_iter().map(|((before, after), reasons)| PrecedenceEdge { before, after, reasons }).collect();
        let depth = level.iter().copied().max().unwrap_or(0);
        let levels: Vec<Vec<usize>> = (0..=depth).map(|l| (0..k).filter(|&s| level[s] == l).collect()).collect();
        // a longest chain: from a step of the deepest level back through predecessors one level up
        let mut critical_path = Vec::new();
        let mut at = (0..k).find(|&s| level[s] == depth);
        while let Some(s) = at {
            critical_path.push(s);
            at = edges.iter().filter(|e| e.after == s && level[e.before] + 1 == level[s]).map(|e| e.before).min();
        }
        critical_path.reverse();
        // the travel that clears every part that may be in place: all but the step's descendants
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); k];
        for e in &edges {
            after[e.before].push(e.after);
        }
        let u = |m: f32| world.assembly().units.from_metres(m as f64);
        let entries = (0..k)
            .map(|s| {
                let mut later = vec![false; k];
                let mut stack = vec![s];
                while let Some(x) = stack.pop() {
                    for &y in &after[x] {
                        if !later[y] {
                            later[y] = true;
                            stack.push(y);
                        }
                    }
                }
                let may = (0..k).filter(|&t| !later[t]).flat_map(|t| parts[t].iter().copied());
                let state = PartSet::from_indices(n + 1, may.chain(world.contacts().fixed().iter().filter(|&q| q < n)));
                let distance = match &steps[s].motion {
                    Motion::Linear { direction, distance } | Motion::Screw { direction, distance, .. } => {
                        let need = if parts[s].len() == 1 {
                            world.removal().clearance(parts[s][0], &state, *direction)
                        } else {
                            world.removal().group_clearance(&PartSet::from_indices(n + 1, parts[s].iter().copied()), &state, *direction)
                        };
                        Some(u(need.max(*distance)))
                    }
                    Motion::Path { .. } => None,
                };
                PrecedenceStep { step: s, part: steps[s].part, name: world.name(steps[s].part).to_string(), level: level[s], distance }
            })
            .collect();
        Some(PrecedenceEntry {
            stability: PrecedenceStability {
                criterion: if physics { "physics" } else { "contact" }.into(),
                conservative: true,
                guaranteed: !physics,
            },
            steps: entries,
            edges,
            levels,
            critical_path,
        })
    }

    /// The graph as Graphviz DOT: one node per step (`N: name`), ranked by level; blocking edges
    /// solid, support edges dashed, the critical path bold.
    pub fn to_dot(&self) -> String {
        use std::fmt::Write;
        let mut s = String::from("digraph precedence {\n  rankdir=LR;\n  node [shape=box];\n");
        for st in &self.steps {
            let _ = writeln!(s, "  s{} [label=\"{}: {}\"];", st.step, st.step + 1, st.name.replace('\\', "\\\\").replace('"', "\\\""));
        }
        for level in &self.levels {
            let nodes: Vec<String> = level.iter().map(|i| format!("s{i}")).collect();
            let _ = writeln!(s, "  {{ rank=same; {}; }}", nodes.join("; "));
        }
        let critical: std::collections::HashSet<(usize, usize)> = self.critical_path.windows(2).map(|w| (w[0], w[1])).collect();
        for e in &self.edges {
            let label = e
                .reasons
                .iter()
                .map(|r| match r {
                    PrecedenceReason::Blocks => "blocks",
                    PrecedenceReason::Supports => "supports",
                    PrecedenceReason::Thread => "thread",
                })
                .collect::<Vec<_>>()
                .join("+");
            let style = if e.reasons == [PrecedenceReason::Supports] { "dashed" } else { "solid" };
            let bold = if critical.contains(&(e.before, e.after)) { ", penwidth=2.5" } else { "" };
            let _ = writeln!(s, "  s{} -> s{} [label=\"{label}\", style={style}{bold}];", e.before, e.after);
        }
        s.push_str("}\n");
        s
    }
}

/// Whether a part of `others`, in place, blocks the motion of `movers`.
fn blocks(world: &World, movers: &[usize], motion: &Motion, others: &[usize]) -> bool {
    match motion {
        Motion::Linear { direction, .. } | Motion::Screw { direction, .. } => {
            let k = world.blocking().directions().iter().position(|d| d.dot(*direction) > 0.999_999);
            movers.iter().any(|&p| {
                others.iter().any(|&q| match k {
                    Some(k) => world.blocking().row(p)[k].contains(q),
                    None => world.blocking().pair_blocks(p, q, *direction),
                })
            })
        }
        Motion::Path { poses, pivot } => movers.iter().any(|&p| {
            others.iter().any(|&q| {
                let state = PartSet::from_indices(world.num_parts() + 1, [q]);
                poses.windows(2).any(|w| world.removal().collision_between(p, &w[0], &w[1], *pivot, &state) == Some(q))
            })
        }),
    }
}
