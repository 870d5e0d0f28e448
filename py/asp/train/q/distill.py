"""A smaller Q network distilled from a trained one (:func:`distill_q`), and how much of the
teacher's ranking it keeps (:func:`ranking_kept`).

The search asks a Q-function for every feasible removal of a state; what guides it is the order of
those values (the argmax in rollouts, the normalised values as priors). A network a quarter as wide
with one layer costs a fraction of an inference, so the student is fitted to the teacher's values
of every action of states met in the data sets (not to single transitions, as deep Q-learning
fits), with a loss on the values and one on their differences within each state (the ranking).
The ranking it keeps is measured on states it was not fitted on.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Callable

import numpy as np
import torch
from torch import nn

from ...datasets.transitions import DataError, Transition
from ..trainer import _seed_everything
from .graphs import GraphCache, GraphSource, _positions
from .network import QNetwork
from .replay import QAssembly, _run

__all__ = ["DistillConfig", "DistillState", "distill_q", "ranking_kept", "sample_states"]


@dataclass(frozen=True)
class DistillConfig:
    """What the student is and how it is fitted."""

    width: int = 16
    """The student's hidden width."""
    layers: int = 1
    """The student's GNN layers."""
    steps: int = 2000
    """Gradient steps."""
    batch: int = 32
    """States per step."""
    lr: float = 3e-3
    """Adam's learning rate."""
    states: int = 1500
    """Distinct states per assembly (with at least two actions), the first met in file order."""
    holdout_every: int = 5
    """Every this many states of an assembly is held out to measure the ranking kept."""
    rank_weight: float = 1.0
    """Weight of the loss on the values' differences within a state (their ranking)."""
    seed: int = 0
    """Seeds the weights and the sampling."""
    threads: int = 1
    """PyTorch CPU threads (results are reproducible for one thread count)."""


@dataclass(frozen=True)
class DistillState:
    """A state of a data set with the teacher's values of its actions."""

    source: QAssembly
    t: Transition
    target: np.ndarray
    """The teacher's Q of ``t.actions``, in their order."""


def sample_states(assemblies: Sequence[QAssembly], per_assembly: int) -> list[tuple[QAssembly, Transition]]:
    """The first ``per_assembly`` distinct states (present parts and history) with at least two
    feasible actions of each assembly, in file order."""
    out: list[tuple[QAssembly, Transition]] = []
    for a in assemblies:
        seen: set[tuple[bytes, bytes]] = set()
        for t in a.assembly.transitions():
            if len(t.actions) < 2:
                continue
            key = (t.present.tobytes(), t.history.tobytes())
            if key in seen:
                continue
            seen.add(key)
            out.append((a, t))
            if len(seen) >= per_assembly:
                break
    return out


@torch.no_grad()
def _values(model: QNetwork, graphs: GraphCache, states: Sequence[tuple[QAssembly, Transition]], batch: int = 64) -> list[np.ndarray]:
    model.eval()
    out: list[np.ndarray] = []
    for b in range(0, len(states), batch):
        chunk = states[b : b + batch]
        gs = [graphs(a.assembly, t.present, t.actions, t.history) for a, t in chunk]
        q, offsets = _run(model, gs)
        qn = q.numpy()
        for (a, t), g, off in zip(chunk, gs, offsets):
            out.append(qn[off + _positions(g, t.actions, a.assembly)].astype(np.float64))
    return out


def _ranks(v: np.ndarray) -> np.ndarray:
    order = np.argsort(v, kind="stable")
    r = np.empty(len(v))
    r[order] = np.arange(len(v))
    return r


def _centred(v: torch.Tensor, owner: torch.Tensor, counts: torch.Tensor) -> torch.Tensor:
    """``v`` minus the mean of its state's values (``owner[k]``: the state of value ``k``;
    ``counts``: values per state), so a loss on it sees only the order within each state."""
    return v - (torch.zeros(len(counts)).index_add(0, owner, v) / counts).index_select(0, owner)


def ranking_kept(student: Sequence[np.ndarray], teacher: Sequence[np.ndarray]) -> dict:
    """How much of the teacher's ranking of each state's actions the student keeps: ``top1`` how
    often the student's best action is one of the teacher's best (ties count), ``chance`` that
    rate for a uniformly random choice, ``spearman`` the mean rank correlation, and ``regret`` the
    mean shortfall of the teacher's value of the student's choice relative to the spread of the
    teacher's values in the state (0: the teacher's own choice, 1: its worst)."""
    if not teacher:
        return {"states": 0, "top1": None, "chance": None, "spearman": None, "regret": None}
    top1 = chance = spearman = regret = 0.0
    for s, t in zip(student, teacher):
        best = t.max()
        ties = t >= best - 1e-9 * max(1.0, abs(best))
        top1 += float(ties[int(np.argmax(s))])
        chance += float(ties.mean())
        spread = best - t.min()
        regret += float((best - t[int(np.argmax(s))]) / spread) if spread > 0 else 0.0
        rs, rt = _ranks(s), _ranks(t)
        if rs.std() > 0 and rt.std() > 0:
            spearman += float(np.corrcoef(rs, rt)[0, 1])
        else:
            spearman += 1.0 if rs.std() == rt.std() else 0.0
    n = len(teacher)
    return {"states": n, "top1": top1 / n, "chance": chance / n, "spearman": spearman / n, "regret": regret / n}


