"""The vocabulary of planning settings: the closed sets as ``Literal`` types and every setting of
:meth:`asp.Assembly.plan` as a :class:`PlanSettings` ``TypedDict``.

Generated from asp's settings table (``crates/asp-app/src/settings/table.rs``), where each
setting is declared once: do not edit; a Rust test fails when this file differs and
``ASP_REGENERATE=1 cargo test --workspace checked_in_settings`` rewrites it. The settings are the
keys of asp's plan request, the same as the command line's flags with ``_`` for ``-``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Literal, TypedDict, Union

__all__ = ["given", "Order", "Overlaps", "PathLike", "PlanSettings", "QUse", "Stability", "Support"]

#: A path: a string or an ``os.PathLike``.
PathLike = Union[str, "os.PathLike[str]"]
#: The values of ``overlaps=``.
Overlaps = Literal["strict", "lenient", "error"]
#: The values of ``stability=``.
Stability = Literal["contact", "physics"]
#: The values of ``order=``.
Order = Literal["auto", "given", "shuffled", "random", "bookkeeping", "gnn"]
#: The values of ``support=``.
Support = Literal["below", "contact"]
#: The values of ``q_use=``.
QUse = Literal["rollouts", "expansions", "both", "priors", "seed"]


class PlanSettings(TypedDict, total=False):
    """Every keyword of :meth:`asp.Assembly.plan` (each optional; see its documentation)."""

    allow_outside_files: bool
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
    rrt_iterations: int
    rrt_time: float
    order: Order
    model: PathLike
    bookkeeping: bool
    precedence: bool
    seed: int
    max_tests: int
    timeout: float
    unit_group: str | Sequence[str | Sequence[str]]
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
    q: PathLike | Sequence[PathLike]
    epsilon: float
    q_use: QUse
    robot: str
    robot_base: str | Sequence[float]
    drop_off: str | Sequence[float]
    replans: int
    grippers: int
    package_path: Sequence[str]


def given(settings: dict) -> dict:
    """The settings that were given (``None`` means "the default": left out)."""
    return {k: v for k, v in settings.items() if v is not None}
