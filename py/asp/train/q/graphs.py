"""State graphs for Q-learning: what a graph source returns, the default source (asp's own graphs
through the binding), synthetic ``asp-q/1`` graphs in NumPy, and the least-recently-used cache
that checks a source's output."""

from __future__ import annotations

import re
from collections import OrderedDict
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Protocol

import numpy as np

from ...datasets.transitions import DataError, TransitionAssembly

if TYPE_CHECKING:
    from ...qgraphs import QGraphs

__all__ = ["GraphLike", "GraphSource", "SyntheticGraph", "parse_q_features", "synthetic_q_graph", "BindingGraphs", "GraphCache"]


class GraphLike(Protocol):
    """What a graph source returns (``asp.Graph`` is one): four read-only arrays."""

    @property
    def nodes(self) -> np.ndarray:
        """int64 ``[n]``: the part of each node, -1 for the context node."""

    @property
    def x(self) -> np.ndarray:
        """float32 ``[n, node_dim]``."""

    @property
    def edge_index(self) -> np.ndarray:
        """int64 ``[2, e]``."""

    @property
    def edge_attr(self) -> np.ndarray:
        """float32 ``[e, edge_dim]``."""


GraphSource = Callable[[TransitionAssembly, np.ndarray, np.ndarray, np.ndarray], GraphLike]
"""``source(assembly, present, actions, history) -> graph`` of one optimiser state."""


@dataclass(frozen=True)
class SyntheticGraph:
    """A graph built in NumPy (:func:`synthetic_q_graph`), shaped like ``asp.Graph``."""

    nodes: np.ndarray
    x: np.ndarray
    edge_index: np.ndarray
    edge_attr: np.ndarray


_Q_FEATURES = re.compile(r"^asp-q/1 directions=(\d+) neighbours=(\d+)$")


def parse_q_features(features: str) -> tuple[int, int] | None:
    """``(D, K)`` of an ``asp-q/1 directions=D neighbours=K`` string, else ``None``."""
    m = _Q_FEATURES.match(features.strip())
    return (int(m.group(1)), int(m.group(2))) if m else None


def synthetic_q_graph(
    boxes: np.ndarray,
    present: np.ndarray,
    actions: np.ndarray,
    history: np.ndarray,
    directions: int,
    neighbours: int = 8,
    fixed: np.ndarray | None = None,
    maps: np.ndarray | None = None,
    rng: np.random.Generator | None = None,
) -> SyntheticGraph:
    """An ``asp-q/1`` state graph laid out as the contract's tables, from part boxes in NumPy.

    ``boxes`` float ``[N, 2, 3]`` (min and max corner of each part), ``present``/``actions`` part
    indices, ``history`` direction indices. Map columns (``M̄``, ``B^M̄`` per node and ``M``,
    ``B^M`` per edge) come from ``maps`` (float ``[N, N, D]`` in [0, 1], ``maps[t, s]`` how far
    ``t`` moves before it enters ``s``; a node's minimum map is the minimum over the present ``s``)
    or, without it, are drawn from ``rng``. For tests and the export's parity check; asp computes
    the real graphs in Rust.
    """
    D = directions
    present = np.asarray(present, dtype=np.int64)
    n = len(present)
    boxes = np.asarray(boxes, dtype=np.float64)
    lo_all, hi_all = boxes[:, 0].min(0), boxes[:, 1].max(0)
    centre_all = (lo_all + hi_all) / 2
    diag = float(np.linalg.norm(hi_all - lo_all)) or 1.0
    centres = boxes[present].mean(axis=1)
    x = np.zeros((n + 1, 28 + 2 * D), dtype=np.float32)
    x[:, 0] = 1.0
    x[n, 1] = 1.0
    if fixed is not None:
        x[:n, 2] = np.asarray(fixed, dtype=bool)[present]
    x[:n, 3] = np.isin(present, actions)
    for k in range(8):
        corner = np.stack([boxes[present, 1 if k & (1 << axis) else 0, axis] for axis in range(3)], 1)
        x[:n, 4 + 3 * k : 7 + 3 * k] = (corner - centre_all) / diag
    if maps is None:
        rng = rng or np.random.default_rng(0)
        maps_present = rng.uniform(0.0, 1.0, size=(n, n, D))
    else:
        maps_present = np.asarray(maps, dtype=np.float64)[np.ix_(present, present)]
    for i in range(n):
        others = np.delete(maps_present[i], i, axis=0)
        minimum = others.min(0) if len(others) else np.ones(D)
        x[i, 28 : 28 + D] = minimum
        x[i, 28 + D :] = minimum >= 1.0
    x[n, 28 + D :] = 0.0
    x[n, 28 + D + np.asarray(history, dtype=np.int64)] = 1.0
    sources, targets, attrs = [], [], []
    for t in range(n):
        d = np.linalg.norm(centres - centres[t], axis=1)
        order = [s for s in np.lexsort((present, d)) if s != t][:neighbours]
        for s in order:
            a = np.zeros(5 + 2 * D, dtype=np.float32)
            v = centres[s] - centres[t]
            if d[s] > 0:
                a[1:4] = v / d[s]
            a[4] = d[s] / diag
            a[5 : 5 + D] = maps_present[t, s]
            a[5 + D :] = maps_present[t, s] >= 1.0
            sources.append(s)
            targets.append(t)
            attrs.append(a)
        a = np.zeros(5 + 2 * D, dtype=np.float32)
        a[0] = 1.0
        sources.append(n)
        targets.append(t)
        attrs.append(a)
    edge_index = np.array([sources, targets], dtype=np.int64).reshape(2, -1)
    edge_attr = np.array(attrs, dtype=np.float32).reshape(-1, 5 + 2 * D)
    nodes = np.concatenate([present, [-1]]).astype(np.int64)
    return SyntheticGraph(nodes, x, edge_index, edge_attr)


