"""Supervised training of the removability GNN (thesis 3.6.2): BCE on labelled nodes, Adam.

States are kept as small index arrays (present parts, induced edge ids, renumbered edges, labels);
their attributes are gathered from the assemblies' memory-mapped arrays batch by batch, so memory
grows with the number of states, not with their attributes. A batch merges its states into one
disjoint graph. Training is seeded and deterministic on CPU (one thread by default).
"""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import torch

from ..datasets.removability import Assembly, DataError, RemovabilityDataset
from .gnn import RemovabilityGNN

__all__ = ["TrainConfig", "StateRecord", "AssemblyData", "load_assemblies", "train", "evaluate", "Batch", "make_batch"]


@dataclass(frozen=True)
class TrainConfig:
    """Training hyper-parameters."""

    epochs: int = 50
    """Passes over the training states."""
    lr: float = 1e-3
    """Adam's learning rate."""
    batch: int = 32
    """States per batch."""
    seed: int = 0
    """Seeds the weights and the batch order."""
    width: int = 64
    """Hidden width."""
    layers: int = 3
    """GNN layers."""
    seconds: float | None = None
    """Stop after this many seconds of training (checked after every batch)."""
    threads: int = 1
    """PyTorch CPU threads (results are reproducible for one thread count)."""
    pos_weight: float = 1.0
    """Weight of the removable class (label 1) in the loss; above 1 when removable parts are rare."""
    patience: int = 5
    """With a validation set: stop after this many epochs without a better validation accuracy."""


@dataclass(frozen=True)
class StateRecord:
    """One state of an assembly, as indices into the assembly's arrays."""

    present: np.ndarray
    """int64 part indices (the nodes)."""
    edge_ids: np.ndarray
    """int64 rows of the assembly's edge arrays (the edges)."""
    edge_index: np.ndarray
    """int64 ``[2, e]`` renumbered edges."""
    labels: np.ndarray
    """float32 ``[n]``."""
    mask: np.ndarray
    """bool ``[n]``: labelled nodes."""


@dataclass
class AssemblyData:
    """An assembly with its states, ready for batching."""

    assembly: Assembly
    """The assembly (memory-mapped arrays)."""
    states: list[StateRecord] = field(default_factory=list)
    """Its states, in file order."""
    checker: str = "default"
    """The checker whose tests labelled its states (its data set's ``checker``)."""

    @property
    def name(self) -> str:
        """The assembly's name."""
        return self.assembly.name


def load_assemblies(
    dirs: Sequence[str], like: tuple[str, str, int, int, str] | None = None
) -> tuple[list[AssemblyData], str, int, int]:
    """Open data sets and read their states. Returns ``(assemblies, features, node_dim, edge_dim)``.

    All data sets must share features, dimensions and checker (the labels of one checker: a model
    ranks for one), with each other and with ``like``, ``(where, features, node_dim, edge_dim,
    checker)`` of other data (the training data, when these are for validation); assembly names
    must be unique across them.
    """
    if not dirs:
        raise DataError("no data set given")
    out: list[AssemblyData] = []
    features = node_dim = edge_dim = None
    first: str | None = None
    checker: str | None = None
    if like is not None:
        first, features, node_dim, edge_dim, checker = like
    for d in dirs:
        ds = RemovabilityDataset.open(d)
        if first is None:
            first, features, node_dim, edge_dim, checker = d, ds.features, ds.node_dim, ds.edge_dim, ds.checker
        elif (ds.features, ds.node_dim, ds.edge_dim) != (features, node_dim, edge_dim):
            raise DataError(
                f"{ds.root / 'index.json'}: features '{ds.features}' ({ds.node_dim}/{ds.edge_dim}) differ from "
                f"{first}'s '{features}' ({node_dim}/{edge_dim})"
            )
        elif ds.checker != checker:
            raise DataError(
                f"{ds.root / 'index.json'}: labelled by the {ds.checker} checker, {first}'s by the {checker} checker "
                "(a model learns the labels of one checker)"
            )
        for a in ds.assemblies:
            if any(o.name == a.name for o in out):
                raise DataError(f"{ds.root / 'index.json'}: assembly '{a.name}' also appears in an earlier data set")
            data = AssemblyData(a, checker=ds.checker)
            for s in a.states():
                edge_ids, edge_index = s.subgraph()
                labels, mask = s.labels()
                data.states.append(StateRecord(s.present, edge_ids, edge_index, labels, mask))
            out.append(data)
    return out, features, node_dim, edge_dim  # type: ignore[return-value]


@dataclass(frozen=True)
class Batch:
    """Several states merged into one disjoint graph."""

    x: torch.Tensor
    """float32 ``[n, node_dim]``."""
    edge_index: torch.Tensor
    """int64 ``[2, e]``."""
    edge_attr: torch.Tensor
    """float32 ``[e, edge_dim]``."""
    labels: torch.Tensor
    """float32 ``[n]``."""
    mask: torch.Tensor
    """bool ``[n]``."""


def make_batch(items: Iterable[tuple[AssemblyData, StateRecord]]) -> Batch:
    """Merge states into one disjoint graph (edge indices offset by the preceding node counts)."""
    xs, eis, eas, ls, ms = [], [], [], [], []
    offset = 0
    for data, s in items:
        xs.append(np.asarray(data.assembly.nodes[s.present], dtype=np.float32))
        eas.append(np.asarray(data.assembly.edge_attr[s.edge_ids], dtype=np.float32))
        eis.append(s.edge_index + offset)
        ls.append(s.labels)
        ms.append(s.mask)
        offset += len(s.present)
    return Batch(
        x=torch.from_numpy(np.concatenate(xs)),
        edge_index=torch.from_numpy(np.concatenate(eis, axis=1)),
        edge_attr=torch.from_numpy(np.concatenate(eas)),
        labels=torch.from_numpy(np.concatenate(ls)),
        mask=torch.from_numpy(np.concatenate(ms)),
    )


