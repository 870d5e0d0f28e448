"""What the two data-set readers share: the one error class, the checked ``index.json`` with its
assembly entries, typed fields, and the validated JSONL streamer of the per-assembly record files
(``states.jsonl``, ``transitions.jsonl``).

Every problem is a :class:`DataError` whose message is one line naming the file (with the line
number for a JSONL record) and the cause.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Callable, TypeVar

import numpy as np

from ..errors import AspError

__all__ = ["DataError", "read_index", "assembly_entries", "stream_jsonl", "parse_line", "part_list", "check_ascending"]

T = TypeVar("T")


class DataError(AspError, ValueError):
    """A data set file is missing, malformed or inconsistent (one line: file and cause); also a
    :class:`ValueError`."""


def _fail(path: os.PathLike[str] | str, message: str) -> DataError:
    return DataError(f"{path}: {message}")


def _read_json(path: Path) -> object:
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        raise _fail(path, "file not found") from None
    except json.JSONDecodeError as err:
        raise _fail(path, f"invalid JSON at line {err.lineno} column {err.colno}: {err.msg}") from None
    except OSError as err:
        raise _fail(path, f"cannot read: {err.strerror}") from None


def _int_field(path: Path, obj: dict[str, Any], key: str, where: str = "", minimum: int = 0) -> int:
    value = obj.get(key)
    if isinstance(value, bool) or not isinstance(value, int):
        raise _fail(path, f"{where}'{key}' must be an integer, found {json.dumps(value)}")
    if value < minimum:
        raise _fail(path, f"{where}'{key}' must be at least {minimum}, found {value}")
    return value


def _str_field(path: Path, obj: dict[str, Any], key: str, where: str = "") -> str:
    value = obj.get(key)
    if not isinstance(value, str):
        raise _fail(path, f"{where}'{key}' must be a string, found {json.dumps(value)}")
    return value


def _optional_int(index: dict[str, Any], key: str) -> int | None:
    value = index.get(key)
    return value if isinstance(value, int) else None


def read_index(path: Path, fmt: str, version: int) -> tuple[dict[str, Any], str, int, int]:
    """A data set's ``index.json``, checked to be an object of format ``fmt`` and ``version``,
    with its ``features``, ``node_dim`` and ``edge_dim``."""
    index = _read_json(path)
    if not isinstance(index, dict):
        raise _fail(path, "must be a JSON object")
    got = index.get("format")
    if got != fmt:
        raise _fail(path, f"format is {json.dumps(got)}, expected \"{fmt}\"")
    v = index.get("version")
    if v != version:
        raise _fail(path, f"{fmt} version {json.dumps(v)} is not supported (this reader knows {version})")
    features = _str_field(path, index, "features")
    node_dim = _int_field(path, index, "node_dim", minimum=1)
    edge_dim = _int_field(path, index, "edge_dim", minimum=1)
    return index, features, node_dim, edge_dim


def assembly_entries(path: Path, index: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any], str, str]]:
    """The entries of ``index.json``'s ``assemblies`` list, each checked to be an object with a
    unique string ``name`` and a string ``dir``: ``(where, entry, name, dir)``, ``where`` the
    prefix of a message about the entry (``"assemblies[3]: "``)."""
    entries = index.get("assemblies")
    if not isinstance(entries, list):
        raise _fail(path, "'assemblies' must be a list")
    names: set[str] = set()
    for k, entry in enumerate(entries):
        where = f"assemblies[{k}]: "
        if not isinstance(entry, dict):
            raise _fail(path, f"{where}must be an object")
        name = _str_field(path, entry, "name", where)
        if name in names:
            raise _fail(path, f"{where}assembly name '{name}' appears twice")
        names.add(name)
        yield where, entry, name, _str_field(path, entry, "dir", where)


def stream_jsonl(
    path: Path, expected: int, record: str, parse: Callable[[dict[str, Any], str], T]
) -> Iterator[T]:
    """Stream the records of a JSONL file: each non-blank line must be a JSON object, which
    ``parse(obj, where)`` validates and converts (``where`` is ``"FILE:LINE"``, the prefix of its
    messages). The file must hold ``expected`` records (``record`` names one in messages:
    ``"state"`` gives "a state must be a JSON object", "has 3 states, ...")."""
    count = 0
    try:
        f = open(path, encoding="utf-8")
    except FileNotFoundError:
        raise _fail(path, "file not found") from None
    except OSError as err:
        raise _fail(path, f"cannot read: {err.strerror}") from None
    with f:
        for lineno, line in enumerate(f, start=1):
            if not line.strip():
                continue
            yield parse_line(path, line, lineno, record, parse)
            count += 1
    if count != expected:
        raise _fail(path, f"has {count} {record}s, index.json announces {expected}")


def parse_line(path: Path, line: str, lineno: int, record: str, parse: Callable[[dict[str, Any], str], T]) -> T:
    """One record of a JSONL file (line ``lineno``), as :func:`stream_jsonl` reads it."""
    where = f"{path}:{lineno}"
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as err:
        raise DataError(f"{where}: invalid JSON: {err.msg}") from None
    if not isinstance(obj, dict):
        raise DataError(f"{where}: a {record} must be a JSON object")
    return parse(obj, where)


def _int_list(obj: dict[str, Any], key: str, where: str, what: str) -> np.ndarray:
    value = obj.get(key)
    if not isinstance(value, list) or not all(isinstance(v, int) and not isinstance(v, bool) for v in value):
        raise DataError(f"{where}: '{key}' must be a list of {what}")
    return np.asarray(value, dtype=np.int64)


def part_list(obj: dict[str, Any], key: str, where: str, parts: int) -> np.ndarray:
    """int64 array of the part indices under ``key`` of a record, each in ``0..parts-1``."""
    array = _int_list(obj, key, where, "part indices")
    bad = array[(array < 0) | (array >= parts)]
    if bad.size:
        raise DataError(f"{where}: '{key}' names part {int(bad[0])}, the model has {parts} parts")
    return array


def check_ascending(array: np.ndarray, key: str, where: str) -> None:
    """Checks that the part list ``array`` (``key`` of a record) is non-empty and strictly
    ascending, as a state's ``present`` parts are."""
    if len(array) == 0:
        raise DataError(f"{where}: '{key}' is empty")
    if np.any(np.diff(array) <= 0):
        raise DataError(f"{where}: '{key}' must be strictly ascending")
