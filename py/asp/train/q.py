"""Q-functions learned by deep Q-learning (thesis 5.4.4 and 6.4.4), exported to ONNX.

The model (:class:`QNetwork`): node embeddings ``h`` by the GNN of 3.5.2 (the layers of
:class:`~asp.train.gnn.RemovabilityGNN`, without its ``log1p`` input transform: the ``asp-q/1``
features lie in [0, 1]; they are standardised with training statistics stored as buffers), then
one value per node::

    q_i = phi_Q([h_i, hbar]),   hbar = sum_j x[j, 0] h_j / max(sum_j x[j, 0], 1)

``phi_Q`` a two-layer ReLU MLP. ``x[:, 0]`` is 1 for every real node and 0 for the padding rows
asp-learn appends, so padding changes no real output (docs/learning.md, "Q models"). In a training
batch (graphs concatenated with offsets) ``hbar`` is pooled per graph.

Deep Q-learning (:func:`train_q`): transitions stream in from ``asp-transitions`` data sets
(:mod:`asp.qdata`) into a replay buffer (10,000 by default; a data set that fits is read once,
a larger one streams through it, round robin over the assemblies, ``batch / 8`` new transitions
per step, so each is sampled about eight times while it is in the buffer); every step samples a
batch uniformly, and regresses ``Q(s, a)`` on ``y = r~ + max_{a' in next_actions} Q_target(s', a')``
(no bootstrap when ``next_actions`` is empty) with a Huber or squared loss and Adam; the target
network is a copy of the trained one, synced every ``target_sync`` steps. ``r~`` is the contract's
normalised reward of the chosen objective. Seeded: the same data, seed, settings and thread count
give the same model (when the run is bounded by ``steps``, not by ``seconds``).

State graphs are not stored in the data set: a *graph source* computes them from each
assembly's model, by default :class:`BindingGraphs` (the Rust code of the search, through
``asp.load(model, **load).q_graphs(**maps)``). Any callable
``source(assembly, present, actions, history)`` returning an object with ``nodes`` (int64 part
index per node, -1 for the context node), ``x``, ``edge_index`` and ``edge_attr`` will do (the
tests use :func:`synthetic_q_graph`-style fakes).
"""

from __future__ import annotations

import copy
import math
import re
import time
from collections import OrderedDict
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Protocol, Sequence

import numpy as np
import torch
from torch import Tensor, nn

from ..qdata import DataError, Transition, TransitionAssembly, TransitionDataset
from .export import export_onnx
from .gnn import RemovabilityGNN
from .trainer import _seed_everything

__all__ = [
    "QNetwork",
    "QConfig",
    "QAssembly",
    "GraphSource",
    "BindingGraphs",
    "GraphCache",
    "open_q_assemblies",
    "train_q",
    "DeepQLearner",
    "save_q_weights",
    "load_q_weights",
    "ranking_quality",
    "export_q",
    "synthetic_q_graph",
    "SyntheticGraph",
    "parse_q_features",
    "PARITY_PARTS",
    "PARITY_PADDING",
    "MIN_STD",
]

#: Standard deviations of input columns are floored at this value: ``asp-q/1`` features lie in
#: [0, 1], and a column that barely varied in training would otherwise be scaled by a huge factor.
MIN_STD = 1e-2
#: Parts of the synthetic graphs the export checks parity on (sizes no training batch is made of).
PARITY_PARTS = (1, 2, 13, 57, 91)
#: ``(nodes, edges)`` of padding appended in the parity check (real outputs must not change).
PARITY_PADDING = (5, 7)


