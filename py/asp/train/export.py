"""ONNX export of a :class:`~asp.train.gnn.RemovabilityGNN` (or any model built on the shared
:class:`~asp.train.encoder.GraphEncoder`, as the Q network is) as docs/learning.md specifies.

The file has opset 17, inputs ``x`` float32 ``[n, node_dim]``, ``edge_index`` int64 ``[2, e]``,
``edge_attr`` float32 ``[e, edge_dim]``, output ``removability`` float32 ``[n]`` with ``n`` and
``e`` dynamic, and the metadata properties ``asp.kind``, ``asp.features``, ``asp.node_dim``,
``asp.edge_dim`` (plus ``asp.aggregation``, ``asp.layers``, ``asp.width`` for information).

Export uses PyTorch's TorchScript-based exporter (``dynamo=False``): it needs no ``onnxscript``,
gives a small graph of elementary ops (Gemm, Gather, ScatterND or MatMul, Exp, ...) and honours
``dynamic_axes``. After writing, :func:`export_onnx` runs the file with ``onnxruntime`` when it is
installed, else with ``onnx.reference.ReferenceEvaluator``, on random graphs of sizes the model
never saw (one of them without edges) and fails unless it agrees with PyTorch to ``tolerance``.
"""

from __future__ import annotations

import copy
import os
import warnings
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import onnx
import torch

from ..errors import AspError
from .encoder import EncodedModel

__all__ = [
    "OPSET", "INPUT_NAMES", "OUTPUT_NAME", "ExportError", "export_onnx", "pad_graph", "parity_check", "run_onnx",
    "random_graph", "write_parity_cases",
]

#: The ONNX opset of exported models.
OPSET = 17
#: Input names, in order.
INPUT_NAMES = ("x", "edge_index", "edge_attr")
#: The output name.
OUTPUT_NAME = "removability"
#: ``(n, e)`` of the graphs the exporter checks parity on.
PARITY_SIZES = ((7, 0), (53, 212), (131, 610))
#: ``(n, e)`` of the cases :func:`write_parity_cases` writes (sizes never used in training batches
#: as such; small, so the file stays small).
CASE_SIZES = ((3, 0), (9, 24), (19, 60))


class ExportError(AspError, RuntimeError):
    """The exported file does not reproduce the PyTorch model (also a :class:`RuntimeError`)."""


