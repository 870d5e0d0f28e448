"""The exceptions asp raises (all exported from :mod:`asp`).

Every error of asp is an :class:`AspError`; bad input is a :class:`LoadError` (the model file or
folder cannot be read, or its content cannot be planned as given) or a :class:`ConfigError` (a
setting is unknown, of the wrong type or out of range). A search that finds no plan is not an
error: its :class:`asp.Plan` has ``status == "no_plan"``. The errors of the optional parts are
:class:`AspError` too, each also an instance of the builtin class it used to be:
:class:`asp.datasets.DataError` (a data set is malformed; a :class:`ValueError`),
:class:`asp.train.ExportError` (an exported ONNX file does not reproduce its model; a
:class:`RuntimeError`) and :class:`asp.batch.BatchError` (a batch cannot start or finish).
"""

from __future__ import annotations

__all__ = ["AspError", "LoadError", "ConfigError"]


class AspError(Exception):
    """Base class of every error asp raises."""


class LoadError(AspError):
    """The model cannot be loaded or planned as given.

    The message names the file and the cause, as the command line's one-line errors do
    (``tests/data/x.glb: No such file or directory (os error 2)``); :attr:`path` is the file or
    folder.
    """

    def __init__(self, message: str, path: str | None = None) -> None:
        super().__init__(message)
        #: The model file or folder the error is about.
        self.path = path

    def __reduce__(self):  # keep `path` through pickling (multiprocessing, Ray)
        return (type(self), (str(self), self.path))


class ConfigError(AspError, ValueError):
    """A setting is unknown, of the wrong type or out of range (also a :class:`ValueError`)."""
