"""The library's messages in the words of the command line: warnings become notes, parameters become options.

The library speaks Python: a model's hyperparameters by their keyword names (``fit_offset``,
``bounds=``, ``asymmetric=True``), warnings through :mod:`warnings` (printed by Python with the
category and the source line that issued them). A user of the ``greybox`` command knows options:
``--offset``, ``--set bounds=...``. This module rewrites the one into the other, for the errors the
command prints and for every warning issued while it runs, which it prints as one line each::

    note: svr: C = 1e+03 ended at the end of its search interval; the optimum may lie outside
    (widen it with --set bounds='{"NAME": [LOW, HIGH]}')

(one line on the terminal). What a model computes is not touched: only the text is.
"""

from __future__ import annotations

import argparse
import contextlib
import re
import sys
import warnings
from typing import Iterator

from ..errors import LogError, ParameterError
from ._model_options import MODEL_OPTIONS, CommandLineError

__all__ = ["OPTION_OF", "command_notes", "error_message", "option_words"]

#: Hyperparameter -> the option that sets it in train, discover and compensate (see ``_build``).
OPTION_OF = {hyperparameter: option for option, _, hyperparameter in MODEL_OPTIONS}

#: Options that are flags (no value): ``name=True`` is the flag itself.
_FLAGS = {"fit_offset", "asymmetric"}

#: Metavariables of the mapped options that take a value.
_METAVARS = {"n_elements": "N", "random_state": "N"}

#: Example values of ``--set NAME=VALUE`` where the form is not obvious.
_EXAMPLES = {"bounds": "'{\"NAME\": [LOW, HIGH]}'"}


def _bounds_example(text: str) -> str:
    """``--set bounds=`` value for the SVR hyperparameters ``text`` reports as ``name = value``, else generic."""
    from ..models.svr import BOUNDED

    named = [name for name in BOUNDED if re.search(rf"(?<![\w.\-]){re.escape(name)} = ", text)]
    if not named:
        return _EXAMPLES["bounds"]
    return "'{" + ", ".join(f'"{name}": [LOW, HIGH]' for name in named) + "}'"


def _hyperparameters() -> set[str]:
    """Names of the hyperparameters of every registered model kind."""
    from ..registry import MODEL_CLASSES

    names = set()
    for cls in MODEL_CLASSES.values():
        names.update(cls().get_params(deep=False))
    return names


def _set(name: str, value: str | None, settable: bool, example: str) -> str:
    text = f"--set {name}={value if value is not None else example}"
    return text if settable else f"{text} of greybox train"


def _option(name: str, value: str | None, settable: bool, text: str = "") -> str:
    """The command-line spelling of setting ``name`` (to ``value``, if given) in a message ``text``."""
    option = OPTION_OF.get(name)
    if option is None:
        example = _bounds_example(text) if name == "bounds" else _EXAMPLES.get(name, "VALUE")
        return _set(name, value, settable, example)
    if name in _FLAGS:
        return f"no {option}" if value == "False" else option
    return f"{option} {value if value is not None else _METAVARS.get(name, 'VALUE')}"


def option_words(text: str, *, parameters: bool = False, settable: bool = True, names=None) -> str:
    """Rewrite the Python spelling of model hyperparameters in ``text`` into command-line options.

    Parameters
    ----------
    text : str
        A message of the library.
    parameters : bool, default False
        The message is about a model's parameters (a :class:`~greybox.errors.ParameterError` or a
        warning of a fit): then also a bare name of a hyperparameter that has an option of its own
        (``asymmetric``) is taken for the hyperparameter.
    settable : bool, default True
        Whether the command offers ``--set NAME=VALUE``; if not, a setting is named as one of
        ``greybox train``.
    names : iterable of str, optional
        Hyperparameter names to rewrite; default those of every registered model kind.

    Returns
    -------
    str
        ``name=True`` -> the flag (``--asymmetric``); ``name=VALUE`` -> ``--option VALUE`` or
        ``--set name=VALUE``; ``name=`` -> the same with a placeholder; a bare name with an
        underscore (``fit_offset``) -> its option, or ``--set name``, unless it is quoted or reports
        a value (``name = 3.2``). Other words are kept, and so is the whole text when it names no
        hyperparameter.

    Examples
    --------
    >>> option_words("use asymmetric=True or fit_offset=True")
    'use --asymmetric or --offset'
    >>> option_words("the optimum may lie outside (widen it with bounds=)")
    'the optimum may lie outside (widen it with --set bounds=\\'{"NAME": [LOW, HIGH]}\\')'
    """
    names = sorted(set(_hyperparameters() if names is None else names), key=len, reverse=True)
    if not names:
        return text
    alternatives = "|".join(re.escape(name) for name in names)
    edge = r"(?<![\w.\-])"
    assignment = re.compile(edge + rf"({alternatives})=([\w.+\-]+)?")
    original = text
    text = assignment.sub(lambda m: _option(m.group(1), m.group(2), settable, original), text)

    def bare(match: re.Match) -> str:
        name = match.group(1)
        if name in OPTION_OF:
            return OPTION_OF[name]
        return f"--set {name}" if settable else f"{name} (--set {name}=VALUE of greybox train)"

    identifiers = [name for name in names if "_" in name or (parameters and name in OPTION_OF)]
    if identifiers:
        # not a quoted key ("NAME" of a bounds example) nor a reported value ("name = 3.2")
        pattern = r"(?<![\w.\-\"])(" + "|".join(re.escape(name) for name in identifiers) + r")(?![\w\-=\"]| = )"
        text = re.sub(pattern, bare, text)
    return text


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


#: The log readers' keyword arguments, as the options that set them (``add_log_arguments``).
_READER_WORDS = (
    (re.compile(r"columns=\{'(\w+)': '([^']*)'\}"), r"--columns \1=\2"),
    (re.compile(r"columns=\{'(\w+)': \.\.\.\}"), r"--columns \1=COLUMN"),
    (re.compile(r"(?<![\w\-])columns=(?![\w{])"), "--columns NAME=COLUMN"),
    (re.compile(r"(?<![\w\-])sample_time(?![\w=])"), "--sample-time"),
    (re.compile(r"(?<![\w\-])topic= \("), "--topic TOPIC ("),
    (re.compile(r" \(axis= in Python\)"), ""),
    (re.compile(r" \(or give the format explicitly\)"), ""),
)


def reader_words(text: str) -> str:
    """Rewrite the log readers' keyword arguments in ``text`` into their options (``columns=`` -> ``--columns``)."""
    for pattern, replacement in _READER_WORDS:
        text = pattern.sub(replacement, text)
    return text


def error_message(error: BaseException, args: argparse.Namespace) -> str:
    """The text of a user-facing error of a command, hyperparameters spelt as options, on one line.

    Parameters
    ----------
    error : BaseException
        The error the command raised. A :class:`CommandLineError` is shown as is, a log-reading error
        in the reader's option words, any other with model hyperparameters spelt as options.
    args : argparse.Namespace
        The parsed command line (whether it offers ``--set``).
    """
    if isinstance(error, CommandLineError):
        return _one_line(error)
    if isinstance(error, LogError):
        return reader_words(_one_line(error))
    return option_words(_one_line(error), parameters=isinstance(error, ParameterError),
                        settable=hasattr(args, "set"))


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
        note = "note: " + option_words(_one_line(message), parameters=True, settable=settable)
        if note in printed:
            return
        printed.append(note)
        print(note, file=stream or sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield printed
