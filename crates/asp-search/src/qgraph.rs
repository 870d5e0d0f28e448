//! The graph of an optimiser state that learned Q-functions read (thesis 5.4.3 and 6.4.3 in one
//! representation; the contract is `docs/learning.md`, "Q-functions", features `asp-q/1`).
//!
//! Nodes are the present parts (fixed ones included, the floor not) and one *context* node that
//! carries the direction history `H` of the `dirchange` objective. A part node holds its box's
//! eight corners, its minimum distance map `M̄(p_i, s)` and its free directions `B^M̄(p_i, s)`;
//! an edge `s → t` joins each part to its `K` nearest present parts (by box centres) with the
//! unit vector and distance between them, `M(p_t, p_s)` and `B^M(p_t, p_s)`; the context node
//! sends an edge to every part. Everything comes from the optimiser's [`MapState`] and the
//! objectives' memory; nothing is copied per state but the output arrays.
//!
//! [`QGraphBuilder`] precomputes what does not depend on the state (corners, centres, each
//! part's other parts sorted by distance) once per model; [`QGraphBuilder::build`] then writes a
//! state's graph into reused buffers in `O(n·K + n·D)`.

use crate::mdp::Mdp;
use crate::objective::DirHistory;
use asp_geom::distmap::{DirMask, DistanceMaps, MapState};
use asp_geom::math::Vec3;

/// The name of the feature set.
pub const FEATURES: &str = "asp-q/1";
/// Neighbours per part node (`K`, the thesis' `N_c`).
pub const DEFAULT_NEIGHBOURS: usize = 8;
/// Node columns before the two direction blocks: flags (4) and box corners (24).
const NODE_HEAD: usize = 28;
/// Edge columns before the two direction blocks: flag, unit vector, distance.
const EDGE_HEAD: usize = 5;

/// The parameters of the feature set: the maps' direction count `D` and the neighbours `K`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QGraphConfig {
    /// Directions of the distance maps (`D`, the square of the maps' resolution).
    pub directions: usize,
    /// Nearest parts each part node receives an edge from (`K`).
    pub neighbours: usize,
}

impl QGraphConfig {
    /// The features of `maps` with the default neighbours.
    pub fn for_maps(maps: &DistanceMaps) -> Self {
        QGraphConfig { directions: maps.num_directions(), neighbours: DEFAULT_NEIGHBOURS }
    }

    /// The features string a model records (`asp-q/1 directions=81 neighbours=8`).
    pub fn features(&self) -> String {
        format!("{FEATURES} directions={} neighbours={}", self.directions, self.neighbours)
    }

    /// Floats per node.
    pub fn node_dim(&self) -> usize {
        NODE_HEAD + 2 * self.directions
    }

    /// Floats per edge.
    pub fn edge_dim(&self) -> usize {
        EDGE_HEAD + 2 * self.directions
    }
}

/// The direction history `H` of the problem's `dirchange` objective in `memory` (the state's
/// memory words of every objective), or `None` without that objective or before the first
/// removal.
pub fn direction_history(problem: &Mdp, memory: &[u64]) -> Option<DirMask> {
    let k = problem.objectives().iter().position(|o| o.name() == "dirchange")?;
    let words = &memory[problem.memory_range(k)];
    if words.len() < DirHistory::WORDS {
        return None;
    }
    let h = DirHistory::load(words);
    h.active.then_some(h.mask)
}

/// The order of neighbours: the centre distance in units of `1e-5 ×` the model's diagonal,
/// rounded, so that parts at equal distances (voxel models) tie at every scale and ties go by
/// part index.
pub fn neighbour_key(a: Vec3, b: Vec3, diagonal: f32) -> u64 {
    (f64::from(a.distance(b)) / f64::from(diagonal) * 1e5).round() as u64
}

/// One state's graph in the layout of a Q model's inputs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QGraph {
    /// The part index of each node; `-1` for the context node (the last).
    pub nodes: Vec<i64>,
    /// `[n, node_dim]` row-major.
    pub x: Vec<f32>,
    /// `[2, e]`: the `e` sources, then the `e` targets (node positions).
    pub edge_index: Vec<i64>,
    /// `[e, edge_dim]` row-major.
    pub edge_attr: Vec<f32>,
    /// Edge targets while building (moved into `edge_index` at the end).
    targets: Vec<i64>,
}

impl QGraph {
    /// Nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Edges.
    pub fn num_edges(&self) -> usize {
        self.edge_index.len() / 2
    }
}

