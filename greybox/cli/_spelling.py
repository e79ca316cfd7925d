"""The library's messages in the words of the command line: settings spelt as options, warnings as notes.

The library names a setting in a message as a :class:`~greybox.errors.Setting` part (Python reads
``fit_offset=True``); this module spells each such part as the option that sets it (``--offset``),
from one table, :data:`OPTIONS`. Text is never searched or rewritten: a message without settings is
printed as it is, on one line. Every warning issued while a command runs is printed as one line::

    note: svr: C = 1e+03 ended at the end of its search interval; the optimum may lie outside
    (widen it with --set bounds='{"C": [LOW, HIGH]}')

(one line on the terminal). What a model computes is not touched: only the text is.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import warnings
from dataclasses import dataclass
from typing import Iterator

from ..errors import Setting
from ._model_options import MODEL_OPTIONS

__all__ = ["OPTIONS", "Option", "command_notes", "error_message", "spelt", "message_text"]


@dataclass(frozen=True)
class Option:
    """The option that sets a setting.

    Parameters
    ----------
    flag : str
        The option, e.g. ``"--elements"``.
    metavar : str or None
        Placeholder of its value (``"N"``); None for an option without a value (``--offset``).
    """

    flag: str
    metavar: str | None = None


#: Model hyperparameters without an option of their own take a value, ``--set NAME=VALUE``; these take
#: none (``--asymmetric``, ``--offset``).
_FLAGS = {"fit_offset", "asymmetric"}

#: Metavariables of the model options (as ``greybox.cli._build`` declares their options).
_MODEL_METAVARS = {"n_elements": "N", "random_state": "N", "inertia": "J"}

#: Setting -> the option that sets it: the model options of train, discover and compensate
#: (``greybox.cli._model_options``), the log readers' options (``greybox.cli._options.add_log_arguments``) and
#: those of ``greybox predict`` and ``greybox plot``.
OPTIONS: dict[str, Option] = {
    **{name: Option(flag, None if name in _FLAGS else _MODEL_METAVARS.get(name, "VALUE"))
       for flag, _, name in MODEL_OPTIONS},
    "columns": Option("--columns", "NAME=COLUMN"),
    "sample_time": Option("--sample-time", "S"),
    "topic": Option("--topic", "TOPIC"),
    "axis": Option("--axis", "NAME"),
    # greybox predict (greybox.predict.predict_logs); the windows of plot and predict
    "out": Option("--out", "OUT"),
    "axis_config": Option("--axis-config", "TOML"),
    "machine": Option("--machine", "TOML"),
    "calibration": Option("--calibration", "AIRCUT..."),
    "coverage": Option("--interval", "C"),
    "plot": Option("--plot", "PNG"),
    "plot_window": Option("--plot-window", "START END"),
    "window": Option("--window", "START END"),
    "scheduler": Option("--scheduler", "ADDRESS"),
    "workers": Option("--workers", "N"),
}


def _set_value(setting: Setting) -> str:
    """The ``VALUE`` of ``--set NAME=VALUE`` for a setting without an option of its own."""
    if setting.has_value:
        return str(setting.value)
    if setting.keys or setting.name == "bounds":
        keys = setting.keys or ("NAME",)
        return "'{" + ", ".join(f'"{key}": [LOW, HIGH]' for key in keys) + "}'"
    return "VALUE"


def _option_value(setting: Setting, option: Option) -> str:
    """``--option VALUE`` (or ``--flag`` / ``no --flag``) for a setting that has an option."""
    if option.metavar is None:
        return f"no {option.flag}" if setting.value is False else option.flag
    value = setting.value
    if isinstance(value, dict):  # columns={'time_s': 'Zeit'} -> --columns time_s=Zeit
        return " ".join(f"{option.flag} {key}={'COLUMN' if item is Ellipsis else item}" for key, item in value.items())
    return f"{option.flag} {value if setting.has_value else option.metavar}"


def spell(setting: Setting, *, settable: bool = True) -> str:
    """The command-line spelling of one setting named in a message.

    Parameters
    ----------
    setting : Setting
        The setting the message names.
    settable : bool, default True
        Whether the command offers ``--set NAME=VALUE``; if not, a setting without an option of its
        own is named as one of ``greybox train``.

    Returns
    -------
    str
        ``--offset``, ``no --offset``, ``--elements 4``, ``--elements N``, ``--columns time_s=COLUMN``,
        ``--set C=2.0``, ``--set max_iter`` ...

    Examples
    --------
    >>> spell(Setting("fit_offset", True)), spell(Setting("n_elements")), spell(Setting("C", 2.0))
    ('--offset', '--elements N', '--set C=2.0')
    >>> spell(Setting("n_starts", assign=False), settable=False)
    'n_starts (--set n_starts=VALUE of greybox train)'
    """
    option = OPTIONS.get(setting.name)
    if option is not None:
        return _option_value(setting, option) if setting.assign else option.flag
    if not setting.assign:
        name = setting.name
        return f"--set {name}" if settable else f"{name} (--set {name}=VALUE of greybox train)"
    text = f"--set {setting.name}={_set_value(setting)}"
    return text if settable else f"{text} of greybox train"


def spelt(parts, *, settable: bool = True) -> str:
    """A message from its parts, settings spelt as options, on one line.

    Parameters
    ----------
    parts : iterable of str or Setting
        The message's parts (``error.parts`` of a :class:`~greybox.errors.GreyboxError`).
    settable : bool, default True
        Whether the command offers ``--set NAME=VALUE``.

    Returns
    -------
    str

    Examples
    --------
    >>> spelt(["choose ", Setting("asymmetric", assign=False), " or ", Setting("fit_offset", assign=False)])
    'choose --asymmetric or --offset'
    """
    text = "".join(spell(part, settable=settable) if isinstance(part, Setting) else str(part) for part in parts)
    return " ".join(text.split())


def message_text(thing: BaseException, *, settable: bool) -> str:
    """An error's or a warning's text in command-line words (its parts, if it has them), on one line.

    Parameters
    ----------
    thing : BaseException
        The error, or the warning's message (a :class:`Warning`).
    settable : bool
        Whether the command offers ``--set NAME=VALUE``.
    """
    parts = getattr(thing, "parts", None)
    return spelt(parts if parts is not None else [str(thing)], settable=settable)


def error_message(error: BaseException, args: argparse.Namespace) -> str:
    """The text of a user-facing error of a command, settings spelt as options, on one line.

    Parameters
    ----------
    error : BaseException
        The error the command raised.
    args : argparse.Namespace
        The parsed command line (whether it offers ``--set``).
    """
    return message_text(error, settable=hasattr(args, "set"))


@contextlib.contextmanager
def command_notes(args: argparse.Namespace, stream=None) -> Iterator[list[str]]:
    """Print every warning issued inside the block as one ``note:`` line, in command-line words.

    Python's default display (category, file, line number and the source line that issued the
    warning) is replaced for the duration of the block; which warnings are shown is not changed
    (Python's filters still apply), and a note is printed once however often it is issued.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (whether it offers ``--set``).
    stream : file-like, optional
        Where the notes go; default ``sys.stderr`` at the time of the warning.

    Yields
    ------
    list of str
        The notes printed so far.
    """
    printed: list[str] = []
    settable = hasattr(args, "set")

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        note = "note: " + message_text(message, settable=settable)
        if note in printed:
            return
        printed.append(note)
        print(note, file=stream or sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield printed
