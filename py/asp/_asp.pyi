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