class BindingGraphs:
    """The default graph source: asp's own ``asp-q/1`` graphs, through the Python binding.

    Loads each assembly's model once (``asp.load(model, **load).q_graphs(**maps)``) and checks that
    it computes the data set's features and dimensions.
    """

    def __init__(self, features: str, node_dim: int, edge_dim: int) -> None:
        self.features, self.node_dim, self.edge_dim = features, node_dim, edge_dim
        self._maps: dict[str, Any] = {}

    def _q_graphs(self, a: TransitionAssembly) -> QGraphs:
        if a.name in self._maps:
            return self._maps[a.name]
        import asp

        where = f"{a.model} (assembly '{a.name}' of {a.dir.parent})"
        try:
            qg = asp.load(a.model, **a.load).q_graphs(**a.maps)
        except (asp.AspError, TypeError, ValueError, OSError) as err:
            raise DataError(f"{where}: cannot rebuild its state graphs: {err}") from None
        if (qg.features, qg.node_dim, qg.edge_dim) != (self.features, self.node_dim, self.edge_dim):
            raise DataError(
                f"{where}: asp computes features '{qg.features}' ({qg.node_dim}/{qg.edge_dim}), "
                f"the data set has '{self.features}' ({self.node_dim}/{self.edge_dim})"
            )
        self._maps[a.name] = qg
        return qg

    def __call__(self, a: TransitionAssembly, present: np.ndarray, actions: np.ndarray, history: np.ndarray) -> GraphLike:
        import asp

        qg = self._q_graphs(a)
        try:
            return qg.graph([int(p) for p in present], actions=[int(p) for p in actions], history=[int(h) for h in history])
        except (asp.AspError, ValueError) as err:
            raise DataError(f"{a.transitions_path}: a state of assembly '{a.name}' has no graph: {err}") from None


class GraphCache:
    """Memoises a graph source (least recently used, ``capacity`` graphs) and checks its output."""

    def __init__(self, source: GraphSource, node_dim: int, edge_dim: int, capacity: int = 512) -> None:
        self.source, self.node_dim, self.edge_dim, self.capacity = source, node_dim, edge_dim, capacity
        self._graphs: OrderedDict[tuple, GraphLike] = OrderedDict()
        self.calls = 0
        self.hits = 0

    def __call__(self, a: TransitionAssembly, present: np.ndarray, actions: np.ndarray, history: np.ndarray) -> GraphLike:
        key = (a.name, present.tobytes(), actions.tobytes(), history.tobytes())
        self.calls += 1
        g = self._graphs.get(key)
        if g is not None:
            self.hits += 1
            self._graphs.move_to_end(key)
            return g
        g = self.source(a, present, actions, history)
        n, e = g.x.shape[0], g.edge_index.shape[1]
        if (
            g.x.shape != (n, self.node_dim)
            or g.edge_index.shape != (2, e)
            or g.edge_attr.shape != (e, self.edge_dim)
            or g.nodes.shape != (n,)
        ):
            raise DataError(
                f"{a.transitions_path}: the graph source returned x {list(g.x.shape)}, edge_index "
                f"{list(g.edge_index.shape)}, edge_attr {list(g.edge_attr.shape)}, nodes {list(g.nodes.shape)} "
                f"for node_dim {self.node_dim}, edge_dim {self.edge_dim}"
            )
        self._graphs[key] = g
        if len(self._graphs) > self.capacity:
            self._graphs.popitem(last=False)
        return g


def _positions(g: GraphLike, parts: np.ndarray, a: TransitionAssembly) -> np.ndarray:
    """Node positions of ``parts`` in ``g`` (part nodes ascend, the context node is -1)."""
    nodes = np.asarray(g.nodes)
    real = np.flatnonzero(nodes >= 0)
    at = np.searchsorted(nodes[real], parts)
    at = np.minimum(at, max(len(real) - 1, 0))
    if len(real) == 0 or np.any(nodes[real][at] != parts):
        missing = [int(p) for p in parts if p not in set(nodes.tolist())]
        raise DataError(f"{a.transitions_path}: the graph of a state has no node for part {missing[0]} (assembly '{a.name}')")
    return real[at]
