"""The transitions Q-learning trains on: the assemblies of the data sets with the learned
objective's column, the round-robin stream over them, the replay buffer and the batching of
state graphs."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from ...datasets.transitions import DataError, Transition, TransitionAssembly, TransitionDataset
from .graphs import GraphLike
from .network import QNetwork

__all__ = ["QAssembly", "open_q_assemblies", "ReplayBuffer"]


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
