"""The ``asp-removability`` data-set reader under its earlier name: see
:mod:`asp.datasets.removability`, which this module re-exports."""

from __future__ import annotations

from .datasets.jsonl import read_index
from .datasets.removability import (
    FORMAT,
    VERSION,
    Assembly,
    DataError,
    RemovabilityDataset,
    State,
    StateGraph,
    induced_subgraph,
)

__all__ = [
    "FORMAT",
    "VERSION",
    "DataError",
    "Assembly",
    "State",
    "StateGraph",
    "RemovabilityDataset",
    "induced_subgraph",
    "read_index",
]
