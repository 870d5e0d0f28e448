"""The graph encoder of thesis section 3.5.2, shared by the removability GNN and the Q network.

Per layer ``l`` (messages flow from the source ``s`` to the target ``t`` of an edge)::

    a_e'  = phi_e(a_t + a_e + a_s)                                    (3.14)
    m_e   = ReLU(a_t + a_e') + eps
    abar_t = sum_{e -> t} softmax_t(tau_l * m_e) * m_e                (3.15, learned softmax)
    a_t'  = phi_n(a_t + abar_t)                                       (3.16)

``phi_e`` and ``phi_n`` are two-layer, 64-unit ReLU MLPs shared by all layers; ``tau_l`` is a
learnable temperature per layer (torch_geometric's ``SoftmaxAggregation(learn=True)``, one channel).
Before the first layer, node attributes are mapped linearly to the width and edge attributes too
(the thesis' "linear transformation of the edge attributes"). The encoder ends at the node
embeddings; a model puts its head on them (:class:`~asp.train.gnn.RemovabilityGNN`: one
removability per node; :class:`~asp.train.q.QNetwork`: one Q-value per node).

Input normalisation is part of the encoder (buffers), so an exported ONNX file is self-contained:
``log(1 + v)`` of the leading ``log1p_node``/``log1p_edge`` attribute columns, then
``(v - mean) / std`` with the training set's statistics. With no ``log1p`` column on a side, that
side is only standardised (no ``Log`` op in the exported graph).

Aggregation comes in two interchangeable implementations with identical parameters and results:

* ``"scatter"`` (training default): ``index_add`` in PyTorch; it exports to ONNX ``ScatterND``
  with ``reduction="add"`` (opset 16+), which tract 0.23 evaluates row by row.
* ``"dense"``: a one-hot incidence matrix ``[e, n]`` built with ``Equal``/``Cast`` and sums as
  ``MatMul``; only elementary ops, at ``O(e * n * width)`` cost, yet the faster of the two in
  tract for states of up to a few hundred edges (``python -m asp.train`` exports it by default).

The softmax is shifted per target and channel by the mean of the target's scores (computed with
the same sums), which keeps the largest term of every target at ``exp(>= 0)`` so a denominator is
never below 1; shifted scores are clamped at :data:`SCORE_CLAMP` so ``exp`` cannot overflow (the
clamp only changes results where one score exceeds its target's mean by more than 50, where the
softmax is one-hot to float precision anyway). Nodes without incoming edges aggregate to 0, and
``e = 0`` works.
"""

from __future__ import annotations

from typing import Any

import torch
from torch import Tensor, nn

__all__ = ["GraphEncoder", "EncodedModel", "SCORE_CLAMP", "EPS", "AGGREGATIONS"]

#: Shifted softmax scores are clamped at this value before ``exp``.
SCORE_CLAMP = 50.0
#: The small constant added to messages (thesis eq. 3.15).
EPS = 1e-7
#: The aggregation implementations.
AGGREGATIONS = ("scatter", "dense")


class _ScatterAdd(torch.autograd.Function):
    """``zeros(n, c).index_add(0, index, values)``, exported as ONNX ``ScatterND(add)``."""

    @staticmethod
    def forward(ctx: Any, values: Tensor, index: Tensor, zeros: Tensor) -> Tensor:
        ctx.save_for_backward(index)
        return zeros.index_add(0, index, values)

    @staticmethod
    def backward(ctx: Any, grad: Tensor) -> tuple[Tensor, None, None]:
        (index,) = ctx.saved_tensors
        return grad.index_select(0, index), None, None

    @staticmethod
    def symbolic(g: Any, values: Any, index: Any, zeros: Any) -> Any:  # pragma: no cover - exercised by the ONNX export
        idx = g.op("Unsqueeze", index, g.op("Constant", value_t=torch.tensor([1], dtype=torch.int64)))
        return g.op("ScatterND", zeros, idx, values, reduction_s="add")


def _mlp(width: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(width, width), nn.ReLU(), nn.Linear(width, width))


