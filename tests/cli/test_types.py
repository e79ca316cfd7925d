"""Every numeric command-line option refuses a value out of its range: one line naming it, exit 2, no traceback.

The options are found from the parsers themselves (``greybox.cli.build_parser``), so a new option that
takes a value without a range check (``type=float``, ``type=int``, or a number default read as text)
fails :func:`test_every_valued_option_has_a_range_checked_type`, and every range-checked option is run
with values just beyond its bounds, non-finite values and text in
:func:`test_value_out_of_range_is_one_line_naming_option_and_range`.
"""

from __future__ import annotations

import argparse
import re

import pytest

import greybox.cli as cli
from greybox.cli._types import (
    FRACTION,
    MAX_SEED,
    NON_NEGATIVE,
    NON_NEGATIVE_INT,
    POSITIVE,
    POSITIVE_INT,
    SEED,
    NumberList,
    NumberRange,
    NumberSpan,
    WordOrNumber,
    positive,
)

CHECKED_TYPES = (NumberRange, WordOrNumber, NumberSpan, NumberList)


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = cli.build_parser()
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(action.choices)


def _takes_value(action: argparse.Action) -> bool:
    return action.nargs != 0 and not isinstance(action, (argparse._HelpAction, argparse._VersionAction))


def _valued_options():
    """(command, option, action) of every option of every sub-command that takes a value."""
    return [(command, action.option_strings[-1], action)
            for command, parser in _subparsers().items()
            for action in parser._actions if action.option_strings and _takes_value(action)]


def _range_options():
    return [(command, option, action) for command, option, action in _valued_options()
            if isinstance(action.type, CHECKED_TYPES)]


def _required_arguments(command: str) -> list[str]:
    """Placeholder values for the positionals and required options of ``command`` (never read)."""
    argv = []
    for action in _subparsers()[command]._actions:
        if not _takes_value(action) or not (action.required or not action.option_strings):
            continue
        value = str(sorted(action.choices)[0]) if action.choices else "placeholder"
        argv += ([action.option_strings[-1]] if action.option_strings else []) + [value]
    return argv


def _option_argv(option: str, action: argparse.Action, value: str) -> list[str]:
    """``--option=value``, or for an option of n values ``--option 0 ... value``."""
    if isinstance(action.nargs, int) and action.nargs > 1:
        return [option] + ["0"] * (action.nargs - 1) + [value]
    return [f"{option}={value}"]


def _cases():
    cases = []
    for command, option, action in _range_options():
        for value in action.type.outside():
            if isinstance(action.nargs, int) and action.nargs > 1 and value.startswith("-"):
                continue  # among several values, argparse takes "-inf" for an option: its own one-line error
            cases.append(pytest.param(command, option, action, value, id=f"{command} {option}={value}"))
    return cases


def test_every_valued_option_has_a_range_checked_type():
    unchecked = []
    for command, option, action in _valued_options():
        numeric_default = isinstance(action.default, (int, float)) and not isinstance(action.default, bool)
        if action.type is not None and not isinstance(action.type, CHECKED_TYPES):
            unchecked.append(f"greybox {command} {option}: type={getattr(action.type, '__name__', action.type)}")
        elif action.type is None and numeric_default:
            unchecked.append(f"greybox {command} {option}: default {action.default!r} but read as text")
    assert not unchecked, "options without a range check (use greybox.cli._types): " + "; ".join(unchecked)
    assert len(_range_options()) >= 30  # the numeric options of train, discover, synth, compensate, predict, ...


@pytest.mark.parametrize("command, option, action", [pytest.param(*case, id=f"{case[0]} {case[1]}")
                                                     for case in _range_options()])
def test_default_lies_in_the_range(command, option, action):
    if action.default is None:
        return
    if isinstance(action.default, str):
        assert action.type(action.default) == action.default.strip()
    else:
        assert action.type.contains(action.default) if isinstance(action.type, NumberRange) else True


@pytest.mark.parametrize("command, option, action, value", _cases())
def test_value_out_of_range_is_one_line_naming_option_and_range(capsys, command, option, action, value):
    with pytest.raises(SystemExit) as stop:
        cli.main([command, *_option_argv(option, action, value), *_required_arguments(command)])
    assert stop.value.code == 2
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and captured.out == ""
    names = "/".join(action.option_strings) if len(action.option_strings) > 1 else option
    assert captured.err.splitlines() == [f"greybox {command}: error: argument {names}: must be "
                                         f"{action.type.description}, got {value} (see greybox {command} --help)"]


def captured_error(capsys) -> str:
    (line,) = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    return line


@pytest.mark.parametrize("argv, message", [
    (["train", "--time-tolerance", "6"], "argument --time-tolerance: must be a fraction in (0, 1), got 6"),
    (["train", "--time-tolerance", "0"], "argument --time-tolerance: must be a fraction in (0, 1), got 0"),
    (["train", "--time-tolerance", "nan"], "argument --time-tolerance: must be a fraction in (0, 1), got nan"),
    (["train", "--model-seed", "-1"], f"argument --model-seed: must be an integer from 0 to {MAX_SEED}, got -1"),
    (["discover", "--seed", "-1"], f"argument --seed: must be an integer from 0 to {MAX_SEED}, got -1"),
    (["discover", "--time-tolerance", "6"], "argument --time-tolerance: must be a fraction in (0, 1), got 6"),
    (["compensate", "--inertia", "-1"], "argument --inertia: must be plant, model or a non-negative number, got -1"),
])
def test_the_reported_cases(capsys, argv, message):
    """The values of issue 12 that ended in ValueError tracebacks with exit status 1."""
    with pytest.raises(SystemExit) as stop:
        cli.main(argv[:1] + _required_arguments(argv[0]) + argv[1:])
    assert stop.value.code == 2
    assert captured_error(capsys) == f"greybox {argv[0]}: error: {message} (see greybox {argv[0]} --help)"


def test_values_in_range_pass_with_their_type():
    assert FRACTION("0.25") == 0.25 and POSITIVE("1e-9") == 1e-9 and NON_NEGATIVE("0") == 0.0
    assert POSITIVE_INT("1") == 1 and NON_NEGATIVE_INT("0") == 0
    assert SEED("0") == 0 and SEED(str(MAX_SEED)) == MAX_SEED and isinstance(SEED("7"), int)
    assert positive("seconds")("0.002") == 0.002
    for refused, checked in (("1", FRACTION), ("0", POSITIVE), ("-0.0001", NON_NEGATIVE), ("0", POSITIVE_INT),
                             ("2.0", POSITIVE_INT), ("1e3", SEED), (str(MAX_SEED + 1), SEED)):
        message = re.escape(f"must be {checked.description}, got {refused}")
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            checked(refused)
    inertia = WordOrNumber(("plant", "model"), NON_NEGATIVE)
    assert [inertia(text) for text in ("plant", "Model", " 0.5")] == ["plant", "Model", "0.5"]
    assert positive("seconds").description == "a positive number of seconds"
    assert SEED.description == f"an integer from 0 to {MAX_SEED}"
