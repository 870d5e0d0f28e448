""":func:`load`, :class:`Assembly` (a loaded model) and :class:`Part`; :func:`plan` loads and plans
in one call."""

from __future__ import annotations

import inspect
import math
import os
from dataclasses import dataclass
from typing import Any, Iterable, Optional, Sequence, Tuple, Union

from asp import _asp
from asp.errors import ConfigError
from asp.graph import Graph
from asp.qgraphs import QGraphs
from asp.result import Plan

__all__ = ["Assembly", "Part", "load", "plan"]

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Part:
    """A part of a model: its index (the number asp uses for it everywhere), name and whether it
    is a base part that stays in place."""

    index: int
    name: str
    fixed: bool


def load(
    path: PathLike,
    *,
    unit: Optional[str] = None,
    up: Optional[str] = None,
    fixed: Iterable[str] = (),
) -> "Assembly":
    """Loads a model: a ``.glb``/``.gltf`` file, or a folder of ``.obj``/``.stl`` files (one part
    per file).

    :param unit: the unit of the coordinates: ``m``, ``cm``, ``mm``, ``in``, ``ft`` or metres per
        unit (default: what the file says, else metres).
    :param up: the up axis, ``x``, ``y``, ``z``, ``-x``, ``-y``, ``-z`` (default: what the file
        says, else +Y for glTF and +Z for OBJ/STL).
    :param fixed: names of base parts, on top of those the file marks as fixed. Without any, a
        ground plane under the lowest point is the base.
    :raises LoadError: the file cannot be read or is not a model (the message names the file).
    :raises ConfigError: an unknown unit or axis, or a fixed part the model does not have.
    """
    if isinstance(fixed, str):
        fixed = [fixed]
    native = _asp.load(os.fspath(path), unit=unit, up=up, fixed=list(fixed))
    return Assembly(native)