def distill_q(
    teacher: QNetwork,
    assemblies: Sequence[QAssembly],
    config: DistillConfig,
    graph_source: GraphSource,
    log: Callable[[str], None] | None = None,
) -> tuple[QNetwork, dict]:
    """Fits a ``config.width``-wide, ``config.layers``-layer :class:`QNetwork` to ``teacher``'s
    values on states of ``assemblies``. Returns ``(student, summary)``; the summary holds the
    settings, the loss curve and the ranking kept on the held-out states (every
    ``holdout_every``-th of each assembly) and on the fitted ones, and the teacher's and the
    student's parameter counts."""
    for name in ("width", "layers", "steps", "batch", "states", "holdout_every", "threads"):
        if getattr(config, name) < 1:
            raise ValueError(f"{name} must be at least 1")
    _seed_everything(config.seed, config.threads)
    rng = np.random.default_rng(config.seed)
    node_dim, edge_dim = teacher.node_dim, teacher.edge_dim
    graphs = GraphCache(graph_source, node_dim, edge_dim, capacity=4 * config.batch)
    picked = sample_states(assemblies, config.states)
    if len(picked) < 2:
        raise DataError("fewer than two states with two or more actions to distill on")
    start = time.monotonic()
    targets = _values(teacher, graphs, picked)
    if log:
        log(f"teacher's values of {len(picked)} states in {time.monotonic() - start:.1f} s")
    states = [DistillState(a, t, v) for (a, t), v in zip(picked, targets)]
    held = [s for k, s in enumerate(states) if k % config.holdout_every == config.holdout_every - 1]
    fit = [s for k, s in enumerate(states) if k % config.holdout_every != config.holdout_every - 1]
    student = QNetwork(node_dim, edge_dim, width=config.width, layers=config.layers)
    sample = [fit[int(k)] for k in np.sort(rng.choice(len(fit), size=min(256, len(fit)), replace=False))]
    gs = [graphs(s.source.assembly, s.t.present, s.t.actions, s.t.history) for s in sample]
    student.fit_normalisation(
        torch.from_numpy(np.concatenate([g.x for g in gs]).astype(np.float32)),
        torch.from_numpy(np.concatenate([g.edge_attr for g in gs]).astype(np.float32)),
    )
    optimiser = torch.optim.Adam(student.parameters(), lr=config.lr)
    mse = nn.MSELoss()
    losses: list[float] = []
    for step in range(config.steps):
        student.train()
        chunk = [fit[int(k)] for k in rng.integers(0, len(fit), size=config.batch)]
        gs = [graphs(s.source.assembly, s.t.present, s.t.actions, s.t.history) for s in chunk]
        q, offsets = _run(student, gs)
        pos = np.concatenate([off + _positions(g, s.t.actions, s.source.assembly) for s, g, off in zip(chunk, gs, offsets)])
        owner = torch.from_numpy(np.concatenate([np.full(len(s.t.actions), k, dtype=np.int64) for k, s in enumerate(chunk)]))
        pred = q.index_select(0, torch.from_numpy(pos))
        want = torch.from_numpy(np.concatenate([s.target for s in chunk]).astype(np.float32))
        counts = torch.bincount(owner, minlength=len(chunk)).to(torch.float32)
        loss = mse(pred, want) + config.rank_weight * mse(_centred(pred, owner, counts), _centred(want, owner, counts))
        optimiser.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(student.parameters(), 10.0)
        optimiser.step()
        losses.append(float(loss.item()))
        if log and ((step + 1) % max(1, config.steps // 10) == 0 or step == 0):
            log(f"step {step + 1}/{config.steps}: loss {np.mean(losses[-max(1, config.steps // 10):]):.3g}")
    student.eval()
    kept = ranking_kept(_values(student, graphs, [(s.source, s.t) for s in held]), [s.target for s in held])
    fitted = ranking_kept(_values(student, graphs, [(s.source, s.t) for s in fit[:len(held)]]), [s.target for s in fit[:len(held)]])
    params = lambda m: int(sum(p.numel() for p in m.parameters()))  # noqa: E731
    summary = {
        "settings": asdict(config),
        "states": len(states),
        "fitted_states": len(fit),
        "held_out_states": len(held),
        "seconds": round(time.monotonic() - start, 3),
        "loss_curve": [
            {"steps": min(k + max(1, len(losses) // 20), len(losses)), "loss": float(np.mean(losses[k : k + max(1, len(losses) // 20)]))}
            for k in range(0, len(losses), max(1, len(losses) // 20))
        ],
        "ranking_kept": kept,
        "ranking_kept_fitted": fitted,
        "teacher_parameters": params(teacher),
        "student_parameters": params(student),
    }
    return student, summary
