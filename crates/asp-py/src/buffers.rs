//! The graph buffers handed to Python, shared by `Assembly.graph` and `QGraphs.graph` (its own
//! module so that `assembly.rs` and `qgraphs.rs` do not import each other).

use pyo3::prelude::*;
use pyo3::types::PyByteArray;

/// What `Assembly.graph` returns: the part indices (int64), `x` (float32), `edge_index` (int64)
/// and `edge_attr` (float32) as little-endian bytes, `node_dim`, `edge_dim` and the features
/// string; `asp.Graph` views the bytes as numpy arrays.
pub type GraphBuffers<'py> =
    (Bound<'py, PyByteArray>, Bound<'py, PyByteArray>, Bound<'py, PyByteArray>, Bound<'py, PyByteArray>, usize, usize, String);
