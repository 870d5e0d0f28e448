""":func:`load`, :class:`Assembly` (a loaded model) and :class:`Part`; :func:`plan` loads and plans
in one call."""

from __future__ import annotations

import inspect
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

from asp import _asp, step
from asp.errors import ConfigError
from asp.graph import Graph
from asp.qgraphs import QGraphs
from asp.result import Plan
from asp.settings import Order, Overlaps, PathLike, QUse, Stability, Support, given

if TYPE_CHECKING:
    from asp.search import Search

__all__ = ["Assembly", "Part", "load", "plan"]


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
    unit: str | None = None,
    up: str | None = None,
    fixed: Iterable[str] = (),
    max_triangles: int | None = None,
    max_parts: int | None = None,
    allow_outside_files: bool | None = None,
    tessellation: float | None = None,
    split_bodies: bool | None = None,
) -> Assembly:
    """Loads a model: a ``.glb``/``.gltf`` file, a ``.step``/``.stp`` file (read and tessellated by
    OpenCASCADE through ``cascadio``: ``pip install cascadio``), or a folder of ``.obj``/``.stl``
    files (one part per file).

    :param unit: the unit of the coordinates: ``m``, ``cm``, ``mm``, ``in``, ``ft`` or metres per
        unit (default: what the file says, else metres).
    :param up: the up axis, ``x``, ``y``, ``z``, ``-x``, ``-y``, ``-z`` (default: what the file
        says, else +Y for glTF and +Z for STEP, which has none, and OBJ/STL).
    :param fixed: names of base parts, on top of those the file marks as fixed. Without any, a
        ground plane under the lowest point is the base.
    :param max_triangles: most triangles the model may have over all its parts (default 20 M);
        checked against the file's own counts before its data is read.
    :param max_parts: most parts the model may have (default 10,000).
    :param allow_outside_files: let the model read files outside its folder (absolute paths,
        ``..`` that climbs out, symlinks pointing out); refused by default (``docs/security.md``).
    :param tessellation: STEP files only: the chord tolerance of each edge and face relative to
        its own size (default 0.001).
    :param split_bodies: make each separate body of a part's mesh (pieces that do not touch, such
        as shelf pins stored in a shelf's mesh) a part of its own, ``NAME#1``, ``NAME#2``, ...
        (default: a warning names the part, which moves as one).
    :raises LoadError: the file cannot be read, is not a model, is over a cap or names a file
        outside its folder (the message names the file).
    :raises ConfigError: an unknown unit or axis, or a fixed part the model does not have.
    """
    if isinstance(fixed, str):
        fixed = [fixed]
    glb = None
    if step.is_step(path) and not os.path.isdir(path):
        glb = step.convert(path, tessellation)
    native = _asp.load(os.fspath(path), unit=unit, up=up, fixed=list(fixed), max_triangles=max_triangles,
                       max_parts=max_parts, allow_outside_files=allow_outside_files, tessellation=tessellation,
                       split_bodies=split_bodies, step_glb=glb)
    return Assembly(native)


