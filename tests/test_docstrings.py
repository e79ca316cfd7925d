"""Every public function, class and method documents each of its parameters, and only those (numpydoc).

Public: the names in a module's ``__all__`` (compiled numba functions included); for a class, its
constructor and the methods it defines whose names do not start with an underscore. A parameter is
documented when its name heads an entry of the docstring's ``Parameters`` or ``Other Parameters``
section (a class's constructor in the class docstring; a dataclass may list its fields under
``Attributes`` instead). ``*args`` and ``**kwargs`` are exempt. The command-line entry point
(``greybox.__main__``) is wired by argparse and has none. The validation studies of the repository
(``studies/``, not installed) are held to the same rule.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re

import pytest

import greybox
import studies

SECTIONS = ("Parameters", "Other Parameters")
ENTRY = re.compile(r"^([*A-Za-z_][\w*]*(?:\s*,\s*[*A-Za-z_][\w*]*)*)\s*(?::|$)")


def module_names() -> list[str]:
    names = ["greybox", "studies"]
    for package in (greybox, studies):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if not info.name.endswith("__main__"):
                names.append(info.name)
    return sorted(names)


def section_entries(doc: str | None, sections: tuple[str, ...]) -> set[str]:
    """Names heading the entries of the named numpydoc sections of ``doc``."""
    if not doc:
        return set()
    lines = inspect.cleandoc(doc).splitlines()
    names: set[str] = set()
    inside = False
    for k, line in enumerate(lines):
        underlined = k + 1 < len(lines) and line.strip() and set(lines[k + 1].strip()) == {"-"}
        if underlined:
            inside = line.strip() in sections
            continue
        if inside and line and not line[0].isspace() and not set(line.strip()) <= {"-"}:
            match = ENTRY.match(line)
            if match:
                names.update(part.strip().lstrip("*") for part in match.group(1).split(","))
    return names


def own_parameters(function) -> tuple[list[str], set[str]]:
    """The parameters a docstring must document, and all it may (``*args`` and ``**kwargs`` too)."""
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return [], set()
    names = [name for name in signature.parameters if name not in ("self", "cls")]
    variable = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return [name for name in names if signature.parameters[name].kind not in variable], set(names)


def public_callables(module) -> list[tuple[str, object, str | None, tuple[str, ...]]]:
    """(label, function, docstring, sections) for each public callable defined in ``module``."""
    found = []
    for name in getattr(module, "__all__", ()):
        value = getattr(module, name)
        value = getattr(value, "py_func", value)  # a compiled (numba) function: its Python source
        if getattr(value, "__module__", None) != module.__name__:
            continue  # re-exported: checked where it is defined
        if inspect.isfunction(value):
            found.append((f"{module.__name__}.{name}", value, value.__doc__, SECTIONS))
        elif inspect.isclass(value):
            sections = SECTIONS + ("Attributes",) if dataclasses.is_dataclass(value) else SECTIONS
            if "__init__" in vars(value) or dataclasses.is_dataclass(value):
                found.append((f"{module.__name__}.{name}", value.__init__, value.__doc__, sections))
            for method_name, method in vars(value).items():
                method = method.__func__ if isinstance(method, (staticmethod, classmethod)) else method
                if not method_name.startswith("_") and inspect.isfunction(method):
                    found.append((f"{module.__name__}.{name}.{method_name}", method, method.__doc__, SECTIONS))
    return found


@pytest.mark.parametrize("module_name", module_names())
def test_public_parameters_are_documented(module_name):
    module = importlib.import_module(module_name)
    problems = []
    for label, function, doc, sections in public_callables(module):
        required, allowed = own_parameters(function)
        documented = section_entries(doc, sections)
        missing = [name for name in required if name not in documented]
        if missing:
            problems.append(f"{label}: undocumented {', '.join(missing)}")
        stale = sorted(documented - allowed) if sections == SECTIONS else []
        if stale:
            problems.append(f"{label}: documents {', '.join(stale)}, which it does not take")
    assert not problems, "\n".join(problems)


def test_the_section_reader_finds_grouped_entries_and_nothing_else():
    doc = """Summary.

    Parameters
    ----------
    a, b : float
        Two [mm].
    c : int
        With a colon: in the text.
    **kwargs
        Passed on.

    Returns
    -------
    d : float
    """
    assert section_entries(doc, SECTIONS) == {"a", "b", "c", "kwargs"}
    assert section_entries("No sections.", SECTIONS) == set()
