"""Deep Q-learning (thesis 5.4.4, 6.5.1): the hyper-parameters, the step-by-step learner and the
offline training loop over data sets."""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any, Callable

import numpy as np
import torch
from torch import nn

from ...datasets.transitions import DataError, Transition
from ..trainer import _seed_everything
from .graphs import GraphCache, GraphSource, _positions
from .network import QNetwork
from .replay import QAssembly, ReplayBuffer, _Record, _run, _stream

__all__ = ["QLearning", "QConfig", "DeepQLearner", "train_q", "config_dict"]


@dataclass(frozen=True)
class QLearning:
    """The deep Q-learning hyper-parameters that offline training (:class:`QConfig`) and the
    online settings (:class:`asp.train.online.OnlineConfig`) share."""

    batch: int = 128
    """Transitions per step."""
    buffer: int = 10_000
    """Replay buffer capacity."""
    lr: float = 1e-3
    """Adam's learning rate."""
    seed: int = 0
    """Seeds the weights and the sampling."""
    layers: int = 3
    """GNN layers."""
    width: int = 64
    """Hidden width."""
    threads: int = 1
    """PyTorch CPU threads (results are reproducible for one thread count)."""
    target_sync: int = 100
    """Steps between copies of the trained network into the target network."""

    def learning(self) -> dict[str, Any]:
        """The :class:`QLearning` fields of these settings, as keywords (of :class:`QConfig`)."""
        return {f.name: getattr(self, f.name) for f in fields(QLearning)}


@dataclass(frozen=True)
class QConfig(QLearning):
    """Deep Q-learning hyper-parameters: :class:`QLearning`'s, and how long and on what to train."""

    steps: int = 2000
    """Gradient steps (at most)."""
    seconds: float | None = None
    """Stop after this many seconds of training (checked after every step)."""
    loss: str = "huber"
    """``"huber"`` (smooth L1, delta 1) or ``"mse"``."""
    cache: int = 512
    """State graphs kept in memory (least recently used)."""
    normalisation_states: int = 256
    """Transitions of the initial buffer whose state graphs give the input statistics."""


def _fit_inputs(model: QNetwork, buffer: ReplayBuffer, graphs: GraphCache, rng: np.random.Generator, count: int) -> None:
    picks = rng.choice(len(buffer), size=min(count, len(buffer)), replace=False)
    gs = [graphs(r.source.assembly, r.t.present, r.t.actions, r.t.history) for r in (buffer.items[int(k)] for k in np.sort(picks))]
    model.fit_normalisation(
        torch.from_numpy(np.concatenate([g.x for g in gs]).astype(np.float32)),
        torch.from_numpy(np.concatenate([g.edge_attr for g in gs]).astype(np.float32)),
    )


def _loss_curve(losses: list[float], points: int = 20) -> list[dict]:
    if not losses:
        return []
    size = max(1, math.ceil(len(losses) / points))
    return [
        {"steps": min(k + size, len(losses)), "loss": float(np.mean(losses[k : k + size]))}
        for k in range(0, len(losses), size)
    ]