class Assembly:
    """A loaded model. It owns its data: it stays valid whatever happens to the file, and plans
    any number of times (each plan builds its collision world afresh; :meth:`graph` caches the
    model's graph features)."""

    __slots__ = ("_native", "_parts")

    def __init__(self, native: _asp.Assembly) -> None:
        """Wraps a native assembly; use :func:`load` to make one."""
        if not isinstance(native, _asp.Assembly):
            raise TypeError("use asp.load(path) to load an assembly")
        self._native = native
        self._parts = tuple(Part(i, name, fixed) for i, name, fixed in native.parts())

    @property
    def parts(self) -> tuple[Part, ...]:
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
    def warnings(self) -> tuple[str, ...]:
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
        allow_outside_files: bool | None = None,
        tolerance: float | None = None,
        contact_distance: float | None = None,
        normals: int | None = None,
        sphere_directions: int | None = None,
        overlaps: Overlaps | None = None,
        stability: Stability | None = None,
        physics_threshold: float | None = None,
        path_planner: bool | None = None,
        subassemblies: bool | Literal["from-file"] | None = None,
        grid: bool | None = None,
        rrt_iterations: int | None = None,
        rrt_time: float | None = None,
        order: Order | None = None,
        model: PathLike | None = None,
        bookkeeping: bool | None = None,
        precedence: bool | None = None,
        seed: int | None = None,
        max_tests: int | None = None,
        timeout: float | None = None,
        unit_group: str | Sequence[str | Sequence[str]] | None = None,
        objective: str | Sequence[str] | None = None,
        pareto: bool | None = None,
        episodes: int | None = None,
        budget: int | None = None,
        threads: int | None = None,
        time_limit: float | None = None,
        exploration: float | None = None,
        polish: float | None = None,
        resolution: int | None = None,
        d_max: float | None = None,
        support: Support | None = None,
        q: PathLike | Sequence[PathLike] | None = None,
        epsilon: float | None = None,
        q_use: QUse | None = None,
        robot: str | None = None,
        robot_base: str | Sequence[float] | None = None,
        drop_off: str | Sequence[float] | None = None,
        replans: int | None = None,
        grippers: int | None = None,
        package_path: Sequence[str] | None = None,
    ) -> Plan:
        """Plans an assembly sequence: the pipeline of ``asp plan``, with the same settings under
        the flags' names (``--max-tests`` is ``max_tests``, ``--no-path-planner`` is
        ``path_planner=False``). Lengths are in model units. A setting left out (``None``) takes its
        default (``asp._asp.default_settings()``); a setting of the other search (``timeout`` with
        ``objective``, ``time_limit`` without) raises :class:`ConfigError` naming the one that
        applies. The keywords and this list are generated from asp's settings table
        (``crates/asp-app/src/settings/table.rs``).

        The feasibility search (without ``objective``):

        :param normals: Clustered surface-normal directions tried besides the six axes (each with
            its opposite). Default: 10.
        :param sphere_directions: Extra removal directions sampled evenly on the sphere. Default: 0.
        :param stability: The feasibility search's stability criterion. Values: ``contact``: every
            part linked through contacts to a fixed part; ``physics``: simulate what remains under
            gravity (rapier3d); unstable when a part moves more than ``physics_threshold``. Default:
            ``contact``.
        :param physics_threshold: Physics stability: how far (a fraction of the model's diagonal) a
            part may move in the simulation before the state counts as unstable. Needs ``stability``
            physics. Default: 0.01.
        :param path_planner: Try the path planner (RRT-Connect) when no straight line works; off:
            straight lines only. Default: True.
        :param subassemblies: Let groups of parts leave together as one rigid subassembly when no
            single part can; off: single parts only. ``from-file`` follows the file's product tree:
            each subassembly of the file (STEP assembly instances, named glTF nodes with children)
            is planned on its own base, then the level above with each as one unit (the plan's
            ``file_subassemblies``); it does not combine with ``unit_group``. Default: True.
        :param grid: Plan voxel models by grid moves (interlocking puzzles whose parts must slide in
            turn before anything can leave). Default: True.
        :param rrt_iterations: Path planner iterations per call. Default: 2000.
        :param rrt_time: Path planner wall-time safety cap per call, seconds (the iteration budget
            keeps runs reproducible; this only guards against pathological models). Default: 5.0.
        :param order: The part ordering of the depth-first search. Values: ``auto``: by what a
            removal test costs: ``given`` where tests are cheap (the default checker), ``gnn`` with
            bookkeeping where they are expensive (``stability`` physics, or a ``robot`` checking the
            arm); ``given``: the model's part order; ``shuffled``: one random order drawn from the
            seed at the start and kept (the thesis' vanilla AbD); ``random``: a fresh random order
            in every state (from the seed and the state); ``bookkeeping``: the given order with
            bookkeeping: a blocked part is retested only after a blocker is gone; ``gnn``: parts in
            order of the removability a graph neural network predicts (``model``), predicted again
            after each removal (thesis 3.5.3). Default: ``auto``.
        :param model: The removability model (ONNX, docs/learning.md) of ``order`` gnn, and of
            ``order`` auto where it is learned. Needs ``order`` gnn, or auto under physics or a
            ``robot``. Default: the shipped model of the run's checker.
        :param bookkeeping: Bookkeeping on top of any ordering: a blocked part is retested only
            after one of its blockers is gone (implied by ``order`` bookkeeping). Default: False.
        :param precedence: Add the precedence graph of a found plan to the plan JSON: which steps
            must go in before which (blocking and, conservatively, support), the levels of steps
            that may go in in parallel and the critical path (docs/plan-format.md, "Precedence").
            Default: False.
        :param max_tests: Stop after this many removal tests (status ``budget_exhausted``). Default:
            none.
        :param timeout: Stop after this many seconds with the best partial plan (0: no limit).
            Default: 60.0.
        :param unit_group: Parts planned as one part each, on purpose (a purchased motor, a
            pressed-in bearing): a list of groups, each a comma-separated string or a list of part
            names (one string is one group; on the command line repeat the flag). A unit goes in
            whole, as a subassembly step whose status is ``unit``, and the plan is still ``found``;
            a unit with a fixed part is part of the base. At least two parts each, no part in two.
            Needs ``subassemblies``. Default: none.
        :param grippers: Grippers in all: up to N-1 parts already in place may be held (by a second
            gripper or a fixture) while the next part goes in, so states that stand only while held
            are allowed (the plan's steps say which parts are held). Default: 1.

        Both searches:

        :param allow_outside_files: Let the model and the robot's URDF read files outside their
            folders: absolute paths, ``..`` that climbs out, symlinks that point out
            (docs/security.md). Default: False.
        :param tolerance: Contact tolerance: motions may push a part this deep into another.
            Default: 1e-4 × the model's diagonal.
        :param contact_distance: Parts closer than this are in contact, for stability. Default: 1e-3
            × the model's diagonal.
        :param overlaps: Parts that overlap in the input (press fits, dowels, screws, slop; warned
            once per pair with the measured depth, listed in the plan's ``overlaps``). Values:
            ``strict``: an overlapping pair separates only along motions that enter no new material
            of each other (a dowel leaves along its axis, never sideways); ``lenient``: shrink one
            part of the pair in their tests; ignore pairs no shrinking separates; ``error``: shrink
            small overlaps; stop with an error on pairs no shrinking separates. Default: ``strict``.
        :param seed: Seed of every random choice (random order, path planner, optimisation).
            Default: 0.
        :param robot: A robot arm that must carry every removal out: ``panda`` (the shipped
            Franka-Panda-like arm) or a URDF file. A part counts as removable only when the arm can
            grasp it, lift it 5 cm along its removal direction and carry it to the drop-off without
            collision (thesis 5.3). Default: none.
        :param robot_base: The robot base's position ``x,y,z`` (a list or a comma-separated string),
            model frame. Needs ``robot``. Default: on the floor, 0.3 m in front of the model's -x
            side, centred on it.
        :param drop_off: Where the gripper puts removed parts down, ``x,y,z`` (a list or a
            comma-separated string), model frame. Needs ``robot``. Default: 0.5 m to the robot's
            side, 0.4 m above the floor.
        :param replans: ``k``: path plans per grasp, the shortest kept (simulation steps of the
            optimiser plan once). Needs ``robot``. Default: 4.
        :param package_path: Where a URDF's ``package://NAME/`` meshes lie, ``NAME=DIR`` each (on
            the command line repeat the flag). Needs ``robot``. Default: none.

        The optimiser (with ``objective``):

        :param objective: Optimise the sequence for these objectives (comma-separated or a list):
            ``access`` (accessibility of each part, thesis 6.15), ``dirchange`` (shared removal
            directions, fewer direction changes, 6.16), ``pathlen`` (straight-line removal path
            length, minimised), ``robot-path`` (the arm's path, with ``robot``). One objective runs
            MCTS; several need ``pareto``. Default: none.
        :param pareto: Search the Pareto front of the objectives (Pareto-MCTS) and write every
            non-dominated sequence to ``pareto_front``. Default: False.
        :param episodes: MCTS episodes (each walks from the assembled state to a complete sequence).
            Default: 1000.
        :param budget: Search budget: MCTS iterations per step of an episode (the thesis uses 5).
            Default: 5.
        :param threads: Optimiser threads, each growing its own tree. The same seed and thread count
            give the same answer. Default: all cores.
        :param time_limit: Stop the optimiser after this many seconds (the answer then depends on
            timing). Default: none.
        :param exploration: Exploration constant c of UCT / MOUCB. Default: 1/√2.
        :param polish: Local search over the answer's sequences: block moves of 1-3 removals around
            every sequence the search finds, taking at most this share of the search's work (0:
            off). Default: 0.25.
        :param resolution: Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the
            half sphere. Default: 9.
        :param d_max: Cap d_max of the distance maps. Default: the model's diagonal.
        :param support: The optimiser's gravity check on the distance maps. Values: ``below``: every
            part rests on a part or the floor directly beneath it (thesis 6.3.2); ``contact``: every
            part linked through contacts to a fixed part or the floor. Default: ``below``.
        :param q: Learned Q-functions (ONNX, ``python -m asp.train q``), one per objective in
            ``objective``'s order (comma-separated or a list), or ``shipped``: the Q-functions
            shipped with asp for ``access``, ``dirchange`` and ``pathlen`` (in place of one model
            or, alone, of all), or ``none``: no learned guidance. Where ``q_use`` says, rollouts
            take the removal with the largest Q-value (the product of the values for several
            objectives) instead of a random one, except with probability ``epsilon`` (thesis 5.4.5,
            6.4.4). Without ``q``, an optimisation whose objectives all have a shipped Q, on maps of
            resolution 9, starts from the shipped Q-functions' greedy sequences and then searches as
            vanilla does (``q_use`` ``seed``; docs/benchmarks.md, "Guidance at equal wall time");
            ``q`` none turns that off. Default: `shipped` with `q_use` `seed` for access, dirchange
            and pathlen at resolution 9; none otherwise.
        :param epsilon: The probability of a random removal in a rollout (or expansion) guided by
            ``q``. Needs ``q``. Default: 0.2.
        :param q_use: Where ``q`` guides. Values: ``rollouts``: ε-greedy rollouts (thesis: one
            evaluation per rollout step); ``expansions``: the Q-values of each state the search adds
            order its expansions; rollouts stay random (one evaluation per node); ``both``: ε-greedy
            rollouts and Q-ordered expansions; ``priors``: the Q-values of each state the search
            adds are PUCT priors (expansion order and a bonus in the tree policy), a greedy sequence
            on them seeds the local search; rollouts stay random (one evaluation per node, cached by
            state); ``seed``: greedy sequences on the Q-values (their product and each objective's
            own) go to the front and seed the local search before the first episode; the search
            itself stays vanilla (one evaluation per step of those sequences, none after). Needs
            ``q``. Default: ``rollouts``.
        :raises ConfigError: a setting is unknown, of the wrong type, out of range or of the
            other search.
        :raises LoadError: the model cannot be planned as given (parts overlapping beyond
            repair, ...).
        :raises KeyboardInterrupt: Ctrl-C while planning or optimising (checked every 50 ms; a
            state whose tests take long, such as a path planner call, delays it until it ends).

        The GIL is released while planning.
        """
        settings = given({k: v for k, v in locals().items() if k != "self"})
        json, found, trace = self._native.plan(settings)
        return Plan(json, found, trace)

    def check(
        self,
        sequence: str | os.PathLike[str] | Sequence[str | Sequence[str]],
        **settings: Any,
    ) -> dict[str, Any]:
        """Checks a given assembly sequence with the removal tests, stability and settings of
        :meth:`plan` (``asp check``; the report is docs/check-format.md's, as a dict).

        :param sequence: the steps in assembly order: a list whose items are part names (a
            string may carry an insertion direction after the name, ``"bolt1 -z"`` or
            ``"bolt1 0,0,-1"``: the part goes in along it and is removed the opposite way) or
            lists of names (a rigid subassembly, ``["a", "b"]``); or the text of a sequence file
            (one step per line, ``#`` comments, ``[a, b]`` groups) or of a plan JSON; or the path
            of such a file.
        :param settings: the keywords of :meth:`plan`'s feasibility search (``tolerance``,
            ``stability``, ``path_planner``, ...; ``max_tests`` and ``timeout`` bound the repair;
            with ``robot`` the arm must also carry every step out, and each step then carries its
            grasp and path, with ``grippers`` the parts held).
        :returns: the report: ``status`` (``"feasible"`` or ``"infeasible"``), ``steps`` (each
            with its ``motion`` or its ``failure``), ``first_failure`` (a step index or ``None``)
            and, when infeasible, ``repair`` (the nearest feasible sequence found, its ``moved``
            steps and ``kendall_tau`` distance).
        :raises ConfigError: a name that is no part (the message lists the nearest names), a
            part placed twice or left out, a malformed line, or a bad setting.
        :raises TypeError: an unknown keyword.
        """
        import json as _json

        inspect.signature(Assembly.plan).bind(self, **settings)  # unknown keywords: TypeError
        if isinstance(sequence, os.PathLike):
            with open(sequence, encoding="utf-8") as f:
                text = f.read()
        elif isinstance(sequence, str):
            text = sequence
        else:
            lines = []
            for item in sequence:
                if isinstance(item, str):
                    lines.append(item)
                else:
                    names = [str(n) for n in item]
                    lines.append("[" + ", ".join(names) + "]")
            text = "\n".join(lines) + "\n"
        report, _feasible = self._native.check(text, given(settings))
        return _json.loads(report)

    def search(self, *, record: bool = True, **settings: Any) -> Search:
        """A stepped optimiser run: the search of :meth:`plan` with ``objective``, run episode by
        episode on one thread (its tree kept between episodes), with Q-functions swapped in
        between episodes — what the online settings of thesis 6.5 need
        (``python -m asp.train q-online``).

        :param record: record each episode's transitions (the ``asp-transitions`` records).
        :param settings: the keywords of :meth:`plan` (``objective`` required; ``threads`` is 1,
            ``episodes`` the most episodes, ``time_limit`` the wall time from the first episode,
            ``q`` the first episodes' Q models; ``epsilon`` and ``q_use`` are also those of
            :meth:`Search.set_q`).
        :raises ConfigError: no objective, or a bad setting (as :meth:`plan`).
        :raises TypeError: an unknown keyword.

        The maps are built here, without the GIL; see :class:`asp.Search`.
        """
        from asp.search import Search

        inspect.signature(Assembly.plan).bind(self, **settings)  # unknown keywords: TypeError
        kw = given(settings)
        if kw.get("objective") is None:
            raise ConfigError("objective: a search needs objectives")
        kw["threads"] = 1
        native = dict(kw)
        if native.get("q") is None:
            # without Q models now, ε and q_use are the later set_q's defaults
            native.pop("epsilon", None)
            native.pop("q_use", None)
        return Search(self._native.search(native, record), kw)

    def graph(
        self,
        present: Iterable[int] | None = None,
        *,
        tolerance: float | None = None,
        contact_distance: float | None = None,
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
        objective: str | Sequence[str],
        resolution: int = 9,
        d_max: float | None = None,
        support: str = "below",
        tolerance: float | None = None,
        contact_distance: float | None = None,
        overlaps: str = "strict",
        neighbours: int = 8,
        robot: str | None = None,
        robot_base: str | Sequence[float] | None = None,
        drop_off: str | Sequence[float] | None = None,
        replans: int | None = None,
        package_path: Sequence[str] | None = None,
        allow_outside_files: bool | None = None,
    ) -> QGraphs:
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
        :param robot: the robot of :meth:`plan` (with ``robot_base``, ``drop_off``, ``replans``,
            ``package_path``, ``allow_outside_files``): needed for the objective ``robot-path``;
            the graphs do not depend on it (a data set of ``asp collect transitions --robot``
            records these keywords).
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
            "robot": robot,
            "robot_base": None if robot_base is None or isinstance(robot_base, str) else list(robot_base),
            "drop_off": None if drop_off is None or isinstance(drop_off, str) else list(drop_off),
            "replans": replans,
            "package_path": None if package_path is None else list(package_path),
            "allow_outside_files": allow_outside_files,
        }
        return QGraphs(self._native.q_graphs(settings))


def plan(
    path: PathLike,
    *,
    unit: str | None = None,
    up: str | None = None,
    fixed: Iterable[str] = (),
    max_triangles: int | None = None,
    max_parts: int | None = None,
    tessellation: float | None = None,
    split_bodies: bool | None = None,
    **settings: Any,
) -> Plan:
    """Loads the model at ``path`` (:func:`load`, whose keywords the named ones are) and plans it
    (:meth:`Assembly.plan`, whose keywords ``settings`` are; ``allow_outside_files`` counts for
    both)."""
    outside = settings.get("allow_outside_files")
    model = load(path, unit=unit, up=up, fixed=fixed, max_triangles=max_triangles, max_parts=max_parts,
                 allow_outside_files=outside, tessellation=tessellation, split_bodies=split_bodies)
    return model.plan(**settings)
