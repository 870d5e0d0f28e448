"""The removability GNN of thesis section 3.5.2, written to export to ONNX for tract.

Per layer ``l`` (messages flow from the source ``s`` to the target ``t`` of an edge)::

    a_e'  = phi_e(a_t + a_e + a_s)                                    (3.14)
    m_e   = ReLU(a_t + a_e') + eps
    abar_t = sum_{e -> t} softmax_t(tau_l * m_e) * m_e                (3.15, learned softmax)
    a_t'  = phi_n(a_t + abar_t)                                       (3.16)

``phi_e`` and ``phi_n`` are two-layer, 64-unit ReLU MLPs shared by all layers; ``tau_l`` is a
learnable temperature per layer (torch_geometric's ``SoftmaxAggregation(learn=True)``, one channel).
Before the first layer, node attributes are mapped linearly to the width and edge attributes too
(the thesis' "linear transformation of the edge attributes"); after the last, a linear head and a
sigmoid give one removability per node.

Input normalisation is part of the model (buffers), so an exported ONNX file is self-contained:
``log(1 + v)`` of the shape-descriptor entries (every attribute but the last two, which are flags or
cosines by the contract), then ``(v - mean) / std`` with the training set's statistics.

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

import torch
from torch import Tensor, nn

__all__ = ["RemovabilityGNN", "SCORE_CLAMP", "EPS", "AGGREGATIONS"]

#: Shifted softmax scores are clamped at this value before ``exp``.
SCORE_CLAMP = 50.0
#: The small constant added to messages (thesis eq. 3.15).
EPS = 1e-7
#: The aggregation implementations.
AGGREGATIONS = ("scatter", "dense")


class _ScatterAdd(torch.autograd.Function):
    """``zeros(n, c).index_add(0, index, values)``, exported as ONNX ``ScatterND(add)``."""

    @staticmethod
    def forward(ctx, values: Tensor, index: Tensor, zeros: Tensor) -> Tensor:  # type: ignore[override]
        ctx.save_for_backward(index)
        return zeros.index_add(0, index, values)

    @staticmethod
    def backward(ctx, grad: Tensor):  # type: ignore[override]
        (index,) = ctx.saved_tensors
        return grad.index_select(0, index), None, None

    @staticmethod
    def symbolic(g, values, index, zeros):  # pragma: no cover - exercised by the ONNX export
        idx = g.op("Unsqueeze", index, g.op("Constant", value_t=torch.tensor([1], dtype=torch.int64)))
        return g.op("ScatterND", zeros, idx, values, reduction_s="add")


def _mlp(width: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(width, width), nn.ReLU(), nn.Linear(width, width))


class RemovabilityGNN(nn.Module):
    """Predicts, for every node of a state graph, the probability that its part is removable.

    ``forward(x [n, node_dim], edge_index int64 [2, e], edge_attr [e, edge_dim]) -> [n]`` in
    (0, 1); :meth:`logits` gives the pre-sigmoid values (for a numerically stable loss).
    """

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
        """A freshly initialised model (use ``torch.manual_seed`` first for reproducibility).

        ``log1p_node``/``log1p_edge`` are how many leading attributes are descriptor entries that
        get ``log1p`` (default: all but the last two, as in the contract).
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
        self.register_buffer("node_mean", torch.zeros(node_dim))
        self.register_buffer("node_std", torch.ones(node_dim))
        self.register_buffer("edge_mean", torch.zeros(edge_dim))
        self.register_buffer("edge_std", torch.ones(edge_dim))
        self.node_encoder = nn.Linear(node_dim, width)
        self.edge_encoder = nn.Linear(edge_dim, width)
        self.phi_e = _mlp(width)
        self.phi_n = _mlp(width)
        self.temperature = nn.Parameter(torch.ones(layers))
        self.head = nn.Linear(width, 1)

    def set_aggregation(self, aggregation: str) -> None:
        """Choose the aggregation implementation (``"scatter"`` or ``"dense"``); same results."""
        if aggregation not in AGGREGATIONS:
            raise ValueError(f"aggregation must be one of {AGGREGATIONS}, not {aggregation!r}")
        self.aggregation = aggregation

    # -- normalisation -------------------------------------------------------------------------
    def _log1p(self, v: Tensor, mask: Tensor) -> Tensor:
        # ``log(1 + v)``, not ``torch.log1p``: ONNX has no Log1p, so the export computes
        # Log(Add(1, v)), which for the small descriptor entries differs from the correctly
        # rounded log1p by up to ulp(1) / v relative; divided by a column's small std that gave
        # ONNX/PyTorch differences of 1e-4 on the trained model. The same two float32 operations
        # in both keep the parity at float rounding (1e-6).
        return torch.where(mask, torch.log(1.0 + torch.clamp(v, min=0.0)), v)

    @torch.no_grad()
    def fit_normalisation(self, nodes: Tensor, edges: Tensor) -> None:
        """Set the input statistics from training attributes ``nodes [*, node_dim]`` and
        ``edges [*, edge_dim]`` (mean and std after ``log1p``; a constant column gets std 1)."""
        for v, mask, mean, std in (
            (nodes, self.node_log_mask, self.node_mean, self.node_std),
            (edges, self.edge_log_mask, self.edge_mean, self.edge_std),
        ):
            if v.shape[0] == 0:
                mean.zero_()
                std.fill_(1.0)
                continue
            t = self._log1p(v.to(torch.float64), mask)
            m = t.mean(0)
            s = t.std(0, unbiased=False) if t.shape[0] > 1 else torch.zeros_like(m)
            mean.copy_(m.to(mean.dtype))
            std.copy_(torch.where(s > 1e-6, s, torch.ones_like(s)).to(std.dtype))

    # -- aggregation ---------------------------------------------------------------------------
    def _sum_to_targets(self, values: Tensor, target: Tensor, onehot: Tensor | None, n: Tensor | int) -> Tensor:
        if onehot is not None:
            return torch.matmul(onehot.transpose(0, 1), values)
        zeros = torch.zeros((n, values.shape[1]), dtype=values.dtype, device=values.device)
        return _ScatterAdd.apply(values, target, zeros)

    def _aggregate(
        self, m: Tensor, target: Tensor, onehot: Tensor | None, inv_count: Tensor, n, tau: Tensor
    ) -> Tensor:
        score = m * tau
        mean = self._sum_to_targets(score, target, onehot, n) * inv_count  # [n, c]
        shifted = torch.clamp(score - mean.index_select(0, target), max=SCORE_CLAMP)
        w = torch.exp(shifted)
        sums = self._sum_to_targets(torch.cat([w * m, w], dim=1), target, onehot, n)
        numerator, denominator = sums[:, : self.width], sums[:, self.width :]
        # every target with an incoming edge has a denominator >= 1; the others sum to 0 / 1 = 0
        return numerator / torch.clamp(denominator, min=1.0)

    # -- forward -------------------------------------------------------------------------------
    def embed(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """The node embeddings ``[n, width]`` after the last layer (before the head); the
        Q-function of :mod:`asp.train.q` builds on them."""
        x = (self._log1p(x, self.node_log_mask) - self.node_mean) / self.node_std
        a_e = (self._log1p(edge_attr, self.edge_log_mask) - self.edge_mean) / self.edge_std
        h = self.node_encoder(x)
        a_e = self.edge_encoder(a_e)
        source, target = edge_index[0], edge_index[1]
        n = x.shape[0]
        if self.aggregation == "dense":
            nodes = torch.arange(n, dtype=torch.int64, device=x.device)
            onehot = (target.unsqueeze(1) == nodes.unsqueeze(0)).to(h.dtype)  # [e, n]
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

    def logits(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """Pre-sigmoid removability ``[n]``."""
        return self.head(self.embed(x, edge_index, edge_attr)).squeeze(1)

    def forward(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """Removability ``[n]`` in (0, 1)."""
        return torch.sigmoid(self.logits(x, edge_index, edge_attr))


def _log_mask(dim: int, leading: int | None) -> Tensor:
    if leading is None:
        leading = max(dim - 2, 0)
    if not 0 <= leading <= dim:
        raise ValueError(f"log1p column count {leading} is outside 0..{dim}")
    mask = torch.zeros(dim, dtype=torch.bool)
    mask[:leading] = True
    return mask
