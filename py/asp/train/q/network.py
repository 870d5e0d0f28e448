"""The Q network: the shared graph encoder and a head giving one Q-value per node."""

from __future__ import annotations

import torch
from torch import Tensor, nn

from ..encoder import EncodedModel, GraphEncoder

__all__ = ["QNetwork", "MIN_STD"]

#: Standard deviations of input columns are floored at this value: ``asp-q/1`` features lie in
#: [0, 1], and a column that barely varied in training would otherwise be scaled by a huge factor.
MIN_STD = 1e-2


class QNetwork(EncodedModel):
    """``forward(x [n, node_dim], edge_index int64 [2, e], edge_attr [e, edge_dim]) -> q [n]``.

    A :class:`~asp.train.encoder.GraphEncoder` (``self.encoder``, the layers of the removability
    GNN without its ``log1p`` input transform: ``asp-q/1`` features lie in [0, 1] and are only
    standardised) and the head ``phi_q``, a two-layer ReLU MLP over ``[h_i, hbar]`` with
    ``hbar = sum_j x[j, 0] h_j / max(sum_j x[j, 0], 1)`` (padding rows, ``x[:, 0] = 0``, change
    no real output).
    """

    def __init__(self, node_dim: int, edge_dim: int, width: int = 64, layers: int = 3, aggregation: str = "scatter") -> None:
        """A freshly initialised network (use ``torch.manual_seed`` first for reproducibility)."""
        super().__init__(GraphEncoder(node_dim, edge_dim, width, layers, aggregation, log1p_node=0, log1p_edge=0))
        self.phi_q = nn.Sequential(nn.Linear(2 * width, width), nn.ReLU(), nn.Linear(width, 1))

    @torch.no_grad()
    def fit_normalisation(self, nodes: Tensor, edges: Tensor) -> None:
        """Mean and std per column of training attributes (std floored at :data:`MIN_STD`)."""
        self.encoder.fit_normalisation(nodes, edges, min_std=MIN_STD)

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