def random_graph(n: int, e: int, node_dim: int, edge_dim: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random state graph ``(x, edge_index, edge_attr)`` as NumPy arrays.

    Attributes lie where real ones do (docs/learning.md): descriptor entries in [0, 1], flag-like
    last two node columns, `above`/`normal_up` in [-1, 1]. (Inputs far outside that range drive a
    trained model's normalised activations to extremes where float32 rounding differs between
    PyTorch and the ONNX evaluator by more than the parity tolerance.) Edges are random ordered
    pairs of distinct nodes (duplicates allowed, which a model must tolerate too).
    """
    x = rng.uniform(0.0, 1.0, size=(n, node_dim)).astype(np.float32)
    if node_dim >= 2:
        x[:, -2:] = rng.integers(0, 2, size=(n, 2)).astype(np.float32)
    if n >= 2 and e > 0:
        s = rng.integers(0, n, size=e)
        t = (s + rng.integers(1, n, size=e)) % n
        edge_index = np.stack([s, t]).astype(np.int64)
    else:
        edge_index = np.zeros((2, 0), dtype=np.int64)
    e = edge_index.shape[1]
    edge_attr = rng.uniform(0.0, 1.0, size=(e, edge_dim)).astype(np.float32)
    if edge_dim >= 2:
        edge_attr[:, -2:] = rng.uniform(-1.0, 1.0, size=(e, 2)).astype(np.float32)
    return x, edge_index, edge_attr


def run_onnx(path: os.PathLike | str, x: np.ndarray, edge_index: np.ndarray, edge_attr: np.ndarray) -> np.ndarray:
    """Run an exported model with onnxruntime if installed, else with ONNX's reference evaluator."""
    feeds = {"x": x, "edge_index": edge_index, "edge_attr": edge_attr}
    try:
        import onnxruntime  # type: ignore[import-not-found]
    except ImportError:
        from onnx.reference import ReferenceEvaluator

        outputs = ReferenceEvaluator(str(path)).run(None, feeds)
        assert isinstance(outputs, list)  # a dict only with intermediate=True
        return np.asarray(outputs[0])
    session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    return np.asarray(session.run(None, feeds)[0])


def _like_training(
    model: EncodedModel, x: np.ndarray, edge_attr: np.ndarray, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Attributes drawn where the model's training data lay: each column within three standard
    deviations of its training mean (in the model's ``log1p`` space, mapped back), the contract's
    ranges kept (descriptor entries in [0, 1], flags 0/1, cosines in [-1, 1]). Far outside that, a
    column whose training spread was tiny is scaled up by ``1/std`` and float32 rounding differs
    between PyTorch and an ONNX runtime by more than the parity tolerance, on inputs asp never
    produces."""

    def draw(v: np.ndarray, mask: torch.Tensor, mean: torch.Tensor, std: torch.Tensor, flags: bool) -> np.ndarray:
        if v.shape[0] == 0:
            return v
        log_cols, mu, sigma = (t.detach().cpu().numpy() for t in (mask, mean, std))
        z = np.clip(rng.standard_normal(v.shape), -3.0, 3.0)
        w = mu + sigma * z
        out = np.where(log_cols, np.expm1(np.maximum(w, 0.0)), w)
        lo, hi = (0.0, 1.0) if flags else (-1.0, 1.0)
        out[:, : v.shape[1] - 2] = np.clip(out[:, : v.shape[1] - 2], 0.0, 1.0)
        out[:, v.shape[1] - 2 :] = v[:, v.shape[1] - 2 :] if flags else np.clip(out[:, v.shape[1] - 2 :], lo, hi)
        return out.astype(np.float32)

    encoder = model.encoder
    x = draw(x, encoder.node_log_mask, encoder.node_mean, encoder.node_std, flags=True)
    edge_attr = draw(edge_attr, encoder.edge_log_mask, encoder.edge_mean, encoder.edge_std, flags=False)
    return x, edge_attr


def pad_graph(
    x: np.ndarray, edge_index: np.ndarray, edge_attr: np.ndarray, nodes: int, edges: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The graph as asp-learn pads it to a size bucket: ``nodes`` zero rows appended to ``x`` and
    ``edges`` self-loop edges with zero attributes on the first padding node (so ``nodes >= 1``
    when ``edges > 0``). A model's outputs for the real nodes must not change."""
    if edges and not nodes:
        raise ValueError("padding edges need a padding node")
    n = x.shape[0]
    x = np.concatenate([x, np.zeros((nodes, x.shape[1]), dtype=x.dtype)])
    loops = np.full((2, edges), n, dtype=np.int64)
    edge_index = np.concatenate([edge_index, loops], axis=1)
    edge_attr = np.concatenate([edge_attr, np.zeros((edges, edge_attr.shape[1]), dtype=edge_attr.dtype)])
    return x, edge_index, edge_attr


def parity_check(
    model: EncodedModel,
    path: os.PathLike | str,
    seed: int = 12345,
    tolerance: float = 1e-5,
    graphs: Iterable[tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None,
    padding: tuple[int, int] | None = None,
) -> float:
    """Compare the ONNX file with the PyTorch model on ``graphs`` (default: random graphs of
    :data:`PARITY_SIZES` drawn like a removability model's training data).

    With ``padding = (nodes, edges)``, each graph is also run in ONNX padded by :func:`pad_graph`,
    and its real nodes' outputs must match PyTorch's on the unpadded graph to the same tolerance.
    Returns the largest absolute difference; raises :class:`ExportError` above ``tolerance``.
    """
    model = model.eval()
    if graphs is None:
        rng = np.random.default_rng(seed)
        graphs = []
        for n, e in PARITY_SIZES:
            x, edge_index, edge_attr = random_graph(n, e, model.node_dim, model.edge_dim, rng)
            x, edge_attr = _like_training(model, x, edge_attr, rng)
            graphs.append((x, edge_index, edge_attr))
    worst = 0.0
    for x, edge_index, edge_attr in graphs:
        n, e = x.shape[0], edge_index.shape[1]
        with torch.no_grad():
            expected = model(torch.from_numpy(x), torch.from_numpy(edge_index), torch.from_numpy(edge_attr)).numpy()
        runs = [("", (x, edge_index, edge_attr))]
        if padding is not None:
            runs.append((f" padded by {padding[0]} nodes and {padding[1]} self loops", pad_graph(x, edge_index, edge_attr, *padding)))
        for what, inputs in runs:
            got = run_onnx(path, *inputs)
            if got.shape != (inputs[0].shape[0],):
                raise ExportError(f"{path}: output shape {list(got.shape)} for n={inputs[0].shape[0]}, expected [{inputs[0].shape[0]}]")
            got = got[:n]
            diff = float(np.max(np.abs(got.astype(np.float64) - expected))) if n else 0.0
            if not np.isfinite(got).all() or diff > tolerance:
                raise ExportError(
                    f"{path}: ONNX and PyTorch differ by {diff:.3g} on a graph with n={n}, e={e}{what} (tolerance {tolerance:g})"
                )
            worst = max(worst, diff)
    return worst


def export_onnx(
    model: EncodedModel,
    path: os.PathLike | str,
    features: str,
    aggregation: str | None = None,
    check: bool = True,
    tolerance: float = 1e-5,
    extra_metadata: dict[str, str] | None = None,
    *,
    kind: str = "removability",
    output_name: str = OUTPUT_NAME,
    parity_graphs: Iterable[tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None,
    padding: tuple[int, int] | None = None,
) -> float | None:
    """Write ``model`` to ``path`` as an ONNX model of ``kind`` (metadata ``asp.kind``) whose
    output is ``output_name``, and check it (:func:`parity_check` with ``parity_graphs`` and
    ``padding``). A removability model by default; :mod:`asp.train.q` writes Q models with it.

    ``aggregation`` picks the exported implementation (default: the model's); the model itself is
    not modified. Returns the parity check's largest difference (``None`` with ``check=False``).
    """
    path = Path(path)
    model = copy.deepcopy(model).eval()
    if aggregation is not None:
        model.set_aggregation(aggregation)
    rng = np.random.default_rng(0)
    x, edge_index, edge_attr = random_graph(5, 8, model.node_dim, model.edge_dim, rng)
    args = (torch.from_numpy(x), torch.from_numpy(edge_index), torch.from_numpy(edge_attr))
    path.parent.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings():
        # the TorchScript exporter announces its deprecation; it is the one that needs no onnxscript
        warnings.simplefilter("ignore")
        torch.onnx.export(
            model,
            args,
            str(path),
            dynamo=False,
            opset_version=OPSET,
            input_names=list(INPUT_NAMES),
            output_names=[output_name],
            dynamic_axes={
                "x": {0: "n"},
                "edge_index": {1: "e"},
                "edge_attr": {0: "e"},
                output_name: {0: "n"},
            },
            do_constant_folding=True,
        )
    proto = onnx.load(str(path))
    metadata = {
        "asp.kind": kind,
        "asp.features": features,
        "asp.node_dim": str(model.node_dim),
        "asp.edge_dim": str(model.edge_dim),
        "asp.aggregation": model.aggregation,
        "asp.layers": str(model.layers),
        "asp.width": str(model.width),
    }
    metadata.update(extra_metadata or {})
    onnx.helper.set_model_props(proto, metadata)
    proto.producer_name = "asp.train"
    onnx.checker.check_model(proto)
    onnx.save(proto, str(path))
    if not check:
        return None
    return parity_check(model, path, tolerance=tolerance, graphs=parity_graphs, padding=padding)


def _f32(v: float) -> float:
    # shortest decimal that reads back as the same float32
    return float(np.format_float_positional(np.float32(v), unique=True, trim="-"))


def write_parity_cases(model: EncodedModel, path: os.PathLike | str, features: str, seed: int = 4242) -> None:
    """Write graphs drawn like the model's training inputs (:data:`CASE_SIZES`) with the PyTorch
    outputs, as JSON (``features``, ``node_dim``, ``edge_dim``, ``cases`` of ``n``, ``e``, ``x``,
    ``edge_index``, ``edge_attr``, ``removability``), so another runtime (asp-learn's tests on the
    shipped model) can check its parity on the same inputs."""
    import json

    rng = np.random.default_rng(seed)
    model = model.eval()
    cases = []
    for n, e in CASE_SIZES:
        x, edge_index, edge_attr = random_graph(n, e, model.node_dim, model.edge_dim, rng)
        x, edge_attr = _like_training(model, x, edge_attr, rng)
        # the inputs as written (shortest decimals) are the inputs PyTorch sees
        x = np.vectorize(_f32)(x).astype(np.float32) if x.size else x
        edge_attr = np.vectorize(_f32)(edge_attr).astype(np.float32) if edge_attr.size else edge_attr
        with torch.no_grad():
            y = model(torch.from_numpy(x), torch.from_numpy(edge_index), torch.from_numpy(edge_attr)).numpy()
        cases.append({
            "n": n, "e": int(edge_index.shape[1]),
            "x": [_f32(v) for v in x.reshape(-1)],
            "edge_index": [int(v) for v in edge_index.reshape(-1)],
            "edge_attr": [_f32(v) for v in edge_attr.reshape(-1)],
            "removability": [_f32(v) for v in y],
        })
    doc = {
        "about": "inputs drawn like the training data and PyTorch outputs of the model; written by asp.train",
        "features": features, "node_dim": model.node_dim, "edge_dim": model.edge_dim, "cases": cases,
    }
    Path(path).write_text(json.dumps(doc, separators=(",", ":")) + "\n")
