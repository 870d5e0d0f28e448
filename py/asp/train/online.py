"""Q-functions trained during the search: the online settings of thesis 6.5.

- **online** ("MCTS + Q-functions"): the first episode's rollouts are random; after each episode
  its transitions (every step of the selection/expansion and the simulation, as recorded by the
  search) go into a replay buffer of 10,000 per objective, a few deep Q-learning steps run on
  batches from it (the thesis: batches of 5, 20 steps, so 100 samples per episode), each network
  is exported to ONNX (parity-checked) and the search continues with the ε-greedy policy over the
  new models, keeping its tree.
- **retrained** ("MCTS + retrained Q-functions"): the same, starting from pretrained networks
  (``--q``; the weights ``python -m asp.train q`` writes beside each ONNX file as ``.onnx.pt``), which
  also guide the first episode.

The search is :meth:`asp.Assembly.search` (Rust, the search loop of ``asp plan --objective``); the
learning is :class:`asp.train.q.DeepQLearner`, the loop of ``python -m asp.train q`` one step at a
time. With a fixed episode count (no time limit), one PyTorch thread and a seed, a run is
reproducible.

:func:`bench_mcts` compares vanilla, online, pretrained and retrained at equal wall time and
prints ``asp bench mcts``'s table through the wheel.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..datasets.transitions import DataError, TransitionDataset
from ..errors import ConfigError
from ..settings import PlanSettings, QUse
from .q import BindingGraphs, DeepQLearner, QAssembly, QConfig, QLearning, export_q, load_q_weights, save_q_weights

if TYPE_CHECKING:
    from ..result import Plan

__all__ = ["OnlineConfig", "OnlineResult", "run_online", "bench_mcts", "SETTINGS", "values_at"]

#: The settings :func:`bench_mcts` knows (thesis 6.5's four, in its order).
SETTINGS = ("vanilla", "online", "pretrained", "retrained")


@dataclass(frozen=True)
class OnlineConfig(QLearning):
    """Settings of a search that trains its Q-functions after each episode: the deep Q-learning
    hyper-parameters of :class:`~asp.train.q.QLearning` (each objective ``k``'s network seeded with
    ``seed + k``; ``seed`` also seeds the search), and the search's."""

    batch: int = 5
    """Transitions per step (the thesis: 5; offline training's default is larger)."""
    objective: str = ""
    """Objectives, comma-separated (one network each; several run Pareto-MCTS); required."""
    seconds: float | None = None
    """Wall time of the search (training between episodes included); ``None``: ``episodes`` only."""
    episodes: int = 1_000_000
    """The most episodes."""
    q: Sequence[str] | None = None
    """Pretrained Q models (ONNX, with their ``.pt`` weights beside them), one per objective: the
    retrained setting."""
    steps_per_episode: int = 20
    """Deep Q-learning steps after each episode (the thesis: 20 for 5×5 cubes)."""
    epsilon: float | None = None
    """The probability of a random removal in a guided rollout (``None``: asp's default, 0.2)."""
    q_use: QUse | None = None
    """Where the Q models guide (``None``: asp's default, ``rollouts``)."""
    budget: int = 5
    resolution: int = 9
    aggregation: str = "dense"
    parity_tolerance: float = 1e-5
    search: dict | None = None
    """Further keywords of :meth:`asp.Assembly.plan` (``exploration``, ``d_max``, ``support``, ...)."""
    keep_models: bool = False
    """Keep every episode's models (``models/<episode>_q_<objective>.onnx``: the ones swapped in
    after that episode), not only the last."""

    def __post_init__(self) -> None:
        if not self.objective.strip(" ,"):
            raise ConfigError("OnlineConfig: objective must name at least one objective")


@dataclass
class OnlineResult:
    """What :func:`run_online` did."""

    plan: Plan
    """The :class:`asp.Plan` of the search."""
    episodes: int
    swaps: int
    """Q models swapped into the search."""
    transitions: int
    steps: int
    """Deep Q-learning steps per network."""
    train_seconds: float
    search_seconds: float
    models: list[Path]
    trace: list[tuple[float, float, int]]
    """``(seconds, value, episodes)`` after each episode (training time included)."""
    interrupted: bool = False
    """Ctrl-C ended the search (the plan is that of the episodes finished)."""


