"""Type stubs of the private native module ``asp._asp`` (crates/asp-py). Use the ``asp`` package."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

__version__: str
PLAN_FORMAT_VERSION: str

def load(
    path: Union[str, PathLike[str]],
    unit: Optional[str] = None,
    up: Optional[str] = None,
    fixed: Sequence[str] = ...,
) -> Assembly: ...
def default_settings() -> Dict[str, Any]: ...
def order_names() -> List[str]: ...
def choices() -> Dict[str, List[str]]: ...

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
    def warnings(self) -> List[str]: ...
    def parts(self) -> List[Tuple[int, str, bool]]: ...
    def __len__(self) -> int: ...
    def plan(self, settings: Dict[str, Any]) -> Tuple[str, bool, Optional[str]]:
        """``(plan_json, found, trace_csv)``."""
    def graph(
        self, present: Sequence[int], settings: Dict[str, Any]
    ) -> Tuple[bytearray, bytearray, bytearray, bytearray, int, int, str]:
        """``(nodes int64, x float32, edge_index int64, edge_attr float32, node_dim, edge_dim, features)``,
        the arrays as little-endian bytes."""
    def q_graphs(self, settings: Dict[str, Any]) -> QGraphs: ...
    def search(self, settings: Dict[str, Any], record: bool) -> Search:
        """A stepped optimiser run with ``Assembly.plan``'s keywords (an objective needed)."""

class Search:
    index_json: str
    swaps: int
    ended: bool
    def episode(self) -> Tuple[str, int, int, float, float, int, bool, bool, bool, bool]:
        """``(transitions_jsonl, episodes, iterations, seconds, value, front_size, finished,
        exhausted, stopped, capped)``."""
    def set_q(self, paths: Sequence[Union[str, PathLike[str]]], epsilon: Optional[float] = None, q_use: Optional[str] = None) -> None: ...
    def result(self) -> Tuple[str, bool, str]:
        """``(plan_json, found, trace_csv)``."""

class QGraphs:
    features: str
    node_dim: int
    edge_dim: int
    directions: int
    num_parts: int
    removable: int
    objectives: List[str]
    reward_ranges: List[Optional[Tuple[float, float]]]
    def feasible_actions(self, present: Sequence[int]) -> List[int]: ...
    def graph(
        self, present: Sequence[int], actions: Sequence[int] = ..., history: Sequence[int] = ...
    ) -> Tuple[bytearray, bytearray, bytearray, bytearray, int, int, str]:
        """Like ``Assembly.graph``; the context node's part index is -1."""

# the items of asp.batch (crates/asp-py/src/batch.rs): JSON strings in and out
def profile_preset(name: str) -> str: ...
def generator_canonical(generator_json: str) -> str: ...
def gen_item(generator_json: str, index: int, count: int, seed: int, out: Union[str, PathLike[str]]) -> str: ...
def gen_manifest(
    generator_json: str,
    preset: Optional[str],
    count: int,
    seed: int,
    entries: Sequence[str],
    out: Union[str, PathLike[str]],
) -> str: ...
def model_items(paths: Sequence[Union[str, PathLike[str]]]) -> List[Tuple[str, int, str, str]]:
    """``(path, index, name, dir)`` of each model, as a data set names them."""
def collect_item(
    path: Union[str, PathLike[str]],
    index: int,
    name: str,
    dir: str,
    out: Union[str, PathLike[str]],
    runs: int,
    seed: int,
    max_tests: Optional[int],
    timeout: Optional[float],
    settings: Dict[str, Any],
    unit: Optional[str] = None,
    up: Optional[str] = None,
    fixed: Sequence[str] = ...,
) -> str: ...
def collect_index(out: Union[str, PathLike[str]], runs: int, seed: int, entries: Sequence[str]) -> str: ...
def bench_item(
    path: Union[str, PathLike[str]],
    name: str,
    orderings: int,
    settings: Dict[str, Any],
    methods: Optional[str] = None,
    model: Optional[str] = None,
    unit: Optional[str] = None,
    up: Optional[str] = None,
    fixed: Sequence[str] = ...,
) -> str: ...
def bench_table(rows: Sequence[str]) -> str: ...
def mcts_table(rows: Sequence[str]) -> Tuple[str, str]:
    """``(table, csv)`` of ``asp bench mcts`` for rows (JSON lists of its rows)."""
