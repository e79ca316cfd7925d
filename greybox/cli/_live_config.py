"""The configuration file of ``greybox live --config``: every option as a TOML key, read as the command line reads it.

A key is an option's name without the dashes, ``-`` or ``_`` alike (``record_s = 60``, ``tls-ca = "ca.pem"``);
a value is what the command line would take, checked by the same types: a number or a string for an option
with a value, ``true``/``false`` for a switch, a list of strings for a repeatable option (``limit =
["force_process_N=1500"]``). The password is never a key: give ``password_file``.
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

from ..errors import GreyboxError

__all__ = ["read_config"]


def _value(action: argparse.Action, value, where: str):
    """The value of one key, converted and checked as the option's action would on the command line."""
    if isinstance(action, argparse._StoreTrueAction):
        if not isinstance(value, bool):
            raise GreyboxError(f"{where}: give true or false")
        return value
    if isinstance(action, argparse._AppendAction):
        values = value if isinstance(value, list) else [value]
        return [_value_of(action, item, where) for item in values]
    return _value_of(action, value, where)


def _value_of(action: argparse.Action, value, where: str):
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise GreyboxError(f"{where}: give a number or a string, got {value!r}")
    text = str(value)
    try:
        converted = action.type(text) if action.type is not None else text
    except (argparse.ArgumentTypeError, ValueError, TypeError) as exc:
        raise GreyboxError(f"{where}: {exc}") from None
    if action.choices is not None and converted not in action.choices:
        raise GreyboxError(f"{where}: give one of {', '.join(map(str, action.choices))}")
    return converted


def read_config(path, actions: dict) -> dict:
    """The option values of a TOML configuration file.

    Parameters
    ----------
    path : path-like
        The file.
    actions : dict of str to argparse.Action
        The command's options by destination (``record_s``, ...).

    Returns
    -------
    dict of str to object
        ``{destination: value}`` for every key of the file.

    Raises
    ------
    GreyboxError
        For a file that cannot be read or is not TOML, an unknown key, a password, or a value the option
        refuses; the message names the file and the key.
    """
    try:
        document = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise GreyboxError(f"--config {path}: cannot read it ({exc.strerror})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise GreyboxError(f"--config {path}: not TOML ({exc})") from None
    out = {}
    for key, value in document.items():
        dest = key.replace("-", "_")
        where = f"--config {path}: {key}"
        if dest == "password":
            raise GreyboxError(f"{where}: the password is not kept in the configuration; give password_file")
        action = actions.get(dest)
        if action is None or dest in ("config", "help") or isinstance(action, argparse._VersionAction):
            known = ", ".join(sorted(name for name in actions if name not in ("config", "help")))
            raise GreyboxError(f"{where}: no such option; the keys are {known}")
        out[dest] = _value(action, value, where)
    return out
