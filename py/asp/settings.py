"""The vocabulary of planning settings: the closed sets as ``Literal`` types and every setting of
:meth:`asp.Assembly.plan` as a :class:`PlanSettings` ``TypedDict``.

The settings are the keys of asp's plan request (the Rust crate ``asp-app``), the same as the
command line's flags with ``_`` for ``-``. Their defaults and accepted values live there, once:
``asp._asp.default_settings()`` and ``asp._asp.choices()`` read them, and a test holds these
types to them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal, TypedDict

__all__ = ["Order", "Overlaps", "PlanSettings", "QUse", "Stability", "Support", "given"]

#: Part orderings of the depth-first search (``order=``).
Order = Literal["auto", "given", "shuffled", "random", "bookkeeping", "gnn"]
#: What to do with parts that overlap in the input (``overlaps=``).
Overlaps = Literal["strict", "lenient", "error"]
#: The feasibility search's stability criterion (``stability=``).
Stability = Literal["contact", "physics"]
#: The optimiser's gravity check (``support=``).
Support = Literal["below", "contact"]
#: Where learned Q-functions guide the optimiser (``q_use=``).
QUse = Literal["rollouts", "expansions", "both", "priors"]


class PlanSettings(TypedDict, total=False):
    """Every keyword of :meth:`asp.Assembly.plan` (each optional; see its documentation)."""

    tolerance: float
    contact_distance: float
    normals: int
    sphere_directions: int
    overlaps: Overlaps
    stability: Stability
    physics_threshold: float
    path_planner: bool
    subassemblies: bool | Literal["from-file"]
    grid: bool
    unit_group: str | Sequence[str | Sequence[str]]
    rrt_iterations: int
    rrt_time: float
    order: Order
    model: str
    bookkeeping: bool
    precedence: bool
    seed: int
    max_tests: int
    timeout: float
    objective: str | Sequence[str]
    pareto: bool
    episodes: int
    budget: int
    threads: int
    time_limit: float
    exploration: float
    polish: float
    resolution: int
    d_max: float
    support: Support
    q: str | Sequence[str]
    epsilon: float
    q_use: QUse
    robot: str
    robot_base: str | tuple[float, float, float] | list[float]
    drop_off: str | tuple[float, float, float] | list[float]
    replans: int
    grippers: int
    package_path: Sequence[str]
    allow_outside_files: bool


def given(settings: dict) -> dict:
    """The settings that were given (``None`` means "the default": left out)."""
    return {k: v for k, v in settings.items() if v is not None}