/// What the graphs of one model share: the feature parameters, box corners and centres, and
/// each part's other parts ordered by centre distance.
#[derive(Clone, Debug)]
pub struct QGraphBuilder {
    config: QGraphConfig,
    /// Per part: the 24 corner coordinates, normalised.
    corners: Vec<[f32; 24]>,
    centres: Vec<Vec3>,
    /// Per part: the other parts, nearest centre first (ties by index).
    nearest: Vec<Vec<u16>>,
    /// The model's bounding-box diagonal `L`.
    diagonal: f32,
    /// Position of each part among the present ones (scratch).
    position: Vec<u32>,
}

impl QGraphBuilder {
    /// The builder of `maps`' graphs with `neighbours` (`K`) per part.
    pub fn new(maps: &DistanceMaps, neighbours: usize) -> Self {
        let n = maps.num_parts();
        let config = QGraphConfig { directions: maps.num_directions(), neighbours };
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for i in 0..n {
            let b = maps.part_aabb(i);
            lo = lo.min(b.mins);
            hi = hi.max(b.maxs);
        }
        let centre = if n == 0 { Vec3::ZERO } else { (lo + hi) * 0.5 };
        let diagonal = if n == 0 { 1.0 } else { (hi - lo).length().max(f32::MIN_POSITIVE) };
        let mut corners = Vec::with_capacity(n);
        let mut centres = Vec::with_capacity(n);
        for i in 0..n {
            let b = maps.part_aabb(i);
            let mut c = [0.0f32; 24];
            for k in 0..8 {
                let p = Vec3::new(
                    if k & 1 != 0 { b.maxs.x } else { b.mins.x },
                    if k & 2 != 0 { b.maxs.y } else { b.mins.y },
                    if k & 4 != 0 { b.maxs.z } else { b.mins.z },
                );
                let q = (p - centre) / diagonal;
                c[3 * k..3 * k + 3].copy_from_slice(&[q.x, q.y, q.z]);
            }
            corners.push(c);
            centres.push((b.mins + b.maxs) * 0.5);
        }
        let nearest = (0..n)
            .map(|i| {
                let mut others: Vec<u16> = (0..n).filter(|&j| j != i).map(|j| j as u16).collect();
                others.sort_by_key(|&j| (neighbour_key(centres[i], centres[j as usize], diagonal), j));
                others
            })
            .collect();
        QGraphBuilder { config, corners, centres, nearest, diagonal, position: vec![u32::MAX; n] }
    }

    /// The feature parameters.
    pub fn config(&self) -> QGraphConfig {
        self.config
    }

    /// Writes the graph of `state` into `out`: `history` is the `dirchange` history `H`
    /// ([`direction_history`]), `actions` the feasible removals a Q-function is asked about
    /// (flagged on their nodes). Parts in `actions` must be present.
    pub fn build(&mut self, state: &mut MapState<'_>, history: Option<DirMask>, actions: &[usize], out: &mut QGraph) {
        self.build_with(state, history, actions, out);
    }

    /// Only the nodes and the edges of `state`'s graph (`out.x` and `out.edge_attr` stay empty).
    /// A part node's attributes are a function of the part, [`MapState::row_key`] and whether it
    /// is asked about ([`node_row`](Self::node_row)), so an evaluator that caches what it makes
    /// of them per part and key needs no more than this per state.
    pub fn build_edges(&mut self, state: &MapState<'_>, out: &mut QGraph) {
        let present = state.present();
        self.place(&present, out);
        self.edges(state.maps(), out, false);
    }

    /// The attributes of part `i`'s node in `state` (`row` has `node_dim` floats); `asked` says
    /// whether the part is one of the removals a Q-function is asked about.
    pub fn node_row(&self, state: &mut MapState<'_>, i: usize, asked: bool, row: &mut [f32]) {
        let maps = state.maps();
        let d = self.config.directions;
        let d_max = maps.d_max();
        row.fill(0.0);
        row[0] = 1.0;
        row[2] = f32::from(u8::from(maps.is_fixed(i)));
        row[3] = f32::from(u8::from(asked));
        row[4..NODE_HEAD].copy_from_slice(&self.corners[i]);
        let min_map = state.min_map(i);
        for (o, v) in row[NODE_HEAD..NODE_HEAD + d].iter_mut().zip(min_map) {
            *o = (v / d_max).clamp(0.0, 1.0);
        }
        let free = state.free_mask(i);
        for (dir, o) in row[NODE_HEAD + d..NODE_HEAD + 2 * d].iter_mut().enumerate() {
            *o = f32::from(u8::from(free.contains(dir)));
        }
    }

