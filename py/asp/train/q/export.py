"""Q models as ONNX files (docs/learning.md, "Q models") with their parity check on synthetic
graphs, and the weights written beside them for retraining."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ...datasets.transitions import DataError
from ..export import export_onnx
from .graphs import parse_q_features, synthetic_q_graph
from .network import QNetwork

__all__ = ["PARITY_PARTS", "PARITY_PADDING", "parity_graphs", "export_q", "save_q_weights", "load_q_weights"]

#: Parts of the synthetic graphs the export checks parity on (sizes no training batch is made of).
PARITY_PARTS = (1, 2, 13, 57, 91)
#: ``(nodes, edges)`` of padding appended in the parity check (real outputs must not change).
PARITY_PADDING = (5, 7)


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
        model = QNetwork(
            saved["node_dim"], saved["edge_dim"], width=saved["width"], layers=saved["layers"], aggregation=saved["aggregation"]
        )
        model.load_state_dict(saved["state_dict"])
    except FileNotFoundError:
        raise DataError(f"{path}: file not found (python -m asp.train q writes the weights beside the ONNX model)") from None
    except (KeyError, RuntimeError, OSError, ValueError) as err:
        raise DataError(f"{path}: not Q network weights written by asp.train: {err}") from None
    model.eval()
    return model, str(saved["features"]), str(saved["objective"])
