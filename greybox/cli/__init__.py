"""The ``greybox`` command line.

Each sub-command lives in its own module of this package and provides
``add_parser(subparsers)``, which registers the sub-command (its options) and
sets ``run=<callable(args) -> int>`` as its default. :data:`SUMMARIES` lists
the sub-commands with their one-line summaries; a sub-command's module is
imported only when that sub-command runs (or shows its ``--help``), so that
``greybox --help`` loads no model, reader or plotting library. Errors caused by
the user's input (:class:`greybox.errors.GreyboxError`) are printed as one line
naming the file and the problem, with exit status 2 and no traceback; so are
errors of the operating system (a read-only file system, a full disk, a
permission: :class:`OSError`, naming the path) and any unexpected error (a bug:
one line naming it, its traceback only with ``greybox --debug``). Warnings
issued while a command runs, or while its options are read, are printed as one
``note:`` line each, never with a source line; in both, a model hyperparameter
is named by the option that sets it (:mod:`greybox.cli._spelling`).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import signal
import sys
import threading
import time
import warnings

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
        The arguments after the program name. Of the options of ``greybox`` itself only ``--key-file``
        takes a value, so the first other argument is the sub-command.

    Returns
    -------
    str or None
        That argument if it names a sub-command, else None.
    """
    skip = False
    for argument in argv:
        if skip:
            skip = False
            continue
        if argument == "--":
            return None
        if argument == "--key-file":
            skip = True
            continue
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
    parser.add_argument("--debug", action="store_true",
                        help="print the traceback of an unexpected error (default: one line)")
    parser.add_argument("--key-file", metavar="FILE",
                        help="file holding the plant's key: model files are signed with it when saved and must be "
                        "signed with it when loaded (as the variable GREYBOX_MODEL_KEY_FILE)")
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
    with warnings.catch_warnings():  # a warning while the modules load: one line, no source line
        warnings.showwarning = _one_line_warning
        parser = build_parser([command] if (command := command_of(arguments)) else [])
        args = parser.parse_args(arguments)
    with _key_file(args.key_file):
        return _run(args, argv)


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one ``note:`` line on stderr (before a command's own display is set up)."""
    print(f"note: {str(message).splitlines()[0] if str(message) else category.__name__}", file=sys.stderr)


@contextlib.contextmanager
def _key_file(path: str | None):
    """``--key-file``: the plant's key file for the command (the variable GREYBOX_MODEL_KEY_FILE), then restored."""
    if path is None:
        yield
        return
    from ..models.files import KEY_FILE_ENV

    before = os.environ.get(KEY_FILE_ENV)
    os.environ[KEY_FILE_ENV] = path
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(KEY_FILE_ENV, None)
        else:
            os.environ[KEY_FILE_ENV] = before


def os_error_line(error: OSError) -> str:
    """One line for an error of the operating system: the path(s) it names and the problem.

    Parameters
    ----------
    error : OSError
        The error (``filename``, ``filename2`` and ``strerror`` where the operating system gave them).
    """
    problem = error.strerror or str(error) or type(error).__name__
    paths = [str(name) for name in (error.filename, error.filename2) if name is not None]
    return f"{' -> '.join(paths)}: {problem}" if paths else problem


def _run(args: argparse.Namespace, argv: list[str] | None) -> int:
    """Run the parsed command; every error one line on stderr (a traceback only with --debug)."""
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
    except BrokenPipeError:  # the reader of the output went away (``greybox ... | head``): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:  # read-only file system, disk full, permission, ...
        if args.debug:
            raise
        print(f"greybox {args.command}: error: {os_error_line(error)}", file=sys.stderr)
        return 2
    except MemoryError:
        if args.debug:
            raise
        print(f"greybox {args.command}: error: out of memory; give fewer or shorter logs, or a machine with more "
              "memory", file=sys.stderr)
        return 2
    except Exception as error:  # a bug (or a signal handled inside compiled code, wrapped in a SystemError)
        stop = _signal_behind(error) if isinstance(error, SystemError) else None
        if stop is not None:
            return _stopped(stop, args.command)
        if args.debug:
            raise
        text = str(error).splitlines()[0] if str(error) else ""
        print(f"greybox {args.command}: internal error: {type(error).__name__}{': ' + text if text else ''} "
              "(a bug: please report it with the output of 'greybox --debug ...')", file=sys.stderr)
        return 2
    finally:
        if installed:
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


def run() -> None:
    """The ``greybox`` command (and ``python -m greybox``): :func:`main`, then exit with its status.

    A command stopped by a signal (status 143 or 130) has removed its temporary files and said so; it then
    exits without waiting for the worker threads of its pools. A pool that was starting a thread when the
    signal came may not know that thread yet, so the interpreter's exit would wait for it forever.
    """
    status = main()
    if status in (143, 130):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)


if __name__ == "__main__":  # pragma: no cover
    run()
