"""Q-functions learned by deep Q-learning (thesis 5.4.4 and 6.4.4), exported to ONNX.

The package's modules: :mod:`~asp.train.q.network` (the model), :mod:`~asp.train.q.graphs` (graph
sources and their cache), :mod:`~asp.train.q.replay` (data sets, replay buffer, batching),
:mod:`~asp.train.q.learner` (deep Q-learning), :mod:`~asp.train.q.evaluate` (ranking quality),
:mod:`~asp.train.q.distill` (a smaller network fitted to a trained one) and
:mod:`~asp.train.q.export` (ONNX files and weights). Everything is importable from
``asp.train.q`` itself.

The model (:class:`QNetwork`): node embeddings ``h`` by the GNN of 3.5.2 (the
:class:`~asp.train.encoder.GraphEncoder` that :class:`~asp.train.gnn.RemovabilityGNN` is built on
too, without its ``log1p`` input transform: the ``asp-q/1`` features lie in [0, 1]; they are
standardised with training statistics stored as buffers), then one value per node::

    q_i = phi_Q([h_i, hbar]),   hbar = sum_j x[j, 0] h_j / max(sum_j x[j, 0], 1)

``phi_Q`` a two-layer ReLU MLP. ``x[:, 0]`` is 1 for every real node and 0 for the padding rows
asp-learn appends, so padding changes no real output (docs/learning.md, "Q models"). In a training
batch (graphs concatenated with offsets) ``hbar`` is pooled per graph.

Deep Q-learning (:func:`train_q`): transitions stream in from ``asp-transitions`` data sets
(:mod:`asp.datasets.transitions`) into a replay buffer (10,000 by default; a data set that fits
is read once, a larger one streams through it, round robin over the assemblies, ``batch / 8`` new
transitions per step, so each is sampled about eight times while it is in the buffer); every step
samples a batch uniformly, and regresses ``Q(s, a)`` on ``y = r~ + max_{a' in next_actions} Q_target(s', a')``
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

# the data-set names the module used to import (``asp.train.q.TransitionDataset`` keeps working)
from ...datasets.transitions import DataError as DataError
from ...datasets.transitions import Transition as Transition
from ...datasets.transitions import TransitionAssembly as TransitionAssembly
from ...datasets.transitions import TransitionDataset as TransitionDataset
from .distill import DistillConfig, DistillState, distill_q, ranking_kept, sample_states
from .evaluate import ranking_quality
from .export import PARITY_PADDING, PARITY_PARTS, export_q, load_q_weights, parity_graphs, save_q_weights
from .graphs import (
    BindingGraphs,
    GraphCache,
    GraphLike,
    GraphSource,
    SyntheticGraph,
    parse_q_features,
    synthetic_q_graph,
)
from .learner import DeepQLearner, QConfig, QLearning, config_dict, train_q
from .network import MIN_STD, QNetwork
from .replay import QAssembly, ReplayBuffer, open_q_assemblies

__all__ = [
    "QNetwork",
    "QConfig",
    "QLearning",
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
    "GraphLike",
    "ReplayBuffer",
    "config_dict",
    "parity_graphs",
    "DistillConfig",
    "DistillState",
    "distill_q",
    "ranking_kept",
    "sample_states",
]
