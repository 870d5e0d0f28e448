"""The ``asp-transitions`` data-set reader under its earlier name: see
:mod:`asp.datasets.transitions`, which this module re-exports."""

from __future__ import annotations

from .datasets.transitions import (
    FORMAT,
    KINDS,
    VERSION,
    DataError,
    Transition,
    TransitionAssembly,
    TransitionDataset,
    directions_of,
)

__all__ = [
    "FORMAT",
    "VERSION",
    "KINDS",
    "DataError",
    "Transition",
    "TransitionAssembly",
    "TransitionDataset",
    "directions_of",
]
