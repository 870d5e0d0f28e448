"""Type stubs of the private native module ``asp._asp`` (crates/asp-py). Use the ``asp`` package."""

from collections.abc import Sequence
from os import PathLike
from typing import Any

__version__: str
PLAN_FORMAT_VERSION: str

def load(
    path: str | PathLike[str],
    unit: str | None = None,
    up: str | None = None,
    fixed: Sequence[str] = ...,
    max_triangles: int | None = None,
    max_parts: int | None = None,
    allow_outside_files: bool | None = None,
) -> Assembly: ...
def default_settings() -> dict[str, Any]: ...
def order_names() -> list[str]: ...
def choices() -> dict[str, list[str]]: ...
def plan_text(json: str) -> str: ...

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
    def graph(
        self, present: Sequence[int], settings: dict[str, Any]
    ) -> tuple[bytearray, bytearray, bytearray, bytearray, int, int, str]:
        """``(nodes int64, x float32, edge_index int64, edge_attr float32, node_dim, edge_dim, features)``,
        the arrays as little-endian bytes."""
    def q_graphs(self, settings: dict[str, Any]) -> QGraphs: ...
    def search(self, settings: dict[str, Any], record: bool) -> Search:
        """A stepped optimiser run with ``Assembly.plan``'s keywords (an objective needed)."""

class Search:
    index_json: str
    swaps: int
    ended: bool
    def episode(self) -> tuple[str, int, int, float, float, int, bool, bool, bool, bool]:
        """``(transitions_jsonl, episodes, iterations, seconds, value, front_size, finished,
        exhausted, stopped, capped)``."""
    def set_q(self, paths: Sequence[str | PathLike[str]], epsilon: float | None = None, q_use: str | None = None) -> None: ...
    def result(self) -> tuple[str, bool, str]:
        """``(plan_json, found, trace_csv)``."""

class QGraphs:
    features: str
    node_dim: int
    edge_dim: int
    directions: int
    num_parts: int
    removable: int
    objectives: list[str]
    reward_ranges: list[tuple[float, float] | None]
    def feasible_actions(self, present: Sequence[int]) -> list[int]: ...
    def graph(
        self, present: Sequence[int], actions: Sequence[int] = ..., history: Sequence[int] = ...
    ) -> tuple[bytearray, bytearray, bytearray, bytearray, int, int, str]:
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
    unit: str | None = None,
    up: str | None = None,
    fixed: Sequence[str] = ...,
) -> str: ...
def collect_index(out: str | PathLike[str], runs: int, seed: int, entries: Sequence[str]) -> str: ...
def bench_item(
    path: str | PathLike[str],
    name: str,
    orderings: int,
    settings: dict[str, Any],
    methods: str | None = None,
    model: str | None = None,
    unit: str | None = None,
    up: str | None = None,
    fixed: Sequence[str] = ...,
) -> str: ...
def bench_table(rows: Sequence[str]) -> str: ...
def mcts_table(rows: Sequence[str]) -> tuple[str, str]:
    """``(table, csv)`` of ``asp bench mcts`` for rows (JSON lists of its rows)."""