class GraphEncoder(nn.Module):
    """Node embeddings of a state graph: ``forward(x [n, node_dim], edge_index int64 [2, e],
    edge_attr [e, edge_dim]) -> h [n, width]`` after ``layers`` message-passing layers."""

    node_log_mask: Tensor
    edge_log_mask: Tensor
    node_mean: Tensor
    node_std: Tensor
    edge_mean: Tensor
    edge_std: Tensor

    def __init__(
        self,
        node_dim: int,
        edge_dim: int,
        width: int = 64,
        layers: int = 3,
        aggregation: str = "scatter",
        log1p_node: int | None = None,
        log1p_edge: int | None = None,
    ) -> None:
        """A freshly initialised encoder (use ``torch.manual_seed`` first for reproducibility).

        ``log1p_node``/``log1p_edge`` are how many leading attributes are descriptor entries that
        get ``log1p`` (default: all but the last two, as in the removability contract; 0: none).
        """
        super().__init__()
        if node_dim < 1 or edge_dim < 1 or width < 1 or layers < 1:
            raise ValueError("node_dim, edge_dim, width and layers must be positive")
        self.node_dim = node_dim
        self.edge_dim = edge_dim
        self.width = width
        self.layers = layers
        self.set_aggregation(aggregation)
        self.register_buffer("node_log_mask", _log_mask(node_dim, log1p_node))
        self.register_buffer("edge_log_mask", _log_mask(edge_dim, log1p_edge))
        # decided once here, so the traced (exported) graph has no Log op on a side without log1p
        self._node_log = bool(self.node_log_mask.any())
        self._edge_log = bool(self.edge_log_mask.any())
        self.register_buffer("node_mean", torch.zeros(node_dim))
        self.register_buffer("node_std", torch.ones(node_dim))
        self.register_buffer("edge_mean", torch.zeros(edge_dim))
        self.register_buffer("edge_std", torch.ones(edge_dim))
        self.node_encoder = nn.Linear(node_dim, width)
        self.edge_encoder = nn.Linear(edge_dim, width)
        self.phi_e = _mlp(width)
        self.phi_n = _mlp(width)
        self.temperature = nn.Parameter(torch.ones(layers))

    def set_aggregation(self, aggregation: str) -> None:
        """Choose the aggregation implementation (``"scatter"`` or ``"dense"``); same results."""
        if aggregation not in AGGREGATIONS:
            raise ValueError(f"aggregation must be one of {AGGREGATIONS}, not {aggregation!r}")
        self.aggregation = aggregation

    # -- normalisation -------------------------------------------------------------------------
    @staticmethod
    def _log1p(v: Tensor, mask: Tensor) -> Tensor:
        # ``log(1 + v)``, not ``torch.log1p``: ONNX has no Log1p, so the export computes
        # Log(Add(1, v)), which for the small descriptor entries differs from the correctly
        # rounded log1p by up to ulp(1) / v relative; divided by a column's small std that gave
        # ONNX/PyTorch differences of 1e-4 on the trained model. The same two float32 operations
        # in both keep the parity at float rounding (1e-6).
        return torch.where(mask, torch.log(1.0 + torch.clamp(v, min=0.0)), v)

    def normalise_nodes(self, x: Tensor) -> Tensor:
        """Node attributes as the first layer sees them (``log1p`` columns, then standardised)."""
        if self._node_log:
            x = self._log1p(x, self.node_log_mask)
        return (x - self.node_mean) / self.node_std

    def normalise_edges(self, edge_attr: Tensor) -> Tensor:
        """Edge attributes as the first layer sees them (``log1p`` columns, then standardised)."""
        if self._edge_log:
            edge_attr = self._log1p(edge_attr, self.edge_log_mask)
        return (edge_attr - self.edge_mean) / self.edge_std

    @torch.no_grad()
    def fit_normalisation(self, nodes: Tensor, edges: Tensor, min_std: float | None = None) -> None:
        """Set the input statistics from training attributes ``nodes [*, node_dim]`` and
        ``edges [*, edge_dim]`` (mean and std after ``log1p``; a constant column gets std 1, and
        with ``min_std`` every std is at least that)."""
        for v, mask, mean, std in (
            (nodes, self.node_log_mask, self.node_mean, self.node_std),
            (edges, self.edge_log_mask, self.edge_mean, self.edge_std),
        ):
            if v.shape[0] == 0:
                mean.zero_()
                std.fill_(1.0)
            else:
                t = self._log1p(v.to(torch.float64), mask)
                m = t.mean(0)
                s = t.std(0, unbiased=False) if t.shape[0] > 1 else torch.zeros_like(m)
                mean.copy_(m.to(mean.dtype))
                std.copy_(torch.where(s > 1e-6, s, torch.ones_like(s)).to(std.dtype))
            if min_std is not None:
                std.clamp_(min=min_std)

    # -- aggregation ---------------------------------------------------------------------------
    def _sum_to_targets(self, values: Tensor, target: Tensor, onehot: Tensor | None, n: int) -> Tensor:
        if onehot is not None:
            return torch.matmul(onehot.transpose(0, 1), values)
        zeros = torch.zeros((n, values.shape[1]), dtype=values.dtype, device=values.device)
        return _ScatterAdd.apply(values, target, zeros)

    def _aggregate(self, m: Tensor, target: Tensor, onehot: Tensor | None, inv_count: Tensor, n: int, tau: Tensor) -> Tensor:
        score = m * tau
        mean = self._sum_to_targets(score, target, onehot, n) * inv_count  # [n, c]
        shifted = torch.clamp(score - mean.index_select(0, target), max=SCORE_CLAMP)
        w = torch.exp(shifted)
        sums = self._sum_to_targets(torch.cat([w * m, w], dim=1), target, onehot, n)
        numerator, denominator = sums[:, : self.width], sums[:, self.width :]
        # every target with an incoming edge has a denominator >= 1; the others sum to 0 / 1 = 0
        return numerator / torch.clamp(denominator, min=1.0)

    # -- forward -------------------------------------------------------------------------------
    def forward(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """The node embeddings ``[n, width]`` after the last layer."""
        h = self.node_encoder(self.normalise_nodes(x))
        a_e = self.edge_encoder(self.normalise_edges(edge_attr))
        source, target = edge_index[0], edge_index[1]
        n = x.shape[0]
        if self.aggregation == "dense":
            nodes = torch.arange(n, dtype=torch.int64, device=x.device)
            onehot: Tensor | None = (target.unsqueeze(1) == nodes.unsqueeze(0)).to(h.dtype)  # [e, n]
            assert onehot is not None
            count = onehot.sum(0).unsqueeze(1)
        else:
            onehot = None
            ones = torch.ones_like(target, dtype=h.dtype).unsqueeze(1)
            count = self._sum_to_targets(ones, target, None, n)
        inv_count = 1.0 / torch.clamp(count, min=1.0)  # [n, 1]
        for layer in range(self.layers):
            h_t = h.index_select(0, target)
            a_e = self.phi_e(h_t + a_e + h.index_select(0, source))
            m = torch.relu(h_t + a_e) + EPS
            h = self.phi_n(h + self._aggregate(m, target, onehot, inv_count, n, self.temperature[layer]))
        return h


class EncodedModel(nn.Module):
    """A model made of a :class:`GraphEncoder` (``self.encoder``) and a head of its own.

    It answers for its encoder's shape (``node_dim``, ``edge_dim``, ``width``, ``layers``,
    ``aggregation``, :meth:`set_aggregation`), which is what :func:`~asp.train.export.export_onnx`
    and the weight files read, and it loads state dicts written before the encoder was its own
    module (the encoder's keys without the ``encoder.`` prefix).
    """

    encoder: GraphEncoder

    def __init__(self, encoder: GraphEncoder) -> None:
        """Wraps ``encoder``; a subclass adds its head after this call."""
        super().__init__()
        self.encoder = encoder
        self.register_load_state_dict_pre_hook(_prefix_encoder_keys)

    @property
    def node_dim(self) -> int:
        """Node attributes per node."""
        return self.encoder.node_dim

    @property
    def edge_dim(self) -> int:
        """Edge attributes per edge."""
        return self.encoder.edge_dim

    @property
    def width(self) -> int:
        """Hidden width."""
        return self.encoder.width

    @property
    def layers(self) -> int:
        """Message-passing layers."""
        return self.encoder.layers

    @property
    def aggregation(self) -> str:
        """The aggregation implementation (``"scatter"`` or ``"dense"``)."""
        return self.encoder.aggregation

    def set_aggregation(self, aggregation: str) -> None:
        """Choose the encoder's aggregation implementation; same results."""
        self.encoder.set_aggregation(aggregation)

    def embed(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """The node embeddings ``[n, width]`` (the encoder's output, before the head)."""
        return self.encoder(x, edge_index, edge_attr)


#: The top-level names in a :class:`GraphEncoder`'s state dict.
_ENCODER_KEYS = frozenset(
    (
        "node_log_mask", "edge_log_mask", "node_mean", "node_std", "edge_mean", "edge_std",
        "node_encoder", "edge_encoder", "phi_e", "phi_n", "temperature",
    )
)


def _prefix_encoder_keys(module: nn.Module, state_dict: dict[str, Any], prefix: str, *_: Any) -> None:
    """Moves an old flat state dict's encoder entries (``node_encoder.weight``, ``node_mean``, ...)
    under ``encoder.``, in place (the state dicts of models saved before the encoder was its own
    module)."""
    for key in list(state_dict):
        if key.startswith(prefix) and key[len(prefix) :].split(".", 1)[0] in _ENCODER_KEYS:
            state_dict[f"{prefix}encoder.{key[len(prefix):]}"] = state_dict.pop(key)


def _log_mask(dim: int, leading: int | None) -> Tensor:
    if leading is None:
        leading = max(dim - 2, 0)
    if not 0 <= leading <= dim:
        raise ValueError(f"log1p column count {leading} is outside 0..{dim}")
    mask = torch.zeros(dim, dtype=torch.bool)
    mask[:leading] = True
    return mask
