"""Reader of the ``asp-transitions`` data set (format version 1, docs/learning.md, "Q-functions").

Also importable as :mod:`asp.qdata`.

Needs only NumPy. A data set is one folder::

    index.json                format, version, features, node_dim, edge_dim, objectives, assemblies
    <dir>/transitions.jsonl   one transition (s, a, rewards, s') per line

``transitions.jsonl`` is read line by line, so a data set never has to fit in memory. The graphs of
the states are not stored: each assembly names its model file and the keyword arguments of
``asp.load`` and ``Assembly.q_graphs`` that rebuild them (:mod:`asp.train.q` does). Every problem
is reported as a :class:`~asp.datasets.DataError` whose message is one line naming the file (and the
line of ``transitions.jsonl``) and the cause.

Example::

    ds = TransitionDataset.open("runs/q5")
    k = ds.objective_index("access")
    for a in ds.assemblies:
        for t in a.transitions():
            r = a.normalised_reward(t, k)        # r~ of the contract
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .jsonl import (
    DataError,
    _fail,
    _int_field,
    _int_list,
    _optional_int,
    _str_field,
    assembly_entries,
    check_ascending,
    parse_line,
    part_list,
    read_index,
    stream_jsonl,
)

__all__ = [
    "FORMAT",
    "VERSION",
    "KINDS",
    "DataError",
    "Transition",
    "TransitionAssembly",
    "TransitionDataset",
    "directions_of",
]

#: The ``format`` field of ``index.json``.
FORMAT = "asp-transitions"
#: The only format version this reader knows.
VERSION = 1
#: The values of a transition's ``kind``.
KINDS = ("expansion", "simulation")

_DIRECTIONS = re.compile(r"(?:^|\s)directions=(\d+)(?:\s|$)")


def directions_of(features: str) -> int | None:
    """``D`` of an ``asp-q/1 directions=D ...`` features string (``None`` when it names none)."""
    m = _DIRECTIONS.search(features)
    return int(m.group(1)) if m else None


@dataclass(frozen=True)
class Transition:
    """One recorded removal ``(s, a, rewards, s')`` of the optimiser."""

    episode: int
    """The collection episode."""
    kind: str
    """``"expansion"`` (a step of the search tree) or ``"simulation"`` (a rollout step)."""
    present: np.ndarray
    """int64, ascending part indices of the state ``s``."""
    history: np.ndarray
    """int64 direction indices of the ``dirchange`` history ``H`` in ``s`` (may be empty)."""
    actions: np.ndarray
    """int64 part indices: the feasible removals of ``s`` (``action`` among them)."""
    action: int
    """The part removed."""
    rewards: np.ndarray
    """float64 raw reward of each objective of the data set, in ``objectives`` order."""
    next_history: np.ndarray
    """int64 direction history after the removal."""
    next_actions: np.ndarray
    """int64 feasible removals of ``s'`` (empty: the episode ends there)."""
    complete: bool
    """Whether ``s'`` has no removable part left (else, with no next action, a dead end)."""

    @property
    def next_present(self) -> np.ndarray:
        """``s'``: ``present`` without ``action`` (ascending)."""
        return self.present[self.present != self.action]

    @property
    def terminal(self) -> bool:
        """No removal follows (``next_actions`` is empty): the target does not bootstrap."""
        return len(self.next_actions) == 0


@dataclass(frozen=True)
class TransitionAssembly:
    """One assembly of a transitions data set: how to rebuild its graphs, and its transitions."""

    name: str
    """The assembly's name."""
    dir: Path
    """Its folder."""
    model: str
    """The model file the transitions were collected on."""
    load: dict
    """Keyword arguments of ``asp.load(model, **load)``."""
    maps: dict
    """Keyword arguments of ``Assembly.q_graphs(**maps)``."""
    parts: int
    """Parts ``N`` of the model (fixed ones included)."""
    removable: int
    """``N_r``: the parts that are not fixed (the normalisation of rewards)."""
    reward_ranges: np.ndarray
    """float64 ``[K, 2]``: ``[lo_k, hi_k]`` per objective."""
    num_transitions: int
    """The number of transitions ``index.json`` announces."""
    transitions_path: Path
    """The ``transitions.jsonl`` file."""
    objectives: tuple[str, ...]
    """The data set's objectives (the order of ``rewards``)."""
    directions: int | None
    """``D`` of the features (history entries are below it), when the features string names it."""

    def normalised_reward(self, t: Transition, objective: int) -> float:
        """``r~ = (r - lo) / (hi - lo) / N_r`` of objective number ``objective`` (0 when ``hi == lo``:
        an objective constant on this model gives every removal the same, uninformative, reward)."""
        lo, hi = self.reward_ranges[objective]
        if hi <= lo:
            return 0.0
        return float((t.rewards[objective] - lo) / (hi - lo) / max(self.removable, 1))

    def transitions(self) -> Iterator[Transition]:
        """Stream the transitions of ``transitions.jsonl``, validating each line."""
        return stream_jsonl(self.transitions_path, self.num_transitions, "transition", self._check)

    def parse(self, line: str, lineno: int) -> Transition:
        """One line of ``transitions.jsonl`` (line number ``lineno``, for messages), validated."""
        return parse_line(self.transitions_path, line, lineno, "transition", self._check)

    # -- validation ----------------------------------------------------------------------------
    def _check(self, obj: dict[str, Any], where: str) -> Transition:
        episode = obj.get("episode")
        if isinstance(episode, bool) or not isinstance(episode, int) or episode < 0:
            raise DataError(f"{where}: 'episode' must be a non-negative integer, found {json.dumps(episode)}")
        kind = obj.get("kind")
        if kind not in KINDS:
            raise DataError(f"{where}: 'kind' must be \"expansion\" or \"simulation\", found {json.dumps(kind)}")
        present = part_list(obj, "present", where, self.parts)
        check_ascending(present, "present", where)
        actions = part_list(obj, "actions", where, self.parts)
        self._subset(actions, present, "actions", "'present'", where)
        action = obj.get("action")
        if isinstance(action, bool) or not isinstance(action, int):
            raise DataError(f"{where}: 'action' must be a part index, found {json.dumps(action)}")
        if action not in set(actions.tolist()):
            raise DataError(f"{where}: 'action' {action} is not one of 'actions'")
        rewards = obj.get("rewards")
        k = len(self.objectives)
        if (
            not isinstance(rewards, list)
            or len(rewards) != k
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in rewards)
        ):
            raise DataError(f"{where}: 'rewards' must be a list of {k} numbers (one per objective)")
        rewards_array = np.asarray(rewards, dtype=np.float64)
        if not np.all(np.isfinite(rewards_array)):
            raise DataError(f"{where}: 'rewards' must be finite")
        history = self._directions(obj, "history", where)
        next_history = self._directions(obj, "next_history", where)
        next_actions = part_list(obj, "next_actions", where, self.parts)
        rest = present[present != action]
        self._subset(next_actions, rest, "next_actions", "'present' without 'action'", where)
        complete = obj.get("complete")
        if not isinstance(complete, bool):
            raise DataError(f"{where}: 'complete' must be true or false")
        if complete and len(next_actions):
            raise DataError(f"{where}: 'complete' is true but 'next_actions' is not empty")
        return Transition(
            episode=episode,
            kind=kind,
            present=present,
            history=history,
            actions=actions,
            action=action,
            rewards=rewards_array,
            next_history=next_history,
            next_actions=next_actions,
            complete=complete,
        )

    def _directions(self, obj: dict, key: str, where: str) -> np.ndarray:
        array = _int_list(obj, key, where, "direction indices")
        limit = self.directions
        bad = array[(array < 0) | (array >= limit)] if limit is not None else array[array < 0]
        if bad.size:
            span = f"0..{limit - 1}" if limit is not None else "non-negative"
            raise DataError(f"{where}: '{key}' holds direction {int(bad[0])}, directions are {span}")
        return array

    @staticmethod
    def _subset(items: np.ndarray, of: np.ndarray, key: str, what: str, where: str) -> None:
        if len(np.unique(items)) != len(items):
            raise DataError(f"{where}: '{key}' lists a part twice")
        outside = items[~np.isin(items, of)]
        if outside.size:
            raise DataError(f"{where}: '{key}' names part {int(outside[0])}, which is not in {what}")


