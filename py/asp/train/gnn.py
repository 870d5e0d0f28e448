"""The removability GNN of thesis section 3.5.2, written to export to ONNX for tract.

The node embeddings come from the shared :class:`~asp.train.encoder.GraphEncoder` (the message
passing of eq. 3.14-3.16, the input normalisation and the two aggregation implementations are
documented there); after its last layer a linear head and a sigmoid give one removability per node.

Input normalisation is part of the model (the encoder's buffers), so an exported ONNX file is
self-contained: ``log(1 + v)`` of the shape-descriptor entries (every attribute but the last two,
which are flags or cosines by the contract), then ``(v - mean) / std`` with the training set's
statistics.
"""

from __future__ import annotations

import torch
from torch import Tensor, nn

from .encoder import AGGREGATIONS, EPS, SCORE_CLAMP, EncodedModel, GraphEncoder

__all__ = ["RemovabilityGNN", "GraphEncoder", "SCORE_CLAMP", "EPS", "AGGREGATIONS"]


class RemovabilityGNN(EncodedModel):
    """Predicts, for every node of a state graph, the probability that its part is removable.

    ``forward(x [n, node_dim], edge_index int64 [2, e], edge_attr [e, edge_dim]) -> [n]`` in
    (0, 1); :meth:`logits` gives the pre-sigmoid values (for a numerically stable loss). The
    model is a :class:`~asp.train.encoder.GraphEncoder` (``self.encoder``) and a linear ``head``.
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
        super().__init__(GraphEncoder(node_dim, edge_dim, width, layers, aggregation, log1p_node, log1p_edge))
        self.head = nn.Linear(width, 1)

    @torch.no_grad()
    def fit_normalisation(self, nodes: Tensor, edges: Tensor) -> None:
        """Set the input statistics from training attributes ``nodes [*, node_dim]`` and
        ``edges [*, edge_dim]`` (mean and std after ``log1p``; a constant column gets std 1)."""
        self.encoder.fit_normalisation(nodes, edges)

    def logits(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """Pre-sigmoid removability ``[n]``."""
        return self.head(self.embed(x, edge_index, edge_attr)).squeeze(1)

    def forward(self, x: Tensor, edge_index: Tensor, edge_attr: Tensor) -> Tensor:
        """Removability ``[n]`` in (0, 1)."""
        return torch.sigmoid(self.logits(x, edge_index, edge_attr))
