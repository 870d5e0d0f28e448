//! [`StateGraph`]: the graph of one disassembly state, the induced subgraph of the
//! [`AssemblyGraph`] on the present parts, laid out as the ONNX model's inputs.

use super::build::AssemblyGraph;
use crate::partset::PartSet;
use smallvec::SmallVec;

/// The graph of a state in the layout of a removability model's inputs (`docs/learning.md`,
/// "Models"): nodes are the present parts in ascending order, edges the model graph's edges
/// whose ends are both present, in the order of [`AssemblyGraph::edges`], renumbered to
/// positions in `nodes`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StateGraph {
    /// The present parts, ascending (part indices of the model).
    pub nodes: Vec<usize>,
    /// Node attributes, row-major `nodes.len() × node_dim` (input `x`).
    pub x: Vec<f32>,
    /// `2 × e` row-major: the `e` sources, then the `e` targets, as positions in `nodes`
    /// (input `edge_index`).
    pub edge_index: Vec<i64>,
    /// Edge attributes, row-major `e × edge_dim` (input `edge_attr`).
    pub edge_attr: Vec<f32>,
    /// Floats per node.
    pub node_dim: usize,
    /// Floats per edge.
    pub edge_dim: usize,
}

impl StateGraph {
    /// Number of nodes `n`.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of edges `e`.
    pub fn num_edges(&self) -> usize {
        self.edge_index.len() / 2
    }

    /// The sources (first row of `edge_index`).
    pub fn sources(&self) -> &[i64] {
        &self.edge_index[..self.num_edges()]
    }

    /// The targets (second row of `edge_index`).
    pub fn targets(&self) -> &[i64] {
        &self.edge_index[self.num_edges()..]
    }
}

impl AssemblyGraph {
    /// The graph of the state `present` (parts beyond [`AssemblyGraph::num_parts`], such as the
    /// virtual ground, are ignored).
    pub fn state(&self, present: &PartSet) -> StateGraph {
        let mut out = StateGraph::default();
        self.state_into(present, &mut out);
        out
    }

    /// [`AssemblyGraph::state`] into `out`, reusing its buffers: no allocation once they have
    /// grown to the largest state. Runs in `O(n + e_out)` for the present parts' out-edges.
    pub fn state_into(&self, present: &PartSet, out: &mut StateGraph) {
        let n = self.num_parts();
        out.node_dim = self.node_dim();
        out.edge_dim = self.edge_dim();
        out.nodes.clear();
        out.x.clear();
        out.edge_index.clear();
        out.edge_attr.clear();
        out.nodes.extend(present.iter().take_while(|&i| i < n));
        for &i in &out.nodes {
            out.x.extend_from_slice(self.node_attr(i));
        }
        // position of a present part = number of present parts below it (bits >= n lie above)
        let words = present.words();
        let mut prefix: SmallVec<[u32; 8]> = SmallVec::with_capacity(words.len());
        let mut count = 0u32;
        for w in words {
            prefix.push(count);
            count += w.count_ones();
        }
        let rank = |g: usize| (prefix[g / 64] + (words[g / 64] & ((1u64 << (g % 64)) - 1)).count_ones()) as i64;
        let edges = self.edges();
        for &s in &out.nodes {
            for k in self.edges_from(s) {
                if present.contains(edges[k].1) {
                    out.edge_index.push(rank(s));
                    out.edge_attr.extend_from_slice(self.edge_attr(k));
                }
            }
        }
        for &s in &out.nodes {
            for k in self.edges_from(s) {
                let t = edges[k].1;
                if present.contains(t) {
                    out.edge_index.push(rank(t));
                }
            }
        }
    }
}