    /// The attributes of the context node (`row` has `node_dim` floats) for the direction
    /// history `history`.
    pub fn context_row(&self, history: Option<DirMask>, row: &mut [f32]) {
        let d = self.config.directions;
        row.fill(0.0);
        row[0] = 1.0;
        row[1] = 1.0;
        if let Some(h) = history {
            for dir in h.iter().filter(|&dir| dir < d) {
                row[NODE_HEAD + d + dir] = 1.0;
            }
        }
    }

    /// The attributes of the edge from part `s` to part `t` (`row` has `edge_dim` floats), or of
    /// the context node's edge to a part when `s` is `None`. They do not depend on the state.
    pub fn edge_attributes(&self, maps: &DistanceMaps, t: usize, s: Option<usize>, row: &mut [f32]) {
        let d = self.config.directions;
        row.fill(0.0);
        let Some(s) = s else {
            row[0] = 1.0;
            return;
        };
        let d_max = maps.d_max();
        let v = self.centres[s] - self.centres[t];
        let len = v.length();
        if len > 0.0 {
            let u = v / len;
            row[1..4].copy_from_slice(&[u.x, u.y, u.z]);
        }
        row[4] = len / self.diagonal;
        for (o, v) in row[EDGE_HEAD..EDGE_HEAD + d].iter_mut().zip(maps.map(t, s)) {
            *o = (v / d_max).clamp(0.0, 1.0);
        }
        let blocked = maps.blocked(t, s);
        for (dir, o) in row[EDGE_HEAD + d..EDGE_HEAD + 2 * d].iter_mut().enumerate() {
            *o = f32::from(u8::from(!blocked.contains(dir)));
        }
    }

    /// The nodes of `present` (increasing part index, then the context node, `-1`) in `out`, and
    /// each part's position among them in `self.position`.
    fn place(&mut self, present: &asp_geom::PartSet, out: &mut QGraph) {
        out.nodes.clear();
        out.x.clear();
        out.edge_index.clear();
        out.edge_attr.clear();
        out.targets.clear();
        for p in self.position.iter_mut() {
            *p = u32::MAX;
        }
        for i in present.iter() {
            self.position[i] = out.nodes.len() as u32;
            out.nodes.push(i as i64);
        }
        out.nodes.push(-1);
    }

    fn build_with(&mut self, state: &mut MapState<'_>, history: Option<DirMask>, actions: &[usize], out: &mut QGraph) {
        let present = state.present();
        self.place(&present, out);
        let node_dim = self.config.node_dim();
        let parts = out.nodes.len() - 1;
        out.x.resize((parts + 1) * node_dim, 0.0);
        for k in 0..parts {
            let i = out.nodes[k] as usize;
            // flagged below (actions are few; a search per node would cost more)
            self.node_row(state, i, false, &mut out.x[k * node_dim..(k + 1) * node_dim]);
        }
        for &a in actions {
            if let Some(&k) = self.position.get(a).filter(|&&k| k != u32::MAX) {
                out.x[k as usize * node_dim + 3] = 1.0;
            }
        }
        self.context_row(history, &mut out.x[parts * node_dim..(parts + 1) * node_dim]);
        self.edges(state.maps(), out, true);
    }

    /// The edges of the nodes in `out` (placed by [`place`](Self::place)), with their attributes
    /// when `attributes` is set.
    fn edges(&self, maps: &DistanceMaps, out: &mut QGraph, attributes: bool) {
        let edge_dim = self.config.edge_dim();
        let parts = out.nodes.len() - 1;
        let context = parts;
        for t_pos in 0..parts {
            let t = out.nodes[t_pos] as usize;
            let mut taken = 0;
            for &s in &self.nearest[t] {
                if taken == self.config.neighbours {
                    break;
                }
                let s = s as usize;
                let s_pos = self.position[s];
                if s_pos == u32::MAX {
                    continue;
                }
                taken += 1;
                out.edge_index.push(i64::from(s_pos));
                out.targets.push(t_pos as i64);
                if attributes {
                    let start = out.edge_attr.len();
                    out.edge_attr.resize(start + edge_dim, 0.0);
                    self.edge_attributes(maps, t, Some(s), &mut out.edge_attr[start..]);
                }
            }
            out.edge_index.push(context as i64);
            out.targets.push(t_pos as i64);
            if attributes {
                let start = out.edge_attr.len();
                out.edge_attr.resize(start + edge_dim, 0.0);
                out.edge_attr[start] = 1.0;
            }
        }
        out.edge_index.extend_from_slice(&out.targets);
        out.targets.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensions_follow_the_contract() {
        let c = QGraphConfig { directions: 81, neighbours: 8 };
        assert_eq!(c.node_dim(), 190);
        assert_eq!(c.edge_dim(), 167);
        assert_eq!(c.features(), "asp-q/1 directions=81 neighbours=8");
    }
}
