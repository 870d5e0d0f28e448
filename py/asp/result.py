""":class:`Plan`: the result of a planning run, around the plan JSON (``docs/plan-format.md``)."""

from __future__ import annotations

import copy as _copy
import json as _json
import os
from typing import Any

from asp import _asp
from asp.steps import Step, steps_of

__all__ = ["ORDERS", "Plan"]

#: The part orderings ``order=`` accepts (``bookkeeping`` is ``given`` with bookkeeping; ``gnn``
#: needs the learned-ordering crate).
ORDERS: tuple[str, ...] = tuple(_asp.order_names())


class Plan:
    """A planning run's result. :attr:`json` is the plan JSON exactly as ``asp plan --json``
    prints it; every other attribute is read from it.

    A search that finds nothing is a result too: :attr:`status` is ``"no_plan"`` (with an
    :attr:`explanation` of what holds which part) or ``"budget_exhausted"``. A complete sequence
    in which some parts go in as one unit because asp could not take them apart is
    ``"partial"``, with its :attr:`locked_cores`; :attr:`found` is then False.
    """

    __slots__ = ("_json", "_found", "_trace", "_dict", "_steps")

    def __init__(self, json: str, found: bool, trace_csv: str | None = None) -> None:
        self._json = json
        self._found = bool(found)
        self._trace = trace_csv
        self._dict: dict[str, Any] = _json.loads(json)
        self._steps: dict[str, tuple[Step, ...]] = {}

    @property
    def json(self) -> str:
        """The plan JSON (pretty-printed, ending in a newline), as the CLI writes it."""
        return self._json

    @property
    def found(self) -> bool:
        """Whether a plan was found that gives every part its own motion (:attr:`status` is
        ``"found"``; False for ``"partial"`` plans)."""
        return self._found

    @property
    def status(self) -> str:
        """``"found"``, ``"partial"`` (complete, with :attr:`locked_cores`), ``"no_plan"`` or
        ``"budget_exhausted"`` (``docs/plan-format.md``, Statuses)."""
        return self._dict["status"]

    @property
    def locked_cores(self) -> list[dict[str, Any]]:
        """For ``"partial"`` plans, the parts asp could not take apart, one dict per core:
        ``base``, ``parts``, ``names``, ``status`` (why: ``"no_plan"``, ``"budget_exhausted"``
        or ``"unplanned"``), ``explanation`` (what holds each part) and ``why`` (format 1.9): a
        dict with ``overlaps`` (the core's overlapping pairs: ``parts``, ``names``, ``depth``,
        ``gross``, ``class`` (format 1.13: ``"fit"``, ``"tessellation"``, ``"planar_slab"`` or
        ``"interpenetration"``), ``artefact``, the last true when deeper than ``artefact_depth``,
        a modelling artefact rather than a fit), ``directions`` (the candidate directions), ``blocks`` (per
        part but the base: ``free`` directions and ``by``, the parts that block it with their
        ``directions`` and ``only`` counts), ``grid`` (``tried``, ``reason``, ``core_on_grid``)
        and ``lenient`` (``status`` and ``frees``: the parts the core's own plan frees under
        ``overlaps="lenient"``); ``docs/plan-format.md``, "Why a core is locked". Empty
        otherwise."""
        return self._copy("locked_cores", [])

    @property
    def bearings(self) -> list[dict[str, Any]]:
        """The rolling bearings found in the model (format 1.12), each planned as one unit:
        ``parts``, ``rings`` (inner, outer) and their ``names``, ``balls`` (the rolling
        elements), ``rolling_elements`` (format 1.14: ``"balls"`` or ``"rollers"``), ``others``
        (cage, shields), ``centre``, ``axis``, ``pitch_radius``, ``ball_radius`` and ``rows``
        (``docs/plan-format.md``, "Bearings"). Empty when there is none."""
        return self._copy("bearings", [])

    @property
    def components(self) -> list[dict[str, Any]]:
        """The components drawn as several interpenetrating solids of one product (format 1.14),
        each planned as one unit: ``parts``, their ``names`` and the ``product`` that holds them
        (``docs/plan-format.md``, "Components drawn as several solids"). Empty when there is
        none."""
        return self._copy("components", [])

    def table(self) -> str:
        """The plan as text, exactly as ``asp plan`` prints it for the same run: the table and,
        for optimising runs, the optimiser's summary."""
        return _asp.plan_text(self._json)

    def _copy(self, key: str, default: Any = KeyError) -> Any:
        """A fresh copy of one entry of the plan (the JSON is parsed once, in the constructor)."""
        if key not in self._dict:
            if default is KeyError:
                raise KeyError(key)
            return default
        return _copy.deepcopy(self._dict[key])

    def to_dict(self) -> dict[str, Any]:
        """The plan JSON as a fresh dict (changing it does not change the plan)."""
        return _json.loads(self._json)

    @property
    def model(self) -> str:
        """The model file or folder, as given."""
        return self._dict["model"]

    @property
    def units(self) -> str:
        """The model's unit; every length of the plan is in it."""
        return self._dict["units"]

    @property
    def up(self) -> str:
        """The up axis (``"+z"``, ...)."""
        return self._dict["up"]

    @property
    def parts(self) -> list[dict[str, Any]]:
        """Every part: ``{"index", "name", "fixed"}``."""
        return self._copy("parts")

    @property
    def assembly_sequence(self) -> list[dict[str, Any]]:
        """One entry per non-fixed part in assembly order: ``{"part", "name", "motion"}``
        (empty unless found)."""
        return self._copy("assembly_sequence")

    @property
    def steps(self) -> tuple[Step, ...]:
        """:attr:`assembly_sequence` as typed, frozen :class:`asp.Step` objects (motions,
        subassemblies with their own steps, grid moves, the robot's part)."""
        return self._typed("assembly_sequence")

    @property
    def partial_steps(self) -> tuple[Step, ...]:
        """:attr:`partial_assembly_sequence` as typed, frozen :class:`asp.Step` objects."""
        return self._typed("partial_assembly_sequence")

    def _typed(self, key: str) -> tuple[Step, ...]:
        if key not in self._steps:
            self._steps[key] = steps_of(self._dict.get(key, []))
        return self._steps[key]

    @property
    def disassembly_sequence(self) -> list[int]:
        """Part indices in removal order (when not found: the partial disassembly that got
        furthest)."""
        return list(self._dict["disassembly_sequence"])

    @property
    def partial_assembly_sequence(self) -> list[dict[str, Any]]:
        """When not found: the parts that did come off, in assembly order onto
        :attr:`remaining`, entries as in :attr:`assembly_sequence` (empty when found)."""
        return self._copy("partial_assembly_sequence", [])

    @property
    def remaining(self) -> list[int] | None:
        """When not found: the parts present where the partial disassembly stops (fixed parts
        included); ``None`` when found."""
        value = self._dict.get("remaining")
        return None if value is None else list(value)

    @property
    def stats(self) -> dict[str, Any]:
        """Removal tests, failures by collision and gravity, path planner calls, seconds."""
        return dict(self._dict["stats"])

    @property
    def explanation(self) -> list[dict[str, Any]]:
        """For ``no_plan``: each part of the deepest dead end, why it is stuck and which parts
        hold it (empty otherwise): ``{"part", "name", "reason", "parts"}``. With a robot, a part
        the geometry lets out but the arm cannot take out is ``"blocked"`` with empty ``parts``
        and a ``"robot"`` key ``{"reason", "detail"}`` (format 1.9; ``reason`` one of
        ``"no_reachable_grasp"``, ``"blocked_lift"``, ``"no_straight_lift"``,
        ``"no_drop_off"``, ``"no_path"``; ``detail`` one line in words)."""
        return self._copy("explanation", [])

    @property
    def warnings(self) -> list[str]:
        """Non-fatal problems found in the model, one line each."""
        return list(self._dict.get("warnings", []))

    @property
    def optimisation(self) -> dict[str, Any] | None:
        """For optimising runs (``objective=``): objectives, values and the search's settings."""
        return self._copy("optimisation", None)

    @property
    def pareto_front(self) -> list[dict[str, Any]] | None:
        """For Pareto runs: every non-dominated sequence with its objective vector."""
        return self._copy("pareto_front", None)

    @property
    def trace_csv(self) -> str | None:
        """For optimising runs: the search's trace as CSV (what ``asp plan --trace`` writes)."""
        return self._trace

    def write(self, path: str | os.PathLike[str]) -> None:
        """Writes the plan JSON to ``path`` (what ``asp plan --out`` writes)."""
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(self._json)

    def __repr__(self) -> str:
        s = self._dict["stats"]
        return f"<asp.Plan {self.model}: {self.status}, {s['removal_tests']} removal tests>"
