"""Type stubs of the private native module ``asp._asp`` (crates/asp-py). Use the ``asp`` package."""

from collections.abc import Sequence
from os import PathLike
from typing import Any, final

__all__ = [
    "__version__",
    "PLAN_FORMAT_VERSION",
    "STEP_ANGULAR",
    "STEP_RELATIVE",
    "STEP_CONVERTER",
    "load",
    "default_settings",
    "order_names",
    "choices",
    "Assembly",
    "QGraphs",
    "Search",
    "EpisodeReport",
    "GraphArrays",
    "profile_preset",
    "generator_canonical",
    "gen_item",
    "gen_manifest",
    "model_items",
    "collect_item",
    "plan_items",
    "collect_index",
    "bench_item",
    "bench_table",
    "mcts_table",
    "plan_text",
]

__version__: str
PLAN_FORMAT_VERSION: str
STEP_ANGULAR: float
STEP_RELATIVE: float
STEP_CONVERTER: str

def load(
    path: str | PathLike[str],
    unit: str | None = None,
    up: str | None = None,
    fixed: Sequence[str] = ...,
    max_triangles: int | None = None,
    max_parts: int | None = None,
    allow_outside_files: bool | None = None,
    tessellation: float | None = None,
    split_bodies: bool | None = None,
    step_glb: bytes | None = None,
) -> Assembly: ...
def default_settings() -> dict[str, Any]: ...
def order_names() -> list[str]: ...
def choices() -> dict[str, list[str]]: ...
def plan_text(json: str) -> str: ...

@final
class Assembly:
    @property
    def source(self) -> str: ...
    @property
    def units(self) -> str: ...
    @property
    def metres_per_unit(self) -> float: ...
    @property
    def up(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    def parts(self) -> list[tuple[int, str, bool]]: ...
    def __len__(self) -> int: ...
    def plan(self, settings: dict[str, Any]) -> tuple[str, bool, str | None]:
        """``(plan_json, found, trace_csv)``."""
    def check(self, sequence: str, settings: dict[str, Any]) -> tuple[str, bool]:
        """``(report_json, feasible)``."""
    def graph(self, present: Sequence[int], settings: dict[str, Any]) -> GraphArrays: ...
    def q_graphs(self, settings: dict[str, Any]) -> QGraphs: ...
    def search(self, settings: dict[str, Any], record: bool) -> Search:
        """A stepped optimiser run with ``Assembly.plan``'s keywords (an objective needed)."""

@final
class GraphArrays:
    """A state graph's arrays as little-endian bytes (int64 ``nodes`` and ``edge_index``, float32
    ``x`` and ``edge_attr``)."""
    @property
    def nodes(self) -> bytearray: ...
    @property
    def x(self) -> bytearray: ...
    @property
    def edge_index(self) -> bytearray: ...
    @property
    def edge_attr(self) -> bytearray: ...
    @property
    def node_dim(self) -> int: ...
    @property
    def edge_dim(self) -> int: ...
    @property
    def features(self) -> str: ...

@final
class EpisodeReport:
    """What one episode of a ``Search`` did."""
    @property
    def transitions_jsonl(self) -> str: ...
    @property
    def episodes(self) -> int: ...
    @property
    def iterations(self) -> int: ...
    @property
    def seconds(self) -> float: ...
    @property
    def value(self) -> float: ...
    @property
    def front_size(self) -> int: ...
    @property
    def finished(self) -> bool: ...
    @property
    def exhausted(self) -> bool: ...
    @property
    def stopped(self) -> bool: ...
    @property
    def capped(self) -> bool: ...

@final
class Search:
    @property
    def index_json(self) -> str: ...
    @property
    def swaps(self) -> int: ...
    @property
    def ended(self) -> bool: ...
    def episode(self) -> EpisodeReport: ...
    def set_q(self, paths: Sequence[str | PathLike[str]], epsilon: float | None = None, q_use: str | None = None) -> None: ...
    def result(self) -> tuple[str, bool, str]:
        """``(plan_json, found, trace_csv)``."""

@final
class QGraphs:
    @property
    def features(self) -> str: ...
    @property
    def node_dim(self) -> int: ...
    @property
    def edge_dim(self) -> int: ...
    @property
    def directions(self) -> int: ...
    @property
    def num_parts(self) -> int: ...
    @property
    def removable(self) -> int: ...
    @property
    def objectives(self) -> list[str]: ...
    @property
    def reward_ranges(self) -> list[tuple[float, float] | None]: ...
    def feasible_actions(self, present: Sequence[int]) -> list[int]: ...
    def graph(self, present: Sequence[int], actions: Sequence[int] = ..., history: Sequence[int] = ...) -> GraphArrays:
        """Like ``Assembly.graph``; the context node's part index is -1."""

# the items of asp.batch (crates/asp-py/src/batch.rs): JSON strings in and out
def profile_preset(name: str) -> str: ...
def generator_canonical(generator_json: str) -> str: ...
def gen_item(generator_json: str, index: int, count: int, seed: int, out: str | PathLike[str]) -> str: ...
def gen_manifest(
    generator_json: str,
    preset: str | None,
    count: int,
    seed: int,
    entries: Sequence[str],
    out: str | PathLike[str],
) -> str: ...
def model_items(paths: Sequence[str | PathLike[str]]) -> list[tuple[str, int, str, str]]:
    """``(path, index, name, dir)`` of each model, as a data set names them."""
def plan_items(
    models: Sequence[tuple[str | PathLike[str], str]],
    out: str | PathLike[str],
    settings: dict[str, Any],
    load: dict[str, Any] | None = None,
) -> list[tuple[str | None, str, bool, int, int, int, float]]:
    """Plans ``(model, plan file)`` pairs into ``out`` in parallel: ``(error, status, found, parts,
    steps, removal_tests, seconds)`` per model, ``error`` one line or ``None``."""
def collect_item(
    path: str | PathLike[str],
    index: int,
    name: str,
    dir: str,
    out: str | PathLike[str],
    runs: int,
    seed: int,
    max_tests: int | None,
    timeout: float | None,
    settings: dict[str, Any],
    load: dict[str, Any] | None = None,
) -> str: ...
def collect_index(
    out: str | PathLike[str],
    runs: int,
    seed: int,
    entries: Sequence[str],
    settings: dict[str, Any],
    load: dict[str, Any] | None = None,
) -> str: ...
def bench_item(
    path: str | PathLike[str],
    name: str,
    orderings: int,
    settings: dict[str, Any],
    methods: str | None = None,
    model: str | None = None,
    load: dict[str, Any] | None = None,
) -> str: ...
def bench_table(rows: Sequence[str]) -> str: ...
def mcts_table(rows: Sequence[str]) -> tuple[str, str]:
    """``(table, csv)`` of ``asp bench mcts`` for rows (JSON lists of its rows)."""
