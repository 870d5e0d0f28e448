""":class:`Graph`: the graph of a disassembly state as numpy arrays (``docs/learning.md``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from asp import _asp

__all__ = ["Graph"]


@dataclass(frozen=True)
class Graph:
    """The graph of a disassembly state, in the layout of a removability model's inputs.

    Nodes are the present parts in ascending order; a directed edge ``s → t`` joins every ordered
    pair of present parts in contact (both directions), ordered by (source, target).
    """

    #: int64 ``[n]``: the part index of each node.
    nodes: np.ndarray
    #: float32 ``[n, node_dim]``: node attributes (model input ``x``).
    x: np.ndarray
    #: int64 ``[2, e]``: sources then targets, as node positions (model input ``edge_index``).
    edge_index: np.ndarray
    #: float32 ``[e, edge_dim]``: edge attributes (model input ``edge_attr``).
    edge_attr: np.ndarray
    #: The feature set and its parameters (``asp-graph/2 radius_bins=8 degree=8 points=2048``).
    features: str

    @property
    def num_nodes(self) -> int:
        """``n``."""
        return int(self.x.shape[0])

    @property
    def num_edges(self) -> int:
        """``e``."""
        return int(self.edge_index.shape[1])

    @property
    def node_dim(self) -> int:
        """Floats per node."""
        return int(self.x.shape[1])

    @property
    def edge_dim(self) -> int:
        """Floats per edge."""
        return int(self.edge_attr.shape[1])

    @classmethod
    def _from_native(cls, raw: _asp.GraphArrays) -> Graph:
        """From ``asp._asp.GraphArrays``' little-endian buffers (writable arrays, no copy)."""
        n = len(raw.nodes) // 8
        e = len(raw.edge_index) // 16
        return cls(
            nodes=np.frombuffer(raw.nodes, dtype="<i8").astype(np.int64, copy=False),
            x=np.frombuffer(raw.x, dtype="<f4").astype(np.float32, copy=False).reshape(n, raw.node_dim),
            edge_index=np.frombuffer(raw.edge_index, dtype="<i8").astype(np.int64, copy=False).reshape(2, e),
            edge_attr=np.frombuffer(raw.edge_attr, dtype="<f4").astype(np.float32, copy=False).reshape(e, raw.edge_dim),
            features=raw.features,
        )
