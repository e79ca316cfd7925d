"""Exceptions and warnings raised by greybox, and the settings their messages name.

Every error caused by the user's input derives from :class:`GreyboxError`; the
command line prints its message (which names the file and the problem) and
exits with a non-zero status instead of showing a traceback.

A message that tells the user what to set names the setting as a :class:`Setting`
among its parts, not as text: Python code reads it as ``fit_offset=True``, the
command line as ``--offset`` (its one table of options, ``greybox.cli._spelling``).
Warnings that name settings are :class:`SettingWarning`.
"""

from __future__ import annotations

from os import PathLike

__all__ = ["GreyboxError", "LogError", "ModelFileError", "ParameterError", "Setting", "SettingWarning"]

#: ``Setting(name)`` without a value.
_UNSET = object()


class Setting:
    """A setting a message names: a model's hyperparameter or a log reader's keyword argument.

    Parameters
    ----------
    name : str
        The keyword name, e.g. ``"fit_offset"``, ``"columns"``, ``"sample_time"``.
    value : object, optional
        The value the message suggests (``fit_offset=True``, ``columns={'time_s': ...}``); without
        one, the message names the setting itself.
    assign : bool, default True
        Spelt as an assignment (``bounds=``) rather than as the bare name (``n_starts``); a setting
        with a value is always an assignment.
    keys : tuple of str, default ()
        The entries a dictionary-valued setting should hold (``bounds`` of the SVR hyperparameters
        named in the message), for an example of its value.

    Examples
    --------
    >>> str(Setting("fit_offset", True)), str(Setting("bounds")), str(Setting("n_starts", assign=False))
    ('fit_offset=True', 'bounds=', 'n_starts')
    """

    __slots__ = ("name", "value", "assign", "keys")

    def __init__(self, name: str, value=_UNSET, *, assign: bool = True, keys: tuple[str, ...] = ()):
        self.name = name
        self.value = value
        self.assign = assign or value is not _UNSET
        self.keys = tuple(keys)

    @property
    def has_value(self) -> bool:
        """Whether the message suggests a value."""
        return self.value is not _UNSET

    def __str__(self) -> str:
        if not self.assign:
            return self.name
        return f"{self.name}={_python(self.value)}" if self.has_value else f"{self.name}="

    def __repr__(self) -> str:
        return f"Setting({self})"

    def __reduce__(self):
        return (_setting, (self.name, self.value if self.has_value else None, self.has_value, self.assign,
                           self.keys))


def _setting(name, value, has_value, assign, keys) -> Setting:
    """A :class:`Setting` from its fields (unpickling, e.g. an error sent back by a fleet worker)."""
    return Setting(name, value, assign=assign, keys=keys) if has_value else Setting(name, assign=assign, keys=keys)


def _python(value) -> str:
    """``value`` as Python source; ``...`` stands for a value the user fills in."""
    if value is Ellipsis:
        return "..."
    if isinstance(value, dict):
        return "{" + ", ".join(f"{key!r}: {_python(item)}" for key, item in value.items()) + "}"
    return repr(value)


def _text(parts) -> str:
    return "".join(str(part) for part in parts)


class GreyboxError(Exception):
    """Base class of all errors that greybox reports to the user.

    Parameters
    ----------
    *parts : str or Setting
        The message: text, with the settings it names as :class:`Setting` parts. ``str(error)`` spells
        them as Python keywords; the command line as its options.
    """

    def __init__(self, *parts):
        self.parts = tuple(parts)
        super().__init__(_text(parts))

    def __reduce__(self):
        return (_rebuild, (type(self), str(self), self.__dict__))


def _rebuild(cls, text: str, state: dict) -> GreyboxError:
    """An error of class ``cls`` with message ``text`` and attributes ``state`` (unpickling: a fleet worker's)."""
    error = cls.__new__(cls)
    Exception.__init__(error, text)
    error.__dict__.update(state)
    return error


class SettingWarning(UserWarning):
    """A warning whose message names settings (:class:`Setting` parts), e.g. a search that ended at a bound.

    Parameters
    ----------
    *parts : str or Setting
        The message: text, with the settings it names as :class:`Setting` parts.
    """

    def __init__(self, *parts):
        self.parts = tuple(parts)
        super().__init__(_text(parts))

    def __reduce__(self):
        return (type(self), self.parts)  # a worker process's warning keeps the settings it names


class LogError(GreyboxError, ValueError):
    """An axis log cannot be read or fails validation.

    Parameters
    ----------
    source : str or path-like or None
        File the log came from; ``None`` for an in-memory log.
    *problem : str or Setting
        What is wrong, in words a user can act on: text, with the reader's settings it names as
        :class:`Setting` parts (``columns=``, ``sample_time``).
    """

    def __init__(self, source: str | PathLike | None, *problem):
        self.source = None if source is None else str(source)
        self.problem = _text(problem)
        where = self.source if self.source else "<in-memory log>"
        super().__init__(f"{where}: ", *problem)


class ModelFileError(GreyboxError, ValueError):
    """A model file is missing, corrupt, or of an unsupported format version."""


class ParameterError(GreyboxError, ValueError):
    """Model parameters are invalid, e.g. would make a forward-Euler step unstable."""
