""":class:`QGraphs`: the graphs of optimiser states that learned Q-functions read
(``docs/learning.md``, "Q-functions", features ``asp-q/1``)."""

from __future__ import annotations

from collections.abc import Iterable

from asp import _asp
from asp.graph import Graph

__all__ = ["QGraphs"]


class QGraphs:
    """One model's distance maps and optimisation problem (from :meth:`asp.Assembly.q_graphs`),
    giving the ``asp-q/1`` graph of any state: the same arrays the search's Q-function sees.

    Nodes are the present parts (ascending) and a context node last (part index ``-1``) that
    carries the ``dirchange`` history; see ``docs/learning.md`` for every column.
    """

    def __init__(self, native: _asp.QGraphs) -> None:
        self._native = native

    @property
    def features(self) -> str:
        """The feature set and its parameters (``asp-q/1 directions=81 neighbours=8``)."""
        return self._native.features

    @property
    def node_dim(self) -> int:
        """Floats per node."""
        return self._native.node_dim

    @property
    def edge_dim(self) -> int:
        """Floats per edge."""
        return self._native.edge_dim

    @property
    def directions(self) -> int:
        """Directions of the distance maps (``D``)."""
        return self._native.directions

    @property
    def num_parts(self) -> int:
        """Parts of the model."""
        return self._native.num_parts

    @property
    def removable(self) -> int:
        """Parts that are not fixed (``N_r`` of the normalised returns)."""
        return self._native.removable

    @property
    def objectives(self) -> tuple[str, ...]:
        """The objectives' names."""
        return tuple(self._native.objectives)

    @property
    def reward_ranges(self) -> tuple[tuple[float, float] | None, ...]:
        """Each objective's per-step reward range ``(lo, hi)`` on these maps (``None``: none)."""
        return tuple(self._native.reward_ranges)

    def feasible_actions(self, present: Iterable[int]) -> list[int]:
        """The parts removable from the state ``present`` on the maps (collision-free along some
        direction, not fixed, the rest supported), ascending."""
        return list(self._native.feasible_actions([int(p) for p in present]))

    def graph(self, present: Iterable[int], actions: Iterable[int] = (), history: Iterable[int] = ()) -> Graph:
        """The graph of the state ``present`` (part indices), with the feasible ``actions`` flagged
        and the ``dirchange`` direction history ``history`` (direction indices; empty before the
        first removal) on the context node.

        :raises ConfigError: a part or direction out of range, or an action that is not present.
        """
        raw = self._native.graph([int(p) for p in present], [int(a) for a in actions], [int(h) for h in history])
        return Graph._from_native(raw)

    def __repr__(self) -> str:
        return repr(self._native).replace("asp._asp.", "asp.")
