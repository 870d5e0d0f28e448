"""asp: assembly sequence planning by Assembly-by-Disassembly, from Python.

>>> import asp
>>> a = asp.load("tests/data/ikea/table_lack_0825.glb", up="z")   # doctest: +SKIP
>>> plan = a.plan(order="given")                                   # doctest: +SKIP
>>> plan.status, [step["name"] for step in plan.assembly_sequence] # doctest: +SKIP

The same pipeline as the ``asp`` command line: ``plan.json`` is the plan JSON that
``asp plan MODEL --json`` prints for the same model and settings. The native module
(``asp._asp``) is private. ``asp.train`` (PyTorch) needs the ``train`` extra; nothing else in the
package imports torch.
"""

from __future__ import annotations

from asp._asp import PLAN_FORMAT_VERSION, __version__
from asp.assembly import Assembly, Part, load, plan
from asp.errors import AspError, ConfigError, LoadError
from asp.graph import Graph
from asp.qgraphs import QGraphs
from asp.result import ORDERS, Plan
from asp.search import Episode, Search
from asp.settings import PlanSettings
from asp.steps import Motion, Move, RobotStep, Step, Subassembly

__all__ = [
    "Assembly",
    "AspError",
    "ConfigError",
    "Episode",
    "Graph",
    "LoadError",
    "Motion",
    "Move",
    "ORDERS",
    "PLAN_FORMAT_VERSION",
    "Part",
    "Plan",
    "PlanSettings",
    "QGraphs",
    "RobotStep",
    "Search",
    "Step",
    "Subassembly",
    "__version__",
    "load",
    "plan",
]