def _log_stderr(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_online(
    model: str | os.PathLike,
    out: str | os.PathLike,
    config: OnlineConfig,
    load: dict | None = None,
    log: Callable[[str], None] | None = _log_stderr,
    record_transitions: bool = True,
) -> OnlineResult:
    """Runs the search of ``model`` with its Q-functions trained after every episode; writes to
    ``out``: ``plan.json``, ``trace.csv``, the final models ``q_<objective>.onnx`` (with their
    ``.pt`` weights), ``transitions/`` (the episodes' transitions as an ``asp-transitions`` data
    set) and ``online.json`` (settings and counts)."""
    import torch

    import asp

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    objectives = [o.strip() for o in config.objective.split(",") if o.strip()]
    if not objectives:
        raise DataError("--objective names no objective")
    pretrained = list(config.q or [])
    if pretrained and len(pretrained) != len(objectives):
        raise DataError(f"{len(pretrained)} Q models for {len(objectives)} objectives ({', '.join(objectives)}): give one per objective")
    networks = []
    for q_path, objective in zip(pretrained, objectives):
        net, features, trained_for = load_q_weights(str(q_path) + ".pt")
        if trained_for != objective:
            raise DataError(f"{q_path}.pt: estimates '{trained_for}', its place in --q is that of '{objective}'")
        networks.append(net)

    assembly = asp.load(model, **(load or {}))
    settings = dict(config.search or {})
    settings.update(
        objective=",".join(objectives),
        pareto=len(objectives) > 1,
        seed=config.seed,
        budget=config.budget,
        resolution=config.resolution,
        episodes=config.episodes,
        time_limit=config.seconds,
        epsilon=config.epsilon if pretrained else None,  # the trained models get them by set_q
        q_use=config.q_use if pretrained else None,
        # without pretrained models the first episodes are the vanilla search's (no default seeds)
        q=",".join(os.fspath(p) for p in pretrained) if pretrained else "none",
    )
    search = assembly.search(record=True, **settings)
    index = search.index
    data_dir = out / "transitions"
    (data_dir / "model").mkdir(parents=True, exist_ok=True)
    (data_dir / "index.json").write_text(json.dumps(index, indent=2) + "\n")
    data = TransitionDataset.open(data_dir)
    source = data.assemblies[0]
    if networks and any(n.node_dim != data.node_dim or n.edge_dim != data.edge_dim for n in networks):
        raise DataError(f"the --q networks read other graphs than this search's '{data.features}'")
    graphs = BindingGraphs(data.features, data.node_dim, data.edge_dim)
    torch.set_num_threads(config.threads)
    learners = []
    for k, objective in enumerate(objectives):
        qc = QConfig(**{**config.learning(), "seed": config.seed + k}, steps=max(config.steps_per_episode, 1))
        learner = DeepQLearner(data.node_dim, data.edge_dim, qc, graphs, networks[k] if networks else None)
        learners.append((QAssembly(source, data.objective_index(objective)), learner))
    paths = [out / f"q_{o}.onnx" for o in objectives]
    lines_path = source.transitions_path
    transitions = 0
    train_seconds = 0.0
    started = time.monotonic()
    trace: list[tuple[float, float, int]] = []
    episodes = 0
    interrupted = False
    with open(lines_path, "w", encoding="utf-8") as lines_file:
        while True:
            try:
                e = search.episode()
            except KeyboardInterrupt:  # the search has ended: keep what it found
                interrupted = True
                if log:
                    log("interrupted: writing the plan of the episodes finished")
                break
            episodes = e.episodes
            lines = e.transitions_jsonl
            lines_file.write(lines)
            parsed = [source.parse(line, transitions + i + 1) for i, line in enumerate(lines.splitlines()) if line.strip()]
            transitions += len(parsed)
            trace.append((time.monotonic() - started, e.value, e.episodes))
            if e.finished:
                break
            t0 = time.monotonic()
            losses = []
            for q_assembly, learner in learners:
                for t in parsed:
                    learner.push(q_assembly, t)
                if len(learner.buffer) == 0:
                    continue
                for _ in range(config.steps_per_episode):
                    losses.append(learner.step())
            exported = False
            if all(learner.steps > 0 or not learner.fresh for _, learner in learners):
                for (_, learner), path, objective in zip(learners, paths, objectives):
                    export_q(
                        learner.model, path, data.features, objective, aggregation=config.aggregation, tolerance=config.parity_tolerance
                    )
                    if config.keep_models:
                        (out / "models").mkdir(exist_ok=True)
                        (out / "models" / f"{e.episodes}_{path.name}").write_bytes(path.read_bytes())
                search.set_q(paths, config.epsilon, config.q_use)
                exported = True
            train_seconds += time.monotonic() - t0
            if log:
                loss = f", loss {np.mean(losses):.3g}" if losses else ""
                swap = "new Q models" if exported else "no model yet"
                log(f"episode {e.episodes}: {len(parsed)} transitions, value {e.value:.6g}, front {e.front_size}{loss}; "
                    f"{swap} ({time.monotonic() - started:.1f} s)")
    plan = search.result()
    search_seconds = time.monotonic() - started
    for (_, learner), path, objective in zip(learners, paths, objectives):
        if learner.steps > 0 or not learner.fresh:
            if learner.steps == 0 or not path.exists():
                export_q(learner.model, path, data.features, objective, aggregation=config.aggregation, tolerance=config.parity_tolerance)
            save_q_weights(learner.model, str(path) + ".pt", data.features, objective)
    index["assemblies"][0]["transitions"] = transitions
    index["assemblies"][0]["episodes_run"] = episodes
    (data_dir / "index.json").write_text(json.dumps(index, indent=2) + "\n")
    (out / "plan.json").write_text(plan.json if plan.json.endswith("\n") else plan.json + "\n")
    if plan.trace_csv is not None:
        (out / "trace.csv").write_text(plan.trace_csv)
    result = OnlineResult(
        plan=plan,
        episodes=episodes,
        swaps=search.swaps,
        transitions=transitions,
        steps=learners[0][1].steps,
        train_seconds=train_seconds,
        search_seconds=search_seconds,
        models=[p for p in paths if p.exists()],
        trace=trace,
        interrupted=interrupted,
    )
    doc = {
        "setting": "retrained" if pretrained else "online",
        "model": str(model),
        "objectives": objectives,
        "pretrained": [os.fspath(p) for p in pretrained],
        "settings": {k: v for k, v in config.__dict__.items() if k != "search"} | {"search": config.search},
        "episodes": episodes,
        "swaps": result.swaps,
        "transitions": transitions,
        "steps_per_network": result.steps,
        "train_seconds": round(train_seconds, 3),
        "seconds": round(search_seconds, 3),
        "models": [str(p) for p in result.models],
        "interrupted": interrupted,
    }
    (out / "online.json").write_text(json.dumps(doc, indent=2, default=str) + "\n")
    if log:
        log(f"{episodes} episodes, {result.swaps} model swaps, {transitions} transitions, "
            f"{train_seconds:.1f} s of {search_seconds:.1f} s training; wrote {out}")
    return result


# -- the benchmark -------------------------------------------------------------------------------
def values_at(trace: Sequence[tuple[float, float]], checkpoints: Sequence[float]) -> list[float]:
    """The value of a trace ``(seconds, value)`` at each checkpoint: its last value at or before
    it (NaN before the first), as ``asp bench mcts`` reads its traces."""
    out = []
    for t in checkpoints:
        v = math.nan
        for s, value in trace:
            if s <= t:
                v = value
            else:
                break
        out.append(v)
    return out


def _trace_of(csv: str) -> tuple[list[tuple[float, float]], int]:
    rows = [line.split(",") for line in csv.strip().splitlines()[1:] if line.strip()]
    trace = [(float(r[2]), float(r[3])) for r in rows]
    episodes = int(rows[-1][0]) if rows else 0
    return trace, episodes


def _mean_std(values: Sequence[float]) -> dict:
    if not values:
        return {"mean": 0.0, "std": 0.0}
    a = np.asarray(values, dtype=np.float64)
    mean = float(a.mean())
    return {"mean": mean if math.isfinite(mean) else None, "std": float(a.std()) if math.isfinite(mean) else None}


def bench_mcts(
    models: Sequence[str | os.PathLike],
    objective: str,
    settings: Sequence[str],
    checkpoints: Sequence[float],
    runs: int = 1,
    q: Sequence[str] | None = None,
    config: OnlineConfig | None = None,
    load: dict | None = None,
    work: Path | None = None,
    log: Callable[[str], None] | None = _log_stderr,
) -> tuple[str, str, list[dict]]:
    """Each setting of :data:`SETTINGS` named in ``settings`` searches each model for the last
    checkpoint's wall time, ``runs`` times (seeds 0, 1, ...); returns ``asp bench mcts``'s table,
    its CSV and the rows. ``vanilla`` and ``pretrained`` run :meth:`asp.Assembly.plan` (one
    thread), ``online`` and ``retrained`` :func:`run_online` (training time counts)."""
    import tempfile

    import asp
    from asp import _asp

    unknown = [s for s in settings if s not in SETTINGS]
    if unknown:
        raise DataError(f"unknown setting '{unknown[0]}' (known: {', '.join(SETTINGS)})")
    if any(s in ("pretrained", "retrained") for s in settings) and not q:
        raise DataError("the pretrained and retrained settings need --q MODELS (one per objective)")
    if not checkpoints or any(not (t > 0) for t in checkpoints) or any(a >= b for a, b in zip(checkpoints, checkpoints[1:])):
        raise DataError(f"checkpoints must be positive and increasing, got {list(checkpoints)}")
    objectives = [o.strip() for o in objective.split(",") if o.strip()]
    base = config or OnlineConfig(objective=objective)
    last = float(checkpoints[-1])
    measure = "hypervolume" if len(objectives) > 1 else objectives[0]
    rows: list[dict] = []
    items = [(path, name) for (path, _, name, _) in _asp.model_items([os.fspath(m) for m in models])]
    with tempfile.TemporaryDirectory() as tmp:
        scratch = Path(work) if work is not None else Path(tmp)
        for path, name in items:
            assembly = asp.load(path, **(load or {}))
            for setting in settings:
                per_checkpoint: list[list[float]] = [[] for _ in checkpoints]
                episodes: list[float] = []
                map_seconds = 0.0
                for run in range(runs):
                    if setting in ("vanilla", "pretrained"):
                        kw = PlanSettings(objective=objectives, pareto=len(objectives) > 1, seed=run, threads=1, time_limit=last,
                                          episodes=10**12, budget=base.budget, resolution=base.resolution)
                        kw["q"] = "none"  # vanilla: no learned guidance, not even asp's default
                        if setting == "pretrained":
                            kw["q"] = list(q or [])
                            if base.epsilon is not None:
                                kw["epsilon"] = base.epsilon
                            if base.q_use is not None:
                                kw["q_use"] = base.q_use
                        kw.update(base.search or {})  # type: ignore[typeddict-item]
                        plan = assembly.plan(**kw)
                        trace, done = _trace_of(plan.trace_csv or "")
                    else:
                        c = replace(base, objective=objective, seconds=last, seed=run, q=list(q or []) if setting == "retrained" else None)
                        r = run_online(path, scratch / f"{name}-{setting}-{run}", c, load=load, log=None)
                        plan = r.plan
                        trace, done = _trace_of(plan.trace_csv or "")
                    opt = plan.optimisation or {}
                    map_seconds = float(opt.get("map_seconds", 0.0))
                    for k, v in enumerate(values_at(trace, checkpoints)):
                        per_checkpoint[k].append(v)
                    episodes.append(float(done))
                    if log:
                        log(f"{name} {setting} run {run}: {done} episodes, " + ", ".join(
                            f"{v:.6g} at {t:g} s" for t, v in zip(checkpoints, values_at(trace, checkpoints))))
                rows.append({
                    "model": name,
                    "setting": setting,
                    "measure": measure,
                    "checkpoints": [float(t) for t in checkpoints],
                    "values": [_mean_std(v) for v in per_checkpoint],
                    "episodes": _mean_std(episodes),
                    "runs": runs,
                    "map_seconds": map_seconds,
                })
    table, csv = _asp.mcts_table([json.dumps(rows)])
    return table, csv, rows