# -- the model -----------------------------------------------------------------------------------
class QNetwork(RemovabilityGNN):
    """``forward(x [n, node_dim], edge_index int64 [2, e], edge_attr [e, edge_dim]) -> q [n]``.

    The GNN layers, their parameters and the standardisation buffers are
    :class:`RemovabilityGNN`'s (so :func:`~asp.train.export.export_onnx` exports it); the removability
    head is replaced by ``phi_Q`` over ``[h_i, hbar]``.
    """

    def __init__(self, node_dim: int, edge_dim: int, width: int = 64, layers: int = 3, aggregation: str = "scatter") -> None:
        super().__init__(node_dim, edge_dim, width=width, layers=layers, aggregation=aggregation, log1p_node=0, log1p_edge=0)
        self.head = None  # no removability head
        self.phi_q = nn.Sequential(nn.Linear(2 * width, width), nn.ReLU(), nn.Linear(width, 1))

    def _log1p(self, v: Tensor, mask: Tensor) -> Tensor:
        return v  # Q features are in [0, 1]: standardisation only

    @torch.no_grad()
    def fit_normalisation(self, nodes: Tensor, edges: Tensor) -> None:
        """Mean and std per column of training attributes (std floored at :data:`MIN_STD`)."""
        super().fit_normalisation(nodes, edges)
        self.node_std.clamp_(min=MIN_STD)
        self.edge_std.clamp_(min=MIN_STD)

    def logits(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:  # pragma: no cover
        raise TypeError("a QNetwork has no removability logits; call it for Q-values")

    def forward(
        self,
        x: Tensor,
        edge_index: Tensor,
        edge_attr: Tensor,
        batch: Tensor | None = None,
        num_graphs: int | None = None,
    ) -> Tensor:
        """Q-values ``[n]``. ``batch`` (int64 ``[n]``, graph of each node; ``num_graphs`` graphs)
        pools per graph in a concatenated batch; without it the whole input is one graph."""
        h = self.embed(x, edge_index, edge_attr)
        w = x[:, :1]
        if batch is None:
            pooled = (w * h).sum(0, keepdim=True) / torch.clamp(w.sum(), min=1.0)
            pooled = pooled.expand_as(h)
        else:
            count = int(num_graphs if num_graphs is not None else int(batch.max()) + 1)
            sums = torch.zeros((count, h.shape[1]), dtype=h.dtype).index_add(0, batch, w * h)
            weights = torch.zeros((count, 1), dtype=h.dtype).index_add(0, batch, w)
            pooled = (sums / torch.clamp(weights, min=1.0)).index_select(0, batch)
        return self.phi_q(torch.cat([h, pooled], dim=1)).squeeze(1)


# -- graphs --------------------------------------------------------------------------------------
class GraphLike(Protocol):
    """What a graph source returns (``asp.Graph`` is one)."""

    nodes: np.ndarray
    x: np.ndarray
    edge_index: np.ndarray
    edge_attr: np.ndarray


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
        corner = np.stack([boxes[present, 1 if k & 1 else 0, 0], boxes[present, 1 if k & 2 else 0, 1], boxes[present, 1 if k & 4 else 0, 2]], 1)
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

    def _q_graphs(self, a: TransitionAssembly):
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


# -- data ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class QAssembly:
    """An assembly of a transitions data set with the column of the objective being learned."""

    assembly: TransitionAssembly
    """The assembly."""
    objective: int
    """The index of the objective in its data set's ``rewards``."""

    @property
    def name(self) -> str:
        """The assembly's name."""
        return self.assembly.name

    def reward(self, t: Transition) -> float:
        """``r~`` of the learned objective."""
        return self.assembly.normalised_reward(t, self.objective)


def open_q_assemblies(dirs: Sequence[str], objective: str) -> tuple[list[QAssembly], str, int, int]:
    """Open data sets for learning ``objective``. Returns ``(assemblies, features, node_dim, edge_dim)``.

    All data sets must share features and dimensions and hold the objective; assembly names must
    be unique across them.
    """
    if not dirs:
        raise DataError("no data set given")
    out: list[QAssembly] = []
    first: TransitionDataset | None = None
    for d in dirs:
        ds = TransitionDataset.open(d)
        if first is None:
            first = ds
        elif (ds.features, ds.node_dim, ds.edge_dim) != (first.features, first.node_dim, first.edge_dim):
            raise DataError(
                f"{ds.index_path}: features '{ds.features}' ({ds.node_dim}/{ds.edge_dim}) differ from "
                f"{first.index_path}'s '{first.features}' ({first.node_dim}/{first.edge_dim})"
            )
        k = ds.objective_index(objective)
        for a in ds.assemblies:
            if any(o.name == a.name for o in out):
                raise DataError(f"{ds.index_path}: assembly '{a.name}' also appears in an earlier data set")
            out.append(QAssembly(a, k))
    assert first is not None
    return out, first.features, first.node_dim, first.edge_dim


@dataclass(frozen=True)
class _Record:
    source: QAssembly
    t: Transition
    reward: float


def _stream(assemblies: Sequence[QAssembly]) -> Iterator[_Record]:
    """Transitions round robin over the assemblies, each file restarted when it ends (forever)."""
    live = [a for a in assemblies if a.assembly.num_transitions > 0]
    if not live:
        raise DataError("no transition to train on (" + ", ".join(a.name for a in assemblies) + ")")
    iters = [a.assembly.transitions() for a in live]
    while True:
        for k, a in enumerate(live):
            try:
                t = next(iters[k])
            except StopIteration:
                iters[k] = a.assembly.transitions()
                t = next(iters[k])
            yield _Record(a, t, a.reward(t))


class ReplayBuffer:
    """A ring of at most ``capacity`` transitions, sampled uniformly."""

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self.items: list[_Record] = []
        self._next = 0

    def __len__(self) -> int:
        return len(self.items)

    def push(self, record: _Record) -> None:
        if len(self.items) < self.capacity:
            self.items.append(record)
        else:
            self.items[self._next] = record
            self._next = (self._next + 1) % self.capacity

    def sample(self, rng: np.random.Generator, size: int) -> list[_Record]:
        return [self.items[int(k)] for k in rng.integers(0, len(self.items), size=size)]


@dataclass(frozen=True)
class _Batch:
    x: Tensor
    edge_index: Tensor
    edge_attr: Tensor
    batch: Tensor
    num_graphs: int


def _collate(graphs: Sequence[GraphLike]) -> tuple[_Batch, np.ndarray]:
    """Concatenate graphs (edge indices offset). Returns the batch and each graph's node offset."""
    offsets = np.zeros(len(graphs), dtype=np.int64)
    xs, eis, eas, ids = [], [], [], []
    at = 0
    for k, g in enumerate(graphs):
        offsets[k] = at
        xs.append(np.asarray(g.x, dtype=np.float32))
        eis.append(np.asarray(g.edge_index, dtype=np.int64) + at)
        eas.append(np.asarray(g.edge_attr, dtype=np.float32))
        ids.append(np.full(g.x.shape[0], k, dtype=np.int64))
        at += g.x.shape[0]
    return (
        _Batch(
            x=torch.from_numpy(np.concatenate(xs)),
            edge_index=torch.from_numpy(np.concatenate(eis, axis=1)),
            edge_attr=torch.from_numpy(np.concatenate(eas)),
            batch=torch.from_numpy(np.concatenate(ids)),
            num_graphs=len(graphs),
        ),
        offsets,
    )


def _run(model: QNetwork, graphs: Sequence[GraphLike]) -> tuple[Tensor, np.ndarray]:
    b, offsets = _collate(graphs)
    return model(b.x, b.edge_index, b.edge_attr, b.batch, b.num_graphs), offsets


# -- training ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class QConfig:
    """Deep Q-learning hyper-parameters."""

    steps: int = 2000
    """Gradient steps (at most)."""
    seconds: float | None = None
    """Stop after this many seconds of training (checked after every step)."""
    batch: int = 128
    """Transitions per step."""
    buffer: int = 10_000
    """Replay buffer capacity."""
    lr: float = 1e-3
    """Adam's learning rate."""
    seed: int = 0
    """Seeds the weights and the sampling."""
    layers: int = 3
    """GNN layers."""
    width: int = 64
    """Hidden width."""
    threads: int = 1
    """PyTorch CPU threads (results are reproducible for one thread count)."""
    target_sync: int = 100
    """Steps between copies of the trained network into the target network."""
    loss: str = "huber"
    """``"huber"`` (smooth L1, delta 1) or ``"mse"``."""
    cache: int = 512
    """State graphs kept in memory (least recently used)."""
    normalisation_states: int = 256
    """Transitions of the initial buffer whose state graphs give the input statistics."""


def _fit_inputs(model: QNetwork, buffer: ReplayBuffer, graphs: GraphCache, rng: np.random.Generator, count: int) -> None:
    picks = rng.choice(len(buffer), size=min(count, len(buffer)), replace=False)
    gs = [graphs(r.source.assembly, r.t.present, r.t.actions, r.t.history) for r in (buffer.items[int(k)] for k in np.sort(picks))]
    model.fit_normalisation(
        torch.from_numpy(np.concatenate([g.x for g in gs]).astype(np.float32)),
        torch.from_numpy(np.concatenate([g.edge_attr for g in gs]).astype(np.float32)),
    )


def _loss_curve(losses: list[float], points: int = 20) -> list[dict]:
    if not losses:
        return []
    size = max(1, math.ceil(len(losses) / points))
    return [
        {"steps": min(k + size, len(losses)), "loss": float(np.mean(losses[k : k + size]))}
        for k in range(0, len(losses), size)
    ]


class DeepQLearner:
    """Deep Q-learning of one objective's Q-function, step by step: the network, its target copy,
    Adam, the replay buffer and the seeded sampling (thesis 5.4.4, 6.5.1).

    :func:`train_q` fills the buffer from data sets and runs ``config.steps`` steps; the online
    settings of 6.5 (:mod:`asp.train.online`) push each search episode's transitions and run a few
    steps after each episode. ``model`` continues training a network (the "retrained" setting; its
    input statistics are kept), else a new one is made (seeded) and :meth:`start` fits its input
    statistics on the buffer.
    """

    def __init__(
        self,
        node_dim: int,
        edge_dim: int,
        config: QConfig,
        graph_source: GraphSource,
        model: QNetwork | None = None,
    ) -> None:
        for name in ("steps", "batch", "buffer", "layers", "width", "threads", "target_sync", "cache"):
            if getattr(config, name) < 1:
                raise ValueError(f"{name} must be at least 1")
        if config.loss not in ("huber", "mse"):
            raise ValueError(f"loss must be 'huber' or 'mse', not {config.loss!r}")
        _seed_everything(config)
        self.config = config
        self.rng = np.random.default_rng(config.seed)
        self.graphs = GraphCache(graph_source, node_dim, edge_dim, capacity=config.cache)
        self.buffer = ReplayBuffer(config.buffer)
        self.fresh = model is None
        self.model = model if model is not None else QNetwork(node_dim, edge_dim, width=config.width, layers=config.layers)
        self.target: QNetwork | None = None
        self.optimiser: torch.optim.Optimizer | None = None
        self.loss_fn = nn.SmoothL1Loss(beta=1.0) if config.loss == "huber" else nn.MSELoss()
        self.losses: list[float] = []

    @property
    def steps(self) -> int:
        """Gradient steps run so far."""
        return len(self.losses)

    def push(self, source: QAssembly, t: Transition) -> None:
        """Adds a transition of ``source`` to the replay buffer (the oldest leaves when it is full)."""
        self.buffer.push(_Record(source, t, source.reward(t)))

    def start(self) -> None:
        """Fits a new network's input statistics on the buffer, then makes the target network and
        the optimiser (once, before the first step)."""
        if self.target is not None:
            return
        if self.fresh:
            _fit_inputs(self.model, self.buffer, self.graphs, self.rng, self.config.normalisation_states)
        self.target = copy.deepcopy(self.model).eval()
        for p in self.target.parameters():
            p.requires_grad_(False)
        self.optimiser = torch.optim.Adam(self.model.parameters(), lr=self.config.lr)

    def step(self) -> float:
        """One gradient step on a batch sampled from the buffer; returns its loss. The target
        network is synced every ``target_sync`` steps."""
        self.start()
        assert self.target is not None and self.optimiser is not None
        model, target = self.model, self.target
        model.train()
        records = self.buffer.sample(self.rng, self.config.batch)
        graphs = self.graphs
        states = [graphs(r.source.assembly, r.t.present, r.t.actions, r.t.history) for r in records]
        action_at = [int(_positions(g, np.array([r.t.action]), r.source.assembly)[0]) for g, r in zip(states, records)]
        rewards = torch.tensor([r.reward for r in records], dtype=torch.float32)
        going_on = [k for k, r in enumerate(records) if not r.t.terminal]
        bootstrap = torch.zeros(len(records), dtype=torch.float32)
        if going_on:
            nexts = [
                graphs(records[k].source.assembly, records[k].t.next_present, records[k].t.next_actions, records[k].t.next_history)
                for k in going_on
            ]
            with torch.no_grad():
                q_next, offsets = _run(target, nexts)
            at, owner = [], []
            for j, (k, g) in enumerate(zip(going_on, nexts)):
                pos = _positions(g, records[k].t.next_actions, records[k].source.assembly) + offsets[j]
                at.append(pos)
                owner.append(np.full(len(pos), k, dtype=np.int64))
            values = q_next.index_select(0, torch.from_numpy(np.concatenate(at)))
            best = torch.full((len(records),), -math.inf).scatter_reduce(
                0, torch.from_numpy(np.concatenate(owner)), values, reduce="amax", include_self=True
            )
            bootstrap = torch.where(torch.isfinite(best), best, torch.zeros_like(best))
        y = rewards + bootstrap
        q, offsets = _run(model, states)
        pred = q.index_select(0, torch.from_numpy(offsets + np.asarray(action_at, dtype=np.int64)))
        loss = self.loss_fn(pred, y)
        self.optimiser.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(model.parameters(), 10.0)
        self.optimiser.step()
        self.losses.append(float(loss.item()))
        if self.steps % self.config.target_sync == 0:
            target.load_state_dict(model.state_dict())
        model.eval()
        return self.losses[-1]


def train_q(
    assemblies: Sequence[QAssembly],
    node_dim: int,
    edge_dim: int,
    config: QConfig,
    graph_source: GraphSource,
    log: Callable[[str], None] | None = None,
) -> tuple[QNetwork, dict]:
    """Deep Q-learning on the transitions of ``assemblies``. Returns ``(model, summary)``.

    The summary holds the steps run, whether time stopped them, the seconds, the transitions read,
    the buffer size, the graph cache's hit rate and the loss curve (mean loss per twentieth).
    """
    learner = DeepQLearner(node_dim, edge_dim, config, graph_source)
    total = sum(a.assembly.num_transitions for a in assemblies)
    if total == 0:
        raise DataError("no transition to train on (" + ", ".join(a.name for a in assemblies) + ")")
    buffer = learner.buffer
    streaming = total > config.buffer
    if streaming:
        stream = _stream(assemblies)
        for _ in range(config.buffer):
            buffer.push(next(stream))
    else:  # everything fits: read each file once (to its end, which checks its count)
        for a in assemblies:
            for t in a.assembly.transitions():
                learner.push(a, t)
    read = len(buffer)
    ingest = max(1, config.batch // 8)
    if log:
        how = f"streaming {ingest} new per step" if streaming else "all of them"
        log(f"replay buffer: {len(buffer)} of {total} transitions ({how})")

    learner.start()
    start = time.monotonic()
    losses = learner.losses
    stopped = False
    for step in range(config.steps):
        if streaming:
            for _ in range(ingest):
                buffer.push(next(stream))
            read += ingest
        learner.step()
        if log and ((step + 1) % max(1, config.steps // 20) == 0 or step == 0):
            recent = float(np.mean(losses[-max(1, config.steps // 20) :]))
            log(f"step {step + 1}/{config.steps}: loss {recent:.3g} ({time.monotonic() - start:.1f} s)")
        if config.seconds is not None and time.monotonic() - start > config.seconds:
            stopped = True
            if log:
                log(f"stopped after {config.seconds:g} s at step {step + 1}")
            break
    model = learner.model
    model.eval()
    graphs = learner.graphs
    summary = {
        "steps": len(losses),
        "time_capped": stopped,
        "seconds": round(time.monotonic() - start, 3),
        "transitions": total,
        "transitions_read": read,
        "buffer": len(buffer),
        "graph_cache_hit_rate": round(graphs.hits / graphs.calls, 4) if graphs.calls else None,
        "final_loss": float(np.mean(losses[-max(1, len(losses) // 20) :])) if losses else math.nan,
        "loss_curve": _loss_curve(losses),
    }
    return model, summary


# -- evaluation ----------------------------------------------------------------------------------
@torch.no_grad()
def ranking_quality(
    model: QNetwork, source: QAssembly, graph_source: GraphSource, max_states: int = 2000, batch: int = 64
) -> dict:
    """How often the argmax-Q action of a state is the action with the best observed return-to-go.

    Transitions are chained in file order (same episode, each state the previous ``s'``) and each
    step's observed return-to-go is the sum of ``r~`` from it to the end of its chain. For every
    state (present parts and history; the first ``max_states`` met) the best return-to-go observed
    after each action is kept; states with at least two observed actions are scored: a hit when
    the action of highest ``Q`` among the observed ones has the best observed return-to-go (ties
    count). ``chance`` is the expected hit rate of a uniformly random choice; ``regret`` the mean
    shortfall of the chosen action's best return-to-go.
    """
    model.eval()
    states: dict[tuple, dict] = {}

    def flush(chain: list[tuple[Transition, float]]) -> None:
        g = 0.0
        for t, r in reversed(chain):
            g += r
            key = (t.present.tobytes(), t.history.tobytes())
            entry = states.get(key)
            if entry is None:
                if len(states) >= max_states:
                    continue
                entry = states[key] = {"t": t, "returns": {}}
            best = entry["returns"].get(t.action)
            entry["returns"][t.action] = g if best is None else max(best, g)

    chain: list[tuple[Transition, float]] = []
    for t in source.assembly.transitions():
        if chain:
            last = chain[-1][0]
            if (
                t.episode != last.episode
                or not np.array_equal(t.present, last.next_present)
                or not np.array_equal(t.history, last.next_history)
            ):
                flush(chain)
                chain = []
        chain.append((t, source.reward(t)))
        if t.terminal:
            flush(chain)
            chain = []
    flush(chain)

    scored = [e for e in states.values() if len(e["returns"]) >= 2]
    hits = 0
    chance = 0.0
    regret = 0.0
    cache = GraphCache(graph_source, model.node_dim, model.edge_dim, capacity=batch)
    for b in range(0, len(scored), batch):
        chunk = scored[b : b + batch]
        gs = [cache(source.assembly, e["t"].present, e["t"].actions, e["t"].history) for e in chunk]
        q, offsets = _run(model, gs)
        q = q.numpy()
        for e, g, off in zip(chunk, gs, offsets):
            acts = np.array(sorted(e["returns"]), dtype=np.int64)
            returns = np.array([e["returns"][int(a)] for a in acts])
            values = q[off + _positions(g, acts, source.assembly)]
            best = returns.max()
            chosen = returns[int(np.argmax(values))]
            hits += int(chosen >= best - 1e-9)
            chance += float(np.mean(returns >= best - 1e-9))
            regret += float(best - chosen)
    n = len(scored)
    return {
        "states": len(states),
        "scored": n,
        "accuracy": hits / n if n else None,
        "chance": chance / n if n else None,
        "regret": regret / n if n else None,
    }


# -- export --------------------------------------------------------------------------------------
def parity_graphs(node_dim: int, edge_dim: int, features: str, seed: int = 12345) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Synthetic ``asp-q/1`` graphs of :data:`PARITY_PARTS` parts for the export's parity check
    (the contract's layout when ``features`` names it and the dimensions agree; else uniform
    [0, 1] attributes with the real-node column set and random nearest-neighbour-like edges)."""
    rng = np.random.default_rng(seed)
    parsed = parse_q_features(features)
    out = []
    for parts in PARITY_PARTS:
        if parsed is not None and (node_dim, edge_dim) == (28 + 2 * parsed[0], 5 + 2 * parsed[0]):
            lo = rng.uniform(0.0, 1.0, size=(parts, 3))
            boxes = np.stack([lo, lo + rng.uniform(0.05, 0.5, size=(parts, 3))], axis=1)
            present = np.arange(parts)
            actions = present[rng.uniform(size=parts) < 0.5]
            history = np.flatnonzero(rng.uniform(size=parsed[0]) < 0.3)
            g = synthetic_q_graph(boxes, present, actions, history, parsed[0], parsed[1], rng=rng)
            out.append((g.x, g.edge_index, g.edge_attr))
        else:
            n = parts + 1
            x = rng.uniform(0.0, 1.0, size=(n, node_dim)).astype(np.float32)
            x[:, 0] = 1.0
            t = np.repeat(np.arange(n), min(8, n - 1)) if n > 1 else np.zeros(0, dtype=np.int64)
            s = (t + rng.integers(1, n, size=len(t))) % n if n > 1 else t
            edge_index = np.stack([s, t]).astype(np.int64).reshape(2, -1)
            edge_attr = rng.uniform(0.0, 1.0, size=(edge_index.shape[1], edge_dim)).astype(np.float32)
            out.append((x, edge_index, edge_attr))
    return out


def export_q(
    model: QNetwork,
    path: Path | str,
    features: str,
    objective: str,
    aggregation: str = "dense",
    tolerance: float = 1e-5,
) -> float:
    """Write a Q model (docs/learning.md, "Q models") and check it against PyTorch on
    :func:`parity_graphs`, each also padded by :data:`PARITY_PADDING`. Returns the largest
    difference."""
    diff = export_onnx(
        model,
        path,
        features,
        aggregation=aggregation,
        tolerance=tolerance,
        extra_metadata={"asp.objective": objective},
        kind="q",
        output_name="q",
        parity_graphs=parity_graphs(model.node_dim, model.edge_dim, features),
        padding=PARITY_PADDING,
    )
    assert diff is not None
    return diff


def save_q_weights(model: QNetwork, path: Path | str, features: str, objective: str) -> None:
    """Write the network's weights and shape beside its ONNX file (``q.onnx.pt``), so that a later
    run can retrain it (the "retrained" setting of 6.5, ``python -m asp.train q-online --q``)."""
    torch.save(
        {
            "state_dict": model.state_dict(),
            "node_dim": model.node_dim,
            "edge_dim": model.edge_dim,
            "width": model.width,
            "layers": model.layers,
            "aggregation": model.aggregation,
            "features": features,
            "objective": objective,
        },
        str(path),
    )


def load_q_weights(path: Path | str) -> tuple[QNetwork, str, str]:
    """The network :func:`save_q_weights` wrote, with its features and objective."""
    try:
        saved = torch.load(str(path), map_location="cpu", weights_only=True)
        model = QNetwork(saved["node_dim"], saved["edge_dim"], width=saved["width"], layers=saved["layers"], aggregation=saved["aggregation"])
        model.load_state_dict(saved["state_dict"])
    except FileNotFoundError:
        raise DataError(f"{path}: file not found (python -m asp.train q writes the weights beside the ONNX model)") from None
    except (KeyError, RuntimeError, OSError, ValueError) as err:
        raise DataError(f"{path}: not Q network weights written by asp.train: {err}") from None
    model.eval()
    return model, str(saved["features"]), str(saved["objective"])


def config_dict(config: QConfig) -> dict:
    """The settings as JSON-ready values."""
    return asdict(config)
