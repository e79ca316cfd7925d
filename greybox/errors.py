"""Exceptions raised by greybox.

Every error caused by the user's input derives from :class:`GreyboxError`; the
command line prints its message (which names the file and the problem) and
exits with a non-zero status instead of showing a traceback.
"""

from __future__ import annotations

from os import PathLike

__all__ = ["GreyboxError", "LogError", "ModelFileError", "ParameterError"]


class GreyboxError(Exception):
    """Base class of all errors that greybox reports to the user."""


class LogError(GreyboxError, ValueError):
    """An axis log cannot be read or fails validation.

    Parameters
    ----------
    source : str or path-like or None
        File the log came from; ``None`` for an in-memory log.
    problem : str
        What is wrong, in words a user can act on.
    """

    def __init__(self, source: str | PathLike | None, problem: str):
        self.source = None if source is None else str(source)
        self.problem = problem
        where = self.source if self.source else "<in-memory log>"
        super().__init__(f"{where}: {problem}")


class ModelFileError(GreyboxError, ValueError):
    """A model file is missing, corrupt, or of an unsupported format version."""


class ParameterError(GreyboxError, ValueError):
    """Model parameters are invalid, e.g. would make a forward-Euler step unstable."""