@dataclass(frozen=True)
class TransitionDataset:
    """An opened ``asp-transitions`` data set (validated ``index.json``; transitions stream later)."""

    root: Path
    """The data set folder."""
    features: str
    """The features string of the state graphs (``asp-q/1 directions=D neighbours=K``)."""
    node_dim: int
    """Floats per node attribute."""
    edge_dim: int
    """Floats per edge attribute."""
    objectives: tuple[str, ...]
    """The objectives whose rewards every transition carries, in order."""
    seed: int | None
    """The collection seed, when recorded."""
    episodes: int | None
    """Collection episodes per assembly, when recorded."""
    assemblies: list[TransitionAssembly]
    """The assemblies, in index order."""

    @property
    def index_path(self) -> Path:
        """``index.json``."""
        return self.root / "index.json"

    @classmethod
    def open(cls, root: os.PathLike | str) -> TransitionDataset:
        """Open and validate a data set folder (its index; the transitions are read when streamed)."""
        root = Path(root)
        path = root / "index.json"
        index, features, node_dim, edge_dim = read_index(path, FORMAT, VERSION)
        objectives = index.get("objectives")
        if (
            not isinstance(objectives, list)
            or not objectives
            or not all(isinstance(o, str) and o for o in objectives)
        ):
            raise _fail(path, "'objectives' must be a non-empty list of objective names")
        if len(set(objectives)) != len(objectives):
            raise _fail(path, "'objectives' names an objective twice")
        seed, episodes = _optional_int(index, "seed"), _optional_int(index, "episodes")
        directions = directions_of(features)
        assemblies: list[TransitionAssembly] = []
        for where, entry, name, sub in assembly_entries(path, index):
            model = _str_field(path, entry, "model", where)
            for key in ("load", "maps"):
                if not isinstance(entry.get(key), dict):
                    raise _fail(path, f"{where}'{key}' must be an object (keyword arguments)")
            parts = _int_field(path, entry, "parts", where, minimum=1)
            removable = _int_field(path, entry, "removable", where)
            if removable > parts:
                raise _fail(path, f"{where}'removable' {removable} exceeds 'parts' {parts}")
            ranges = entry.get("reward_ranges")
            if (
                not isinstance(ranges, list)
                or len(ranges) != len(objectives)
                or not all(
                    isinstance(r, list)
                    and len(r) == 2
                    and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in r)
                    for r in ranges
                )
            ):
                raise _fail(path, f"{where}'reward_ranges' must hold one [lo, hi] pair per objective ({len(objectives)})")
            ranges_array = np.asarray(ranges, dtype=np.float64).reshape(len(objectives), 2)
            for o, (lo, hi) in zip(objectives, ranges_array):
                if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
                    raise _fail(path, f"{where}reward range of '{o}' must be finite with lo <= hi, found [{lo:g}, {hi:g}]")
            transitions = _int_field(path, entry, "transitions", where)
            assemblies.append(
                TransitionAssembly(
                    name=name,
                    dir=root / sub,
                    model=model,
                    load=dict(entry["load"]),
                    maps=dict(entry["maps"]),
                    parts=parts,
                    removable=removable,
                    reward_ranges=ranges_array,
                    num_transitions=transitions,
                    transitions_path=root / sub / "transitions.jsonl",
                    objectives=tuple(objectives),
                    directions=directions,
                )
            )
        return cls(root, features, node_dim, edge_dim, tuple(objectives), seed, episodes, assemblies)

    def objective_index(self, name: str) -> int:
        """The position of objective ``name`` in ``objectives`` (its column of ``rewards``)."""
        if name not in self.objectives:
            raise _fail(self.index_path, f"has no objective '{name}' (it has {', '.join(self.objectives)})")
        return self.objectives.index(name)

    def assembly(self, name: str) -> TransitionAssembly:
        """The assembly called ``name``."""
        for a in self.assemblies:
            if a.name == name:
                return a
        known = ", ".join(a.name for a in self.assemblies)
        raise _fail(self.index_path, f"no assembly named '{name}' (known: {known})")

    def transitions(self) -> Iterator[tuple[TransitionAssembly, Transition]]:
        """Stream every transition of every assembly, assembly by assembly."""
        for a in self.assemblies:
            for t in a.transitions():
                yield a, t