class Assembly:
    """A loaded model. It owns its data: it stays valid whatever happens to the file, and plans
    any number of times (each plan builds its collision world afresh; :meth:`graph` caches the
    model's graph features)."""

    __slots__ = ("_native", "_parts")

    def __init__(self, native: "_asp.Assembly") -> None:
        """Wraps a native assembly; use :func:`load` to make one."""
        if not isinstance(native, _asp.Assembly):
            raise TypeError("use asp.load(path) to load an assembly")
        self._native = native
        self._parts = tuple(Part(i, name, fixed) for i, name, fixed in native.parts())

    @property
    def parts(self) -> Tuple[Part, ...]:
        """The parts in file order (``parts[i].index == i``)."""
        return self._parts

    @property
    def source(self) -> str:
        """The model file or folder, as given to :func:`load`."""
        return self._native.source

    @property
    def units(self) -> str:
        """The unit of the model's coordinates (``m``, ``mm``, ...)."""
        return self._native.units

    @property
    def metres_per_unit(self) -> float:
        """Metres per model unit."""
        return self._native.metres_per_unit

    @property
    def up(self) -> str:
        """The up axis (``+z``, ...); gravity points the other way."""
        return self._native.up

    @property
    def warnings(self) -> Tuple[str, ...]:
        """Non-fatal problems found while loading, one line each, naming the part."""
        return tuple(self._native.warnings)

    def __len__(self) -> int:
        return len(self._parts)

    def __repr__(self) -> str:
        return f"<asp.Assembly {self.source}: {len(self)} parts, {self.units}, up {self.up}>"

    def part(self, name: str) -> Part:
        """The part called ``name`` (a ``KeyError`` if there is none)."""
        for p in self._parts:
            if p.name == name:
                return p
        raise KeyError(name)

    def plan(
        self,
        *,
        order: str = "given",
        model: Optional[str] = None,
        bookkeeping: bool = False,
        seed: int = 0,
        tolerance: Optional[float] = None,
        contact_distance: Optional[float] = None,
        normals: int = 10,
        sphere_directions: int = 0,
        overlaps: str = "strict",
        stability: str = "contact",
        physics_threshold: float = 0.01,
        path_planner: bool = True,
        subassemblies: bool = True,
        rrt_iterations: int = 2000,
        rrt_time: float = 5.0,
        max_tests: Optional[int] = None,
        timeout: Optional[float] = 60.0,
        objective: Union[str, Sequence[str], None] = None,
        pareto: bool = False,
        episodes: int = 1000,
        budget: int = 5,
        threads: Optional[int] = None,
        time_limit: Optional[float] = None,
        exploration: float = math.sqrt(0.5),
        polish: float = 0.25,
        resolution: int = 9,
        d_max: Optional[float] = None,
        support: str = "below",
        q: Union[str, Sequence[str], None] = None,
        epsilon: float = 0.2,
        q_use: str = "rollouts",
    ) -> Plan:
        """Plans an assembly sequence: the pipeline of ``asp plan``, with the same settings under
        the flags' names (``--max-tests`` is ``max_tests``, ``--no-path-planner`` is
        ``path_planner=False``). Lengths are in model units.

        :param order: part ordering of the depth-first search: ``given`` (the model's order),
            ``shuffled`` (one order drawn from ``seed`` and kept: the thesis' vanilla AbD),
            ``random`` (a fresh order in every state), ``bookkeeping`` (``given`` with
            bookkeeping), ``gnn`` (the learned ordering).
        :param model: the removability model (ONNX) of ``order="gnn"`` (default: the model
            shipped with asp).
        :param bookkeeping: skip retesting a part until one of its blockers is gone.
        :param seed: seed of every random choice.
        :param tolerance: contact tolerance (default 1e-4 × the model's diagonal).
        :param contact_distance: parts closer than this touch, for stability (default 1e-3 × the
            diagonal).
        :param normals: clustered surface-normal directions tried besides the six axes.
        :param sphere_directions: extra removal directions sampled evenly on the sphere.
        :param overlaps: parts that overlap in the input (press fits, dowels, screws, slop; warned
            once per pair with the measured depth, listed in the plan's ``overlaps``):
            ``strict`` (they separate only along motions that enter no new material of each
            other), ``lenient`` (shrink one of them; ignore pairs no shrinking separates) or
            ``error`` (raise :class:`LoadError` on pairs no shrinking separates).
        :param stability: ``contact`` (linked through contacts to a base part) or ``physics``
            (rapier3d simulation).
        :param physics_threshold: physics stability: how far (fraction of the diagonal) a part
            may move.
        :param path_planner: try the RRT path planner when no straight line works.
        :param subassemblies: let groups of parts leave together as one rigid subassembly when
            no single part can (each planned on its own base; ``--no-subassemblies`` is
            ``subassemblies=False``).
        :param rrt_iterations: path planner iterations per call.
        :param rrt_time: path planner wall-time cap per call, seconds.
        :param max_tests: stop after this many removal tests (status ``budget_exhausted``).
        :param timeout: stop after this many seconds (status ``budget_exhausted`` with the
            best partial plan); ``None`` for no limit.
        :param objective: optimise instead (MCTS on distance maps): ``access``, ``dirchange``,
            ``pathlen``, comma-separated or a list; several need ``pareto=True``.
        :param pareto: Pareto-MCTS over the objectives.
        :param episodes: MCTS episodes.
        :param budget: MCTS iterations per step.
        :param threads: optimiser threads (default: all cores).
        :param time_limit: optimiser wall-time limit, seconds.
        :param exploration: exploration constant of UCT / MOUCB.
        :param polish: local search over the answer's sequences (block moves of 1-3 removals
            around every sequence the search finds) may take this share of the search's work;
            0 turns it off.
        :param resolution: distance map resolution N_M (odd, 3 to 15).
        :param d_max: distance map cap, model units (default the diagonal).
        :param support: the optimiser's gravity check, ``below`` or ``contact``.
        :param q: learned Q-functions (ONNX files of ``python -m asp.train q``), one per objective
            in ``objective``'s order (a comma-separated string or a list): rollouts take the
            removal with the largest Q-value (the product for several objectives) instead of a
            random one, except with probability ``epsilon`` (thesis 5.4.5, 6.4.4).
        :param epsilon: probability of a random removal in a rollout (or expansion) guided by ``q``.
        :param q_use: where ``q`` guides: ``rollouts`` (the thesis: one evaluation per rollout
            step), ``expansions`` (the Q-values of every state the search adds order its
            expansions, rollouts stay random: one evaluation per node) or ``both``.
        :raises ConfigError: a setting is unknown, of the wrong type or out of range.
        :raises LoadError: the model cannot be planned as given (parts overlapping beyond
            repair, ...).
        :raises KeyboardInterrupt: Ctrl-C while planning or optimising (checked every 50 ms; a
            state whose tests take long, such as a path planner call, delays it until it ends).

        The GIL is released while planning.
        """
        if isinstance(objective, (list, tuple)):
            objective = list(objective)
        settings = {
            "order": order,
            "model": None if model is None else str(model),
            "bookkeeping": bookkeeping,
            "seed": seed,
            "tolerance": tolerance,
            "contact_distance": contact_distance,
            "normals": normals,
            "sphere_directions": sphere_directions,
            "overlaps": overlaps,
            "stability": stability,
            "physics_threshold": physics_threshold,
            "path_planner": path_planner,
            "subassemblies": subassemblies,
            "rrt_iterations": rrt_iterations,
            "rrt_time": rrt_time,
            "max_tests": max_tests,
            "timeout": timeout,
            "objective": objective,
            "pareto": pareto,
            "episodes": episodes,
            "budget": budget,
            "threads": threads,
            "time_limit": time_limit,
            "exploration": exploration,
            "polish": polish,
            "resolution": resolution,
            "d_max": d_max,
            "support": support,
            "q": q if q is None or isinstance(q, str) else ",".join(os.fspath(m) for m in q),
            "epsilon": epsilon,
            "q_use": q_use,
        }
        json, found, trace = self._native.plan(settings)
        return Plan(json, found, trace)

    def search(self, *, record: bool = True, **settings: Any) -> "Search":
        """A stepped optimiser run: the search of :meth:`plan` with ``objective``, run episode by
        episode on one thread (its tree kept between episodes), with Q-functions swapped in
        between episodes — what the online settings of thesis 6.5 need
        (``python -m asp.train q-online``).

        :param record: record each episode's transitions (the ``asp-transitions`` records).
        :param settings: the keywords of :meth:`plan` (``objective`` required; ``threads`` is 1,
            ``episodes`` the most episodes, ``time_limit`` the wall time from the first episode,
            ``q`` the first episodes' Q models).
        :raises ConfigError: no objective, or a bad setting (as :meth:`plan`).
        :raises TypeError: an unknown keyword.

        The maps are built here, without the GIL; see :class:`asp.Search`.
        """
        from asp.search import Search

        bound = inspect.signature(Assembly.plan).bind(self, **settings)
        bound.apply_defaults()
        kw = dict(bound.arguments)
        del kw["self"]
        if kw.get("objective") is None:
            raise ConfigError("objective: a search needs objectives")
        if isinstance(kw["objective"], (list, tuple)):
            kw["objective"] = list(kw["objective"])
        if kw.get("model") is not None:
            kw["model"] = str(kw["model"])
        q = kw.get("q")
        if q is not None and not isinstance(q, str):
            kw["q"] = ",".join(os.fspath(m) for m in q)
        kw["threads"] = 1
        return Search(self._native.search(kw, record), kw)

    def graph(
        self,
        present: Optional[Iterable[int]] = None,
        *,
        tolerance: Optional[float] = None,
        contact_distance: Optional[float] = None,
        overlaps: str = "strict",
        radius_bins: int = 8,
        degree: int = 8,
        points_per_part: int = 2048,
    ) -> Graph:
        """The graph of a disassembly state (thesis 3.4, ``docs/learning.md``) as numpy arrays,
        laid out as a removability model's inputs.

        :param present: the part indices present in the state (default: every part).
        :param tolerance: as in :meth:`plan` (the collision world the contacts come from).
        :param contact_distance: as in :meth:`plan`: parts closer than this are joined by edges.
        :param overlaps: as in :meth:`plan`.
        :param radius_bins: radius shells of the shape descriptor.
        :param degree: highest spherical-harmonic degree of the descriptor.
        :param points_per_part: target number of surface samples per part.
        :raises ConfigError: a part index out of range or a bad feature parameter.

        The model's graph is computed once per set of these settings and cached; each state is
        an induced subgraph of it.
        """
        parts = list(range(len(self))) if present is None else [int(p) for p in present]
        settings = {
            "tolerance": tolerance,
            "contact_distance": contact_distance,
            "overlaps": overlaps,
            "radius_bins": radius_bins,
            "degree": degree,
            "points_per_part": points_per_part,
        }
        return Graph._from_native(self._native.graph(parts, settings))


    def q_graphs(
        self,
        *,
        objective: Union[str, Sequence[str]],
        resolution: int = 9,
        d_max: Optional[float] = None,
        support: str = "below",
        tolerance: Optional[float] = None,
        contact_distance: Optional[float] = None,
        overlaps: str = "strict",
        neighbours: int = 8,
    ) -> "QGraphs":
        """The distance maps and optimisation problem of this model (as :meth:`plan` with
        ``objective`` builds them), as a :class:`QGraphs` that gives the graph of any optimiser
        state in the layout of a Q model's inputs (``docs/learning.md``, features ``asp-q/1``).

        :param objective: the objectives (a comma-separated string or a list), as in :meth:`plan`.
        :param resolution: distance map resolution (``resolution²`` directions).
        :param d_max: cap of the distance maps, model units (default: the model's diagonal).
        :param support: the optimiser's gravity check, ``below`` or ``contact``.
        :param tolerance: as in :meth:`plan`.
        :param contact_distance: as in :meth:`plan`.
        :param overlaps: as in :meth:`plan`.
        :param neighbours: nearest parts each part node gets an edge from (``K``).
        :raises ConfigError: an unknown objective or a bad value.
        """
        settings = {
            "objective": objective if isinstance(objective, str) else list(objective),
            "resolution": resolution,
            "d_max": d_max,
            "support": support,
            "tolerance": tolerance,
            "contact_distance": contact_distance,
            "overlaps": overlaps,
            "neighbours": neighbours,
        }
        return QGraphs(self._native.q_graphs(settings))


def plan(
    path: PathLike,
    *,
    unit: Optional[str] = None,
    up: Optional[str] = None,
    fixed: Iterable[str] = (),
    **settings: Any,
) -> Plan:
    """Loads the model at ``path`` (:func:`load`) and plans it (:meth:`Assembly.plan`, whose
    keywords ``settings`` are)."""
    return load(path, unit=unit, up=up, fixed=fixed).plan(**settings)
