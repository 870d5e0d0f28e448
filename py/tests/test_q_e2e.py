"""Learned Q-functions end to end, as a user runs them: generate a 4×4×4 Soma cube,
collect transitions from asp's own MCTS (``asp collect transitions``), train the Q-function of
the ``access`` objective by deep Q-learning for a fixed number of steps (``python -m asp.train
q``), then

* the exact optimum of the cube, by dynamic programming over its states in Python (feasible
  removals and the accessibility reward read from ``Assembly.q_graphs``, the same arrays the
  search sees), names the optimal first removals, and the Q-function ranks one of them first;
* rollouts guided by it (``asp plan --q``, ε = 0.2) reach that optimum in fewer episodes than
  random rollouts over the same seeds (within 40 episodes; when neither reaches it, the guided
  searches must end with the better mean total)."""

from __future__ import annotations

import csv
import json
import statistics
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import _asp_command, need

torch = need("torch", "asp.train needs torch (pip install ./py[train])")
onnx_reference = need("onnx.reference", "the Q model is evaluated with onnx's reference evaluator")

import asp  # noqa: E402

#: Episodes a search may take to reach the optimum (a run that does not counts one more).
CAP = 40


def run(cmd: list, cwd: Path) -> subprocess.CompletedProcess:
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, f"{cmd}: exit {r.returncode}\n{r.stderr}"
    return r


def exact(qg: asp.QGraphs) -> tuple[float, dict]:
    """The best total accessibility (in units of d_max) and each first removal's best total."""
    d = qg.directions
    fixed = {p for p in range(qg.num_parts) if qg.graph([p]).x[0, 2] == 1.0}
    memo: dict = {}

    def reward(present: frozenset, part: int) -> float:
        g = qg.graph(sorted(present))
        k = list(g.nodes).index(part)
        return float(g.x[k, 28 : 28 + d].astype(np.float64).sum())

    def value(present: frozenset) -> float:
        if present in memo:
            return memo[present]
        actions = qg.feasible_actions(sorted(present))
        if actions:
            best = max(reward(present, a) + value(present - {a}) for a in actions)
        else:
            best = 0.0 if present <= fixed else float("-inf")  # complete, or a dead end
        memo[present] = best
        return best

    full = frozenset(range(qg.num_parts))
    firsts = {a: reward(full, a) + value(full - {a}) for a in qg.feasible_actions(sorted(full))}
    return max(firsts.values()), firsts


def episodes_to_reach(asp_cmd: list, model: Path, optimum: float, seed: int, flags: list, cwd: Path) -> tuple[int, float]:
    """The episode at which a search first reaches ``optimum`` (``CAP + 1``: not within ``CAP``)
    and the best total it reached, in units of d_max. The local search over the answer is off: it
    would improve either search's sequences, and this compares the rollout policies."""
    trace = cwd / f"trace_{seed}_{len(flags)}.csv"
    r = run(asp_cmd + ["plan", str(model), "--objective", "access", "--threads", "1", "--seed", str(seed),
                       "--episodes", str(CAP), "--trace", str(trace), "--json", "--quiet", "--polish", "0"] + flags, cwd)
    d_max = json.loads(r.stdout)["optimisation"]["d_max"]
    rows = list(csv.DictReader(trace.open()))
    best = max(float(row["value"]) / d_max for row in rows)
    for row in rows:
        if float(row["value"]) / d_max >= optimum * (1 - 1e-5):
            return int(row["episode"]), best
    return CAP + 1, best


def test_a_learned_q_function_ranks_the_optimum_first_and_guides_rollouts_to_it(tmp_path: Path) -> None:
    asp_cmd = _asp_command()
    run(asp_cmd + ["gen", "soma", "--size", "4", "--count", "1", "--seed", "31", "--out", "cube"], tmp_path)
    model = tmp_path / "cube" / "soma4_000.glb"
    run(asp_cmd + ["collect", "transitions", "cube", "--objective", "access", "--episodes", "40", "--seed", "0",
                   "--out", "tr"], tmp_path)
    run([sys.executable, "-m", "asp.train", "q", "tr", "--objective", "access", "--out", "q.onnx", "--steps", "700",
         "--batch", "32", "--seed", "0"], tmp_path)

    qg = asp.load(model).q_graphs(objective="access")
    optimum, firsts = exact(qg)
    best_first = {a for a, v in firsts.items() if v >= optimum * (1 - 1e-9)}
    assert 0 < len(best_first) < len(firsts), firsts  # the test means something

    full = list(range(qg.num_parts))
    actions = qg.feasible_actions(full)
    g = qg.graph(full, actions=actions)
    (q,) = onnx_reference.ReferenceEvaluator(str(tmp_path / "q.onnx")).run(
        None, {"x": g.x, "edge_index": g.edge_index, "edge_attr": g.edge_attr}
    )
    nodes = list(g.nodes)
    ranked = max(actions, key=lambda a: q[nodes.index(a)])
    assert ranked in best_first, (ranked, best_first, {a: float(q[nodes.index(a)]) for a in actions})

    vanilla = [episodes_to_reach(asp_cmd, model, optimum, s, [], tmp_path) for s in range(5)]
    guided = [episodes_to_reach(asp_cmd, model, optimum, s, ["--q", "q.onnx"], tmp_path) for s in range(5)]
    mean = lambda runs, k: statistics.mean(r[k] for r in runs)  # noqa: E731
    print(f"episodes to the optimum {optimum:.4f} and best totals: vanilla {vanilla}, guided {guided}")
    assert mean(guided, 0) < mean(vanilla, 0) or (mean(guided, 0) == mean(vanilla, 0) and mean(guided, 1) > mean(vanilla, 1)), (
        guided,
        vanilla,
    )

    # Q at expansions (`q_use`): with ε = 0, one episode and one iteration per step, the first
    # removal is the root's first expansion, the action the model (run by tract in Rust) ranks first
    plan = asp.load(model).plan(objective="access", q=str(tmp_path / "q.onnx"), q_use="expansions", epsilon=0.0,
                                episodes=1, budget=1, threads=1, seed=0)
    assert plan.found and plan.disassembly_sequence[0] == ranked, (plan.disassembly_sequence, ranked)
    with pytest.raises(asp.ConfigError, match="q_use"):
        asp.load(model).plan(objective="access", q=str(tmp_path / "q.onnx"), q_use="sideways")
