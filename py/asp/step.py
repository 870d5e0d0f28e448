"""STEP files (``.step``, ``.stp``; AP203, AP214, AP242) through OpenCASCADE: the ``cascadio``
wheel (``pip install cascadio``, or ``pip install ./py[step]``) reads and tessellates the file
in this process and writes a GLB with the product tree and each triangle's B-rep face
(``TM_brep_faces``), which asp reads as it reads any glTF. The command line runs the same
conversion in a Python that has cascadio (``ASP_PYTHON``, else ``python3``)."""

from __future__ import annotations

import os

from asp import _asp
from asp.errors import ConfigError, LoadError

__all__ = ["INSTALL", "is_step", "convert"]

#: The command that installs what reading STEP needs.
INSTALL = "pip install cascadio"


def is_step(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a STEP file by its extension."""
    return os.fspath(path).lower().endswith((".step", ".stp"))


def convert(path: str | os.PathLike[str], tessellation: float | None = None) -> bytes:
    """The GLB that OpenCASCADE makes of the STEP file ``path``: each edge and face tessellated to
    ``tessellation`` times its own size (default ``asp._asp.STEP_RELATIVE``).

    :raises LoadError: cascadio is missing (the message names the command that installs it), the
        file cannot be read, or OpenCASCADE cannot read it as STEP.
    :raises ConfigError: the tolerance is not between 0 and 1.
    """
    name = os.fspath(path)
    relative = _asp.STEP_RELATIVE if tessellation is None else float(tessellation)
    if not 0.0 < relative < 1.0:
        raise ConfigError(f"tessellation: the relative tessellation tolerance must lie between 0 and 1, got {relative}")
    try:
        import cascadio
    except ImportError:
        raise LoadError(
            f"{name}: reading STEP needs the Python package cascadio (OpenCASCADE): `{INSTALL}`", name
        ) from None
    try:
        with open(name, "rb") as f:
            data = f.read()
    except OSError as e:
        raise LoadError(f"{name}: {e.strerror or e}", name) from e
    glb = cascadio.load(
        data,
        file_type="step",
        tol_linear=relative,
        tol_angular=_asp.STEP_ANGULAR,
        tol_relative=True,
        include_brep=True,
        merge_primitives=True,
    )
    if not glb:
        raise LoadError(f"{name}: OpenCASCADE cannot read it as STEP (its messages are on stderr)", name)
    return bytes(glb)