def _seed_everything(seed: int, threads: int) -> None:
    torch.manual_seed(seed)
    torch.set_num_threads(max(1, threads))
    torch.use_deterministic_algorithms(True, warn_only=True)


def train(
    assemblies: Sequence[AssemblyData],
    node_dim: int,
    edge_dim: int,
    config: TrainConfig,
    log: Callable[[str], None] | None = None,
    validation: Sequence[AssemblyData] = (),
) -> tuple[RemovabilityGNN, dict]:
    """Train a model on every state of ``assemblies``. Returns ``(model, summary)``.

    The summary holds the epochs run, the final epoch's mean loss and the seconds spent. With
    ``validation`` assemblies (never trained on), the accuracy over all their labels is measured
    after every epoch, training stops after ``config.patience`` epochs without a better one, and
    the model returned is the one of the best epoch (early stopping; ``best_epoch`` and the
    per-epoch ``validation_accuracy`` join the summary).
    """
    items = [(a, s) for a in assemblies for s in a.states if s.mask.any()]
    if not items:
        raise DataError("no labelled state to train on (" + ", ".join(a.name for a in assemblies) + ")")
    _seed_everything(config.seed, config.threads)
    model = RemovabilityGNN(node_dim, edge_dim, width=config.width, layers=config.layers)
    nodes = np.concatenate([np.asarray(a.assembly.nodes) for a in assemblies])
    edges = np.concatenate([np.asarray(a.assembly.edge_attr) for a in assemblies])
    model.fit_normalisation(torch.from_numpy(nodes), torch.from_numpy(edges))
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    pos_weight = torch.tensor(config.pos_weight, dtype=torch.float32)
    rng = np.random.default_rng(config.seed)
    start = time.monotonic()
    epochs_run = 0
    mean_loss = math.nan
    stopped = False
    val_history: list[float] = []
    best: tuple[float, int, dict] | None = None  # accuracy, epoch, weights
    for epoch in range(config.epochs):
        model.train()
        order = rng.permutation(len(items))
        total, count = 0.0, 0
        for b in range(0, len(order), config.batch):
            batch = make_batch(items[k] for k in order[b : b + config.batch])
            logits = model.logits(batch.x, batch.edge_index, batch.edge_attr)
            loss = torch.nn.functional.binary_cross_entropy_with_logits(
                logits[batch.mask], batch.labels[batch.mask], pos_weight=pos_weight
            )
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * int(batch.mask.sum())
            count += int(batch.mask.sum())
            if config.seconds is not None and time.monotonic() - start > config.seconds:
                stopped = True
                break
        epochs_run = epoch + 1
        mean_loss = total / max(count, 1)
        note = ""
        if validation:
            acc = _pooled_accuracy(model, validation)
            val_history.append(acc)
            note = f", validation accuracy {acc:.4f}"
            if best is None or acc > best[0]:
                best = (acc, epochs_run, copy.deepcopy(model.state_dict()))
        if log:
            log(f"epoch {epochs_run}/{config.epochs}: loss {mean_loss:.4f}{note} ({time.monotonic() - start:.1f} s)")
        if best is not None and epochs_run - best[1] >= config.patience:
            if log:
                log(f"no better validation accuracy for {config.patience} epochs: keeping epoch {best[1]} ({best[0]:.4f})")
            break
        if stopped:
            if log:
                log(f"stopped after {config.seconds:g} s")
            break
    if best is not None:
        model.load_state_dict(best[2])
    model.eval()
    summary: dict[str, Any] = {
        "epochs": epochs_run, "loss": mean_loss, "seconds": round(time.monotonic() - start, 3), "time_capped": stopped
    }
    if best is not None:
        summary |= {"best_epoch": best[1], "validation_accuracy": val_history}
    return model, summary


def _pooled_accuracy(model: RemovabilityGNN, assemblies: Sequence[AssemblyData]) -> float:
    """Accuracy over every label of ``assemblies`` together (leaves the model in eval mode)."""
    results = [evaluate(model, a) for a in assemblies]
    labels = sum(r["labels"] for r in results)
    return sum(r["accuracy"] * r["labels"] for r in results if r["labels"]) / labels if labels else math.nan


@torch.no_grad()
def evaluate(model: RemovabilityGNN, data: AssemblyData, batch: int = 64) -> dict:
    """Accuracy (threshold 0.5) over the labelled nodes of every state of one assembly."""
    model.eval()
    correct = total = 0
    positives = 0
    states = [s for s in data.states if s.mask.any()]
    for b in range(0, len(states), batch):
        merged = make_batch((data, s) for s in states[b : b + batch])
        pred = model(merged.x, merged.edge_index, merged.edge_attr)[merged.mask] > 0.5
        truth = merged.labels[merged.mask] > 0.5
        correct += int((pred == truth).sum())
        total += int(truth.numel())
        positives += int(truth.sum())
    return {
        "accuracy": correct / total if total else math.nan,
        "labels": total,
        "states": len(states),
        "positive_fraction": positives / total if total else math.nan,
    }
