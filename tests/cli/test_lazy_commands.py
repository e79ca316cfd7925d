"""``greybox --help`` lists every sub-command from the table without importing their modules.

A sub-command's module (its options, and the models, readers and plots it uses)
is imported only when that sub-command runs or shows its own ``--help``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from greybox import cli

REPO = Path(__file__).resolve().parents[2]
#: Most greybox modules ``greybox --help`` may load (issue 32's target).
HELP_MODULES = 25

#: Runs ``python -m greybox ARGS`` (as ``runpy`` does for ``-m``), then prints the modules it loaded as JSON.
_PROBE = """
import json, runpy, sys
sys.argv = ["greybox", *sys.argv[1:]]
code = 0
try:
    runpy.run_module("greybox", run_name="__main__", alter_sys=True)
except SystemExit as stop:
    code = stop.code
print(json.dumps({"code": code, "modules": sorted(sys.modules)}), file=sys.stderr)
"""


def loaded_by(*args: str) -> tuple[int, str, list[str]]:
    """Exit status, standard output and the modules loaded by ``python -m greybox ARGS`` in a fresh interpreter."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])))
    result = subprocess.run([sys.executable, "-c", _PROBE, *args], capture_output=True, text=True, env=env,
                            cwd=REPO, timeout=300)
    report = json.loads(result.stderr.strip().splitlines()[-1])
    return report["code"], result.stdout, report["modules"]


def greybox_modules(modules: list[str]) -> list[str]:
    """The greybox modules among ``modules``."""
    return [name for name in modules if name == "greybox" or name.startswith("greybox.")]


def test_help_lists_every_command_and_loads_no_command_module():
    code, out, modules = loaded_by("--help")
    assert code == 0
    for name, summary in cli.SUMMARIES.items():
        assert f"    {name}" in out
        assert summary.split()[0] in out
    ours = greybox_modules(modules)
    assert len(ours) <= HELP_MODULES, f"greybox --help imports {len(ours)} greybox modules: {ours}"
    assert not [name for name in ours if name.removeprefix("greybox.cli.") in cli.COMMANDS], ours
    assert not {"numpy", "greybox.models.friction", "greybox.models", "greybox.data"} & set(modules)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_a_commands_help_loads_that_command_only_and_shows_its_options():
    code, out, modules = loaded_by("train", "--help")
    assert code == 0
    assert "--model" in out and "--out" in out  # train's own options
    assert "greybox.cli.train" in modules
    assert not {f"greybox.cli.{name}" for name in cli.COMMANDS if name != "train"} & set(modules)


@pytest.mark.parametrize("args, expected", [
    (["train", "--log", "a.csv"], "train"),
    (["--version"], None),
    (["-h", "reproduce"], "reproduce"),
    (["bogus", "train"], None),
    (["--", "train"], None),
    ([], None),
])
def test_the_command_is_the_first_argument_that_is_no_option(args, expected):
    assert cli.command_of(args) == expected


def test_the_full_parser_has_every_commands_options_and_the_tables_summaries():
    parser = cli.build_parser()
    (subparsers,) = [action for action in parser._actions if action.dest == "command"]
    assert list(subparsers.choices) == list(cli.COMMANDS)
    assert {action.dest: action.help for action in subparsers._choices_actions} == cli.SUMMARIES
    for name in cli.COMMANDS:  # every module registered options beyond --help
        assert len(subparsers.choices[name]._actions) > 1, name


def test_a_lazily_built_parser_names_unknown_commands_as_before(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["no-such-command"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'no-such-command'" in err and "'train'" in err and "'monitor'" in err
