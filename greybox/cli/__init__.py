"""The ``greybox`` command line.

Each sub-command lives in its own module of this package and provides
``add_parser(subparsers)``, which registers the sub-command (its options) and
sets ``run=<callable(args) -> int>`` as its default. :data:`SUMMARIES` lists
the sub-commands with their one-line summaries; a sub-command's module is
imported only when that sub-command runs (or shows its ``--help``), so that
``greybox --help`` loads no model, reader or plotting library. Errors caused by
the user's input (:class:`greybox.errors.GreyboxError`) are printed as one line
naming the file and the problem, with exit status 2 and no traceback. Warnings
issued while a command runs are printed as one ``note:`` line each; in both, a
model hyperparameter is named by the option that sets it
(:mod:`greybox.cli._spelling`).
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading
import time

from ..errors import GreyboxError
from ._spelling import command_notes, error_message

#: Sub-commands, in the order ``greybox --help`` lists them: name (of the command and of its module in this
#: package) -> one-line summary.
SUMMARIES = {
    "synth": "write synthetic axis logs (datasets A-D, P) of the twin machine",
    "info": "summarise logs and model files",
    "plot": "draw a log as a PNG",
    "train": "fit a current model to logs and save it",
    "evaluate": "test saved models on logs and report their errors",
    "predict": "process current (and force) of a cutting log from a model trained on air cuts",
    "reproduce": "run the paper's experiments on the shipped data and write the report",
    "discover": "find, name and add the effects a friction model misses",
    "compensate": "compare friction models by the tracking error of a position loop with their feed-forward",
    "plan": "write the air-cut NC program (datasets A and B of the paper) to run on the machine",
    "live": "process current (and force) of a live stream from the controller (MQTT or stdin), with limits",
    "examples": "write the example axis and machine files into a folder",
    "monitor": "fingerprint axis logs into a history, detect friction changes, write a dashboard",
    "process": "teach an envelope of the cutting force from good parts, check parts against it",
}
#: Sub-command modules, in the order ``greybox --help`` lists them.
COMMANDS = tuple(SUMMARIES)


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (the option, the problem) and exit status 2."""

    def error(self, message: str):
        """Print ``<prog>: error: <message> (see <prog> --help)`` on stderr and exit with status 2."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


class _Registrar:
    """The sub-parsers as a sub-command's module sees them: its one-line summary comes from :data:`SUMMARIES`."""

    def __init__(self, subparsers):
        self._subparsers = subparsers

    def add_parser(self, name: str, **kwargs) -> argparse.ArgumentParser:
        """Register the sub-command ``name`` (keyword arguments of :class:`argparse.ArgumentParser`) and return its
        parser.

        Parameters
        ----------
        name : str
            The sub-command, a key of :data:`SUMMARIES`.
        **kwargs
            Passed on to the sub-parsers' ``add_parser`` (description, ...); ``help`` is the summary.
        """
        kwargs["help"] = SUMMARIES[name]
        return self._subparsers.add_parser(name, **kwargs)


def command_of(argv: list[str]) -> str | None:
    """The sub-command that ``argv`` names, if any: its first argument that is not an option.

    Parameters
    ----------
    argv : list of str
        The arguments after the program name. The options of ``greybox`` itself (``--help``,
        ``--version``) take no value, so the first other argument is the sub-command.

    Returns
    -------
    str or None
        That argument if it names a sub-command, else None.
    """
    for argument in argv:
        if argument == "--":
            return None
        if not argument.startswith("-"):
            return argument if argument in COMMANDS else None
    return None


def build_parser(commands=None) -> argparse.ArgumentParser:
    """Return the argument parser of the ``greybox`` command.

    Parameters
    ----------
    commands : iterable of str, optional
        The sub-commands whose modules are imported and whose options are registered; the others are listed
        by their summary only (enough for ``greybox --help`` and for naming an unknown sub-command). Default:
        all of them.
    """
    from .. import __version__

    parser = OneLineParser(
        prog="greybox",
        description="Grey-box motor-current models of machine-tool feed axes.",
    )
    parser.add_argument("--version", action="version", version=f"greybox {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                       parser_class=OneLineParser)
    loaded = set(COMMANDS if commands is None else commands)
    for name in COMMANDS:
        if name in loaded:
            importlib.import_module(f"{__name__}.{name}").add_parser(_Registrar(subparsers))
        else:
            subparsers.add_parser(name, help=SUMMARIES[name])
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM (a scheduler or ``kill`` stopping the command), raised like Ctrl-C so that half-written outputs
    are removed on the way out (:func:`greybox.atomic.atomic_output`)."""


def _terminate(signum, frame):
    raise Terminated()


def _signal_behind(error: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C or SIGTERM in the causes of ``error``, if any.

    A signal's handler raises where the interpreter happens to be; inside a Python callback of compiled
    code (numba loading a cached function) the exception comes out as a ``SystemError`` caused by it.
    """
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def _stopped(stop: KeyboardInterrupt, command: str) -> int:
    """Say how the command was stopped; the exit status (143 for SIGTERM, 130 for Ctrl-C)."""
    if isinstance(stop, Terminated):
        print(f"greybox {command}: terminated (SIGTERM); no output was left half-written", file=sys.stderr)
        return 143
    print(f"greybox {command}: interrupted", file=sys.stderr)
    return 130


def process_age_s() -> float | None:
    """Seconds since this process started (Python's start-up and imports included), or None where unknown.

    Read from Linux's ``/proc`` (the process's start in clock ticks since boot, against the uptime).
    """
    try:
        with open("/proc/self/stat", encoding="ascii") as stream:
            fields = stream.read().rsplit(")", 1)[1].split()
        with open("/proc/uptime", encoding="ascii") as stream:
            uptime = float(stream.read().split()[0])
        return max(0.0, uptime - int(fields[19]) / os.sysconf("SC_CLK_TCK"))  # field 22: starttime
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def main(argv: list[str] | None = None) -> int:
    """Run the ``greybox`` command and return its exit status.

    SIGTERM ends the command like Ctrl-C: no output is left half-written, an earlier file of the same
    name is kept, and the status is 143 (130 for Ctrl-C).
    """
    arguments = sys.argv[1:] if argv is None else argv
    parser = build_parser([command] if (command := command_of(arguments)) else [])
    args = parser.parse_args(arguments)
    age = process_age_s() if argv is None else None  # a command of its own: its start-up counts too
    args.started_s = time.perf_counter() - (age or 0.0)
    args.startup_counted = age is not None
    installed = threading.current_thread() is threading.main_thread()  # signals reach the main thread only
    previous = signal.signal(signal.SIGTERM, _terminate) if installed else None
    try:
        with command_notes(args):  # warnings as one-line notes naming options, not Python
            return int(args.run(args) or 0)
    except GreyboxError as error:
        print(f"greybox {args.command}: error: {error_message(error, args)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as stop:  # Ctrl-C, or SIGTERM (Terminated)
        return _stopped(stop, args.command)
    except SystemError as error:  # a signal handled inside a callback of compiled code comes out wrapped
        stop = _signal_behind(error)
        if stop is None:
            raise
        return _stopped(stop, args.command)
    except BrokenPipeError:  # the reader of the output went away (``greybox ... | head``): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    finally:
        if installed:
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
