"""The stepped optimiser run of :meth:`asp.Assembly.search` (thesis 6.5's online settings)."""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass

from asp import _asp
from asp.result import Plan

__all__ = ["Episode", "Search"]


@dataclass(frozen=True)
class Episode:
    """What one episode of a :class:`Search` did."""

    transitions_jsonl: str
    """Its transitions as lines of ``transitions.jsonl`` (the ``asp-transitions`` records, one
    JSON object per line; empty without recording)."""
    episodes: int
    """Episodes finished so far."""
    iterations: int
    """Its iterations."""
    seconds: float
    """Seconds since the previous episode ended (the caller's time between them included)."""
    value: float
    """The front's hypervolume (several objectives) or the best total so far (0 before any)."""
    front_size: int
    """Points on the front so far."""
    finished: bool
    """The search has ended after it (no more episodes)."""
    exhausted: bool
    """Every sequence has been explored."""
    stopped: bool
    """The time limit stopped it (it counts only when it finished)."""
    capped: bool
    """It reached the recording limit."""

    @property
    def records(self) -> list[dict]:
        """The transitions as dictionaries."""
        return [json.loads(line) for line in self.transitions_jsonl.splitlines() if line.strip()]


class Search:
    """A search running episode by episode on its own thread (from :meth:`asp.Assembly.search`).

    >>> s = asp.load("cube.glb").search(objective="access", seed=1)     # doctest: +SKIP
    >>> e = s.episode()                      # its transitions: e.records
    >>> s.set_q(["q_access.onnx"])           # guides the episodes from the next one on
    >>> plan = s.result()                    # ends the search: the plan, as Assembly.plan gives

    The same model, settings, seed and sequence of Q models give the same episodes and plan.
    Waiting releases the GIL; Ctrl-C stops the running episode, ends the search and raises
    ``KeyboardInterrupt`` (:meth:`result` then gives the plan of the episodes finished).
    """

    def __init__(self, native: _asp.Search, settings: dict) -> None:
        self._native = native
        self._settings = settings

    @property
    def index(self) -> dict:
        """The ``index.json`` of the run's transitions as a data set of one model (folder
        ``model``): features, dimensions, objectives, reward ranges and how to rebuild the maps.
        Its counts are 0; who writes the episodes' lines sets them."""
        return json.loads(self._native.index_json)

    @property
    def objectives(self) -> list[str]:
        """The objectives, in the order of every transition's ``rewards``."""
        return list(self.index["objectives"])

    @property
    def swaps(self) -> int:
        """Q models swapped in so far (:meth:`set_q` followed by an episode)."""
        return self._native.swaps

    @property
    def ended(self) -> bool:
        """Whether the search has ended."""
        return self._native.ended

    def episode(self) -> Episode:
        """Runs the next episode (with the Q models last set) and returns what it did.

        :raises ConfigError: the search has ended.
        :raises KeyboardInterrupt: Ctrl-C (the search ends).
        """
        r = self._native.episode()
        return Episode(
            transitions_jsonl=r.transitions_jsonl, episodes=r.episodes, iterations=r.iterations, seconds=r.seconds,
            value=r.value, front_size=r.front_size, finished=r.finished, exhausted=r.exhausted, stopped=r.stopped,
            capped=r.capped,
        )

    def set_q(self, models: str | Sequence[str | os.PathLike[str]], epsilon: float | None = None, q_use: str | None = None) -> None:
        """Guides the episodes from the next one on by the ε-greedy policy over these Q models (ONNX
        files of ``python -m asp.train``, one per objective in their order). The files are read
        now. ``epsilon`` and ``q_use`` default to the search's settings."""
        paths = [models] if isinstance(models, (str, os.PathLike)) else list(models)
        if len(paths) == 1 and isinstance(paths[0], str) and "," in paths[0]:
            paths = [p.strip() for p in paths[0].split(",") if p.strip()]
        self._native.set_q(
            [os.fspath(p) for p in paths],
            self._settings.get("epsilon") if epsilon is None else epsilon,
            self._settings.get("q_use") if q_use is None else q_use,
        )

    def result(self) -> Plan:
        """Ends the search (after the running episode) and returns its plan, as
        :meth:`asp.Assembly.plan` returns it for the episodes run (with its trace)."""
        plan_json, found, trace = self._native.result()
        return Plan(plan_json, found, trace)

    def __repr__(self) -> str:
        return f"<asp.Search {','.join(self.objectives)}: {'ended' if self.ended else 'running'}, {self.swaps} swaps>"