class DeepQLearner:
    """Deep Q-learning of one objective's Q-function, step by step: the network, its target copy,
    Adam, the replay buffer and the seeded sampling (thesis 5.4.4, 6.5.1).

    :func:`train_q` fills the buffer from data sets and runs ``config.steps`` steps; the online
    settings of 6.5 (:mod:`asp.train.online`) push each search episode's transitions and run a few
    steps after each episode. ``model`` continues training a network (the "retrained" setting; its
    input statistics are kept), else a new one is made (seeded) and :meth:`start` fits its input
    statistics on the buffer.
    """

    def __init__(
        self,
        node_dim: int,
        edge_dim: int,
        config: QConfig,
        graph_source: GraphSource,
        model: QNetwork | None = None,
    ) -> None:
        for name in ("steps", "batch", "buffer", "layers", "width", "threads", "target_sync", "cache"):
            if getattr(config, name) < 1:
                raise ValueError(f"{name} must be at least 1")
        if config.loss not in ("huber", "mse"):
            raise ValueError(f"loss must be 'huber' or 'mse', not {config.loss!r}")
        _seed_everything(config.seed, config.threads)
        self.config = config
        self.rng = np.random.default_rng(config.seed)
        self.graphs = GraphCache(graph_source, node_dim, edge_dim, capacity=config.cache)
        self.buffer = ReplayBuffer(config.buffer)
        self.fresh = model is None
        self.model = model if model is not None else QNetwork(node_dim, edge_dim, width=config.width, layers=config.layers)
        self.target: QNetwork | None = None
        self.optimiser: torch.optim.Optimizer | None = None
        self.loss_fn = nn.SmoothL1Loss(beta=1.0) if config.loss == "huber" else nn.MSELoss()
        self.losses: list[float] = []

    @property
    def steps(self) -> int:
        """Gradient steps run so far."""
        return len(self.losses)

    def push(self, source: QAssembly, t: Transition) -> None:
        """Adds a transition of ``source`` to the replay buffer (the oldest leaves when it is full)."""
        self.buffer.push(_Record(source, t, source.reward(t)))

    def start(self) -> None:
        """Fits a new network's input statistics on the buffer, then makes the target network and
        the optimiser (once, before the first step)."""
        if self.target is not None:
            return
        if self.fresh:
            _fit_inputs(self.model, self.buffer, self.graphs, self.rng, self.config.normalisation_states)
        self.target = copy.deepcopy(self.model).eval()
        for p in self.target.parameters():
            p.requires_grad_(False)
        self.optimiser = torch.optim.Adam(self.model.parameters(), lr=self.config.lr)

    def step(self) -> float:
        """One gradient step on a batch sampled from the buffer; returns its loss. The target
        network is synced every ``target_sync`` steps."""
        self.start()
        assert self.target is not None and self.optimiser is not None
        model, target = self.model, self.target
        model.train()
        records = self.buffer.sample(self.rng, self.config.batch)
        graphs = self.graphs
        states = [graphs(r.source.assembly, r.t.present, r.t.actions, r.t.history) for r in records]
        action_at = [int(_positions(g, np.array([r.t.action]), r.source.assembly)[0]) for g, r in zip(states, records)]
        rewards = torch.tensor([r.reward for r in records], dtype=torch.float32)
        going_on = [k for k, r in enumerate(records) if not r.t.terminal]
        bootstrap = torch.zeros(len(records), dtype=torch.float32)
        if going_on:
            nexts = [
                graphs(records[k].source.assembly, records[k].t.next_present, records[k].t.next_actions, records[k].t.next_history)
                for k in going_on
            ]
            with torch.no_grad():
                q_next, offsets = _run(target, nexts)
            at, owner = [], []
            for j, (k, g) in enumerate(zip(going_on, nexts)):
                pos = _positions(g, records[k].t.next_actions, records[k].source.assembly) + offsets[j]
                at.append(pos)
                owner.append(np.full(len(pos), k, dtype=np.int64))
            values = q_next.index_select(0, torch.from_numpy(np.concatenate(at)))
            best = torch.full((len(records),), -math.inf).scatter_reduce(
                0, torch.from_numpy(np.concatenate(owner)), values, reduce="amax", include_self=True
            )
            bootstrap = torch.where(torch.isfinite(best), best, torch.zeros_like(best))
        y = rewards + bootstrap
        q, offsets = _run(model, states)
        pred = q.index_select(0, torch.from_numpy(offsets + np.asarray(action_at, dtype=np.int64)))
        loss = self.loss_fn(pred, y)
        self.optimiser.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(model.parameters(), 10.0)
        self.optimiser.step()
        self.losses.append(float(loss.item()))
        if self.steps % self.config.target_sync == 0:
            target.load_state_dict(model.state_dict())
        model.eval()
        return self.losses[-1]


def train_q(
    assemblies: Sequence[QAssembly],
    node_dim: int,
    edge_dim: int,
    config: QConfig,
    graph_source: GraphSource,
    log: Callable[[str], None] | None = None,
) -> tuple[QNetwork, dict]:
    """Deep Q-learning on the transitions of ``assemblies``. Returns ``(model, summary)``.

    The summary holds the steps run, whether time stopped them, the seconds, the transitions read,
    the buffer size, the graph cache's hit rate and the loss curve (mean loss per twentieth).
    """
    learner = DeepQLearner(node_dim, edge_dim, config, graph_source)
    total = sum(a.assembly.num_transitions for a in assemblies)
    if total == 0:
        raise DataError("no transition to train on (" + ", ".join(a.name for a in assemblies) + ")")
    buffer = learner.buffer
    streaming = total > config.buffer
    if streaming:
        stream = _stream(assemblies)
        for _ in range(config.buffer):
            buffer.push(next(stream))
    else:  # everything fits: read each file once (to its end, which checks its count)
        for a in assemblies:
            for t in a.assembly.transitions():
                learner.push(a, t)
    read = len(buffer)
    ingest = max(1, config.batch // 8)
    if log:
        how = f"streaming {ingest} new per step" if streaming else "all of them"
        log(f"replay buffer: {len(buffer)} of {total} transitions ({how})")

    learner.start()
    start = time.monotonic()
    losses = learner.losses
    stopped = False
    for step in range(config.steps):
        if streaming:
            for _ in range(ingest):
                buffer.push(next(stream))
            read += ingest
        learner.step()
        if log and ((step + 1) % max(1, config.steps // 20) == 0 or step == 0):
            recent = float(np.mean(losses[-max(1, config.steps // 20) :]))
            log(f"step {step + 1}/{config.steps}: loss {recent:.3g} ({time.monotonic() - start:.1f} s)")
        if config.seconds is not None and time.monotonic() - start > config.seconds:
            stopped = True
            if log:
                log(f"stopped after {config.seconds:g} s at step {step + 1}")
            break
    model = learner.model
    model.eval()
    graphs = learner.graphs
    summary = {
        "steps": len(losses),
        "time_capped": stopped,
        "seconds": round(time.monotonic() - start, 3),
        "transitions": total,
        "transitions_read": read,
        "buffer": len(buffer),
        "graph_cache_hit_rate": round(graphs.hits / graphs.calls, 4) if graphs.calls else None,
        "final_loss": float(np.mean(losses[-max(1, len(losses) // 20) :])) if losses else math.nan,
        "loss_curve": _loss_curve(losses),
    }
    return model, summary


def config_dict(config: QConfig) -> dict:
    """The settings as JSON-ready values."""
    return asdict(config)
