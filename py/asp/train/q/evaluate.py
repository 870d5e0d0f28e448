"""How well a Q network ranks the actions of a data set's states (:func:`ranking_quality`)."""

from __future__ import annotations

import numpy as np
import torch

from ...datasets.transitions import Transition
from .graphs import GraphCache, GraphSource, _positions
from .network import QNetwork
from .replay import QAssembly, _run

__all__ = ["ranking_quality"]


@torch.no_grad()
def ranking_quality(
    model: QNetwork, source: QAssembly, graph_source: GraphSource, max_states: int = 2000, batch: int = 64
) -> dict:
    """How often the argmax-Q action of a state is the action with the best observed return-to-go.

    Transitions are chained in file order (same episode, each state the previous ``s'``) and each
    step's observed return-to-go is the sum of ``r~`` from it to the end of its chain. For every
    state (present parts and history; the first ``max_states`` met) the best return-to-go observed
    after each action is kept; states with at least two observed actions are scored: a hit when
    the action of highest ``Q`` among the observed ones has the best observed return-to-go (ties
    count). ``chance`` is the expected hit rate of a uniformly random choice; ``regret`` the mean
    shortfall of the chosen action's best return-to-go.
    """
    model.eval()
    states: dict[tuple, dict] = {}

    def flush(chain: list[tuple[Transition, float]]) -> None:
        g = 0.0
        for t, r in reversed(chain):
            g += r
            key = (t.present.tobytes(), t.history.tobytes())
            entry = states.get(key)
            if entry is None:
                if len(states) >= max_states:
                    continue
                entry = states[key] = {"t": t, "returns": {}}
            best = entry["returns"].get(t.action)
            entry["returns"][t.action] = g if best is None else max(best, g)

    chain: list[tuple[Transition, float]] = []
    for t in source.assembly.transitions():
        if chain:
            last = chain[-1][0]
            if (
                t.episode != last.episode
                or not np.array_equal(t.present, last.next_present)
                or not np.array_equal(t.history, last.next_history)
            ):
                flush(chain)
                chain = []
        chain.append((t, source.reward(t)))
        if t.terminal:
            flush(chain)
            chain = []
    flush(chain)

    scored = [e for e in states.values() if len(e["returns"]) >= 2]
    hits = 0
    chance = 0.0
    regret = 0.0
    cache = GraphCache(graph_source, model.node_dim, model.edge_dim, capacity=batch)
    for b in range(0, len(scored), batch):
        chunk = scored[b : b + batch]
        gs = [cache(source.assembly, e["t"].present, e["t"].actions, e["t"].history) for e in chunk]
        q_tensor, offsets = _run(model, gs)
        q = q_tensor.numpy()
        for e, g, off in zip(chunk, gs, offsets):
            acts = np.array(sorted(e["returns"]), dtype=np.int64)
            returns = np.array([e["returns"][int(a)] for a in acts])
            values = q[off + _positions(g, acts, source.assembly)]
            best = returns.max()
            chosen = returns[int(np.argmax(values))]
            hits += int(chosen >= best - 1e-9)
            chance += float(np.mean(returns >= best - 1e-9))
            regret += float(best - chosen)
    n = len(scored)
    return {
        "states": len(states),
        "scored": n,
        "accuracy": hits / n if n else None,
        "chance": chance / n if n else None,
        "regret": regret / n if n else None,
    }
