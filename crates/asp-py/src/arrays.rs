//! `asp._asp.GraphArrays`: a state graph as little-endian buffers that `asp.Graph` views with
//! numpy without a copy (`Assembly.graph` and `QGraphs.graph` both give one).

use pyo3::prelude::*;
use pyo3::types::PyByteArray;

/// A graph's arrays: `nodes` (int64 part indices), `x` (float32, `node_dim` per node),
/// `edge_index` (int64, 2 × edges), `edge_attr` (float32, `edge_dim` per edge), and the features
/// string of the layout.
#[pyclass(frozen, get_all, module = "asp._asp", name = "GraphArrays")]
pub struct GraphArrays {
    /// Part index of each node, int64 little-endian.
    pub nodes: Py<PyByteArray>,
    /// Node attributes, float32 little-endian, row-major.
    pub x: Py<PyByteArray>,
    /// Edges as two rows (sources, targets), int64 little-endian.
    pub edge_index: Py<PyByteArray>,
    /// Edge attributes, float32 little-endian, row-major.
    pub edge_attr: Py<PyByteArray>,
    /// Floats per node.
    pub node_dim: usize,
    /// Floats per edge.
    pub edge_dim: usize,
    /// The features string (`asp-graph/...`, `asp-q/1 ...`).
    pub features: String,
}

impl GraphArrays {
    /// The arrays of a graph given as slices.
    #[allow(clippy::too_many_arguments)] // the graph's four arrays and three layout facts
    pub fn new(
        py: Python<'_>,
        nodes: impl Iterator<Item = i64>,
        x: &[f32],
        edge_index: impl Iterator<Item = i64>,
        edge_attr: &[f32],
        node_dim: usize,
        edge_dim: usize,
        features: String,
    ) -> Self {
        let ints = |v: &mut dyn Iterator<Item = i64>| v.flat_map(i64::to_le_bytes).collect::<Vec<u8>>();
        let floats = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
        let (mut nodes, mut edge_index) = (nodes, edge_index);
        GraphArrays {
            nodes: PyByteArray::new(py, &ints(&mut nodes)).unbind(),
            x: PyByteArray::new(py, &floats(x)).unbind(),
            edge_index: PyByteArray::new(py, &ints(&mut edge_index)).unbind(),
            edge_attr: PyByteArray::new(py, &floats(edge_attr)).unbind(),
            node_dim,
            edge_dim,
            features,
        }
    }
}

#[pymethods]
impl GraphArrays {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<asp._asp.GraphArrays {} nodes, {} edges, {}>",
            self.nodes.bind(py).len() / 8,
            self.edge_index.bind(py).len() / 16,
            self.features
        )
    }
}
