"""Writes the ONNX fixtures of the Rust crate ``asp-learn`` (its parity and rejection tests).

Run from the repository root (seeded; same output on every run with the same torch version)::

    PYTHONPATH=py /work/venv/bin/python -m asp.train.fixture crates/asp-learn/tests/data

Writes into the folder:

* ``random_gnn.onnx``: a 3-layer, 64-wide :class:`~asp.train.gnn.RemovabilityGNN` with
  ``node_dim`` 74, ``edge_dim`` 152 and the features string
  ``asp-graph/2 radius_bins=8 degree=8 points=2048``, briefly trained on random graphs with a
  label rule (so its weights and normalisation are not the initial ones), exported with the
  ``scatter`` aggregation;
* ``random_gnn_dense.onnx``: the same weights exported with the ``dense`` aggregation;
* ``random_gnn_cases.json``: input graphs (one without edges, one with a node without incoming
  edges) with PyTorch's outputs, inputs written as shortest float32 decimals;
* ``tiny_gnn.onnx``: a 1-layer, 8-wide model with ``node_dim`` 6, ``edge_dim`` 5 and features
  ``tiny/1``, for the tests that a model of other dimensions is refused;
* ``random_q_access.onnx``, ``random_q_dirchange.onnx``, ``random_q_robot-path.onnx``:
  :class:`~asp.train.q.QNetwork` Q models (3 layers, 32 wide, features ``asp-q/1 directions=25
  neighbours=8``, for maps of resolution 5) briefly fitted to a random target on synthetic state
  graphs, so their values differ between parts; ``--only q`` writes just these three,
  ``--only q --objective NAME`` just one of them.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from .export import export_onnx, random_graph
from .gnn import RemovabilityGNN

FEATURES = "asp-graph/2 radius_bins=8 degree=8 points=2048"
NODE_DIM = 74
EDGE_DIM = 152
SEED = 7
#: ``(n, e)`` of the parity cases.
CASE_SIZES = ((1, 0), (6, 0), (9, 20), (23, 64), (40, 160))


def _f32(v: float) -> float:
    # shortest decimal that reads back as the same float32
    return float(np.format_float_positional(np.float32(v), unique=True, trim="-"))


def _train_random(model: RemovabilityGNN, rng: np.random.Generator, steps: int = 60) -> None:
    graphs = [random_graph(int(rng.integers(5, 40)), int(rng.integers(0, 120)), model.node_dim, model.edge_dim, rng) for _ in range(16)]
    nodes = torch.from_numpy(np.concatenate([g[0] for g in graphs]))
    edges = torch.from_numpy(np.concatenate([g[2] for g in graphs]))
    model.fit_normalisation(nodes, edges)
    opt = torch.optim.Adam(model.parameters(), lr=3e-3)
    for step in range(steps):
        x, edge_index, edge_attr = graphs[step % len(graphs)]
        # a learnable rule: removable when the node has at most two incoming edges
        indeg = np.bincount(edge_index[1], minlength=len(x))
        labels = torch.from_numpy((indeg <= 2).astype(np.float32))
        logits = model.logits(torch.from_numpy(x), torch.from_numpy(edge_index), torch.from_numpy(edge_attr))
        loss = torch.nn.functional.binary_cross_entropy_with_logits(logits, labels)
        opt.zero_grad()
        loss.backward()
        opt.step()
    model.eval()


def write_fixtures(out: Path) -> None:
    """Write the fixture files into ``out`` (created if missing)."""
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    torch.manual_seed(SEED)
    rng = np.random.default_rng(SEED)
    model = RemovabilityGNN(NODE_DIM, EDGE_DIM)
    _train_random(model, rng)
    diff = export_onnx(model, out / "random_gnn.onnx", FEATURES, aggregation="scatter")
    diff_dense = export_onnx(model, out / "random_gnn_dense.onnx", FEATURES, aggregation="dense")
    cases = []
    for n, e in CASE_SIZES:
        x, edge_index, edge_attr = random_graph(n, e, NODE_DIM, EDGE_DIM, rng)
        if n == 23:
            # node 0 gets no incoming edges: its aggregation must be 0, not NaN
            keep = edge_index[1] != 0
            edge_index = np.ascontiguousarray(edge_index[:, keep])
            edge_attr = np.ascontiguousarray(edge_attr[keep])
        x = np.vectorize(_f32)(x).astype(np.float32)
        edge_attr = np.vectorize(_f32)(edge_attr).astype(np.float32) if edge_attr.size else edge_attr
        with torch.no_grad():
            y = model(torch.from_numpy(x), torch.from_numpy(edge_index), torch.from_numpy(edge_attr)).numpy()
        cases.append(
            {
                "n": n,
                "e": int(edge_index.shape[1]),
                "x": [_f32(v) for v in x.reshape(-1)],
                "edge_index": [int(v) for v in edge_index.reshape(-1)],
                "edge_attr": [_f32(v) for v in edge_attr.reshape(-1)],
                "removability": [_f32(v) for v in y],
            }
        )
    doc = {
        "about": "inputs and PyTorch outputs of random_gnn.onnx; written by py/asp/train/fixture.py",
        "features": FEATURES,
        "node_dim": NODE_DIM,
        "edge_dim": EDGE_DIM,
        "cases": cases,
    }
    (out / "random_gnn_cases.json").write_text(json.dumps(doc, separators=(",", ":")) + "\n")
    torch.manual_seed(SEED + 1)
    tiny = RemovabilityGNN(6, 5, width=8, layers=1)
    export_onnx(tiny, out / "tiny_gnn.onnx", "tiny/1")
    print(f"wrote fixtures to {out} (parity: scatter {diff:.2g}, dense {diff_dense:.2g})")


Q_FEATURES = "asp-q/1 directions=25 neighbours=8"


#: The objectives of the Q-model fixtures (each seeded by its position, so adding one changes no other).
Q_OBJECTIVES = ("access", "dirchange", "robot-path")


def write_q_fixtures(out: Path, only: str | None = None) -> None:
    """Write the Q-model fixtures into ``out`` (all of :data:`Q_OBJECTIVES`, or ``only`` that one)."""
    from .q import QNetwork, export_q, synthetic_q_graph

    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    directions, neighbours = 25, 8
    node_dim, edge_dim = 28 + 2 * directions, 5 + 2 * directions
    for k, objective in enumerate(Q_OBJECTIVES):
        if only is not None and objective != only:
            continue
        torch.manual_seed(SEED + 10 + k)
        rng = np.random.default_rng(SEED + 10 + k)
        graphs = []
        for _ in range(12):
            parts = int(rng.integers(4, 20))
            lo = rng.uniform(0.0, 1.0, size=(parts, 3))
            boxes = np.stack([lo, lo + rng.uniform(0.05, 0.4, size=(parts, 3))], axis=1)
            present = np.arange(parts)
            actions = present[rng.uniform(size=parts) < 0.5]
            history = np.flatnonzero(rng.uniform(size=directions) < 0.3)
            graphs.append(synthetic_q_graph(boxes, present, actions, history, directions, neighbours, rng=rng))
        model = QNetwork(node_dim, edge_dim, width=32, layers=3)
        model.fit_normalisation(
            torch.from_numpy(np.concatenate([g.x for g in graphs])), torch.from_numpy(np.concatenate([g.edge_attr for g in graphs]))
        )
        opt = torch.optim.Adam(model.parameters(), lr=3e-3)
        for step in range(40):
            g = graphs[step % len(graphs)]
            # a learnable target: the share of free directions of each node
            target = torch.from_numpy(g.x[:, 28 + directions :].mean(axis=1).astype(np.float32))
            q = model(torch.from_numpy(g.x), torch.from_numpy(g.edge_index), torch.from_numpy(g.edge_attr))
            loss = torch.nn.functional.mse_loss(q, target)
            opt.zero_grad()
            loss.backward()
            opt.step()
        model.eval()
        diff = export_q(model, out / f"random_q_{objective}.onnx", Q_FEATURES, objective)
        print(f"wrote {out / f'random_q_{objective}.onnx'} (parity {diff:.2g})")


def main(argv: list[str] | None = None) -> int:
    """Command line: ``python -m asp.train.fixture OUT_DIR``."""
    parser = argparse.ArgumentParser(prog="python -m asp.train.fixture", description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder to write the fixtures into")
    parser.add_argument("--only", choices=["q"], help="write only the Q-model fixtures")
    parser.add_argument("--objective", choices=Q_OBJECTIVES, help="with --only q: write only this objective's Q model")
    args = parser.parse_args(argv)
    if args.objective is not None and args.only != "q":
        parser.error("--objective needs --only q")
    if args.only != "q":
        write_fixtures(args.out)
    write_q_fixtures(args.out, args.objective)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
