"""The example axis and machine files are installed with the package and written out by ``greybox examples``."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import greybox
from greybox.cli import main
from greybox.cli.examples import EXAMPLE_FILES
from greybox.data.axis_config import read_axis_config
from greybox.data.machine_config import read_machine_config

REPO = Path(__file__).resolve().parents[2]


def test_the_example_files_are_package_data():
    package = Path(greybox.__file__).parent
    shipped = sorted(path.name for path in (package / "examples").glob("*.toml"))
    assert shipped == sorted(EXAMPLE_FILES)
    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["greybox"]
    assert all(any((package / "examples" / name).match(pattern) for pattern in patterns) for name in shipped)
    for name in shipped:  # the repository's examples/ is the same files
        assert (REPO / "examples" / name).read_bytes() == (package / "examples" / name).read_bytes()


def test_greybox_examples_writes_files_that_read_and_keeps_existing_ones(tmp_path, capsys):
    out = tmp_path / "ex"
    assert main(["examples", str(out)]) == 0
    assert "greybox synth --axis X Y --out data --seed 2024" in capsys.readouterr().out
    assert read_axis_config(out / "axis_x.toml").screw_lead_mm == 10.0
    assert read_axis_config(out / "axis_c.toml").motion == "rotary"
    assert set(read_machine_config(out / "machine.toml").axes) >= {"X"}
    (out / "axis_x.toml").write_text("mine\n")
    assert main(["examples", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--force" in err
    assert (out / "axis_x.toml").read_text() == "mine\n" and (out / "axis_c.toml").exists()
    assert main(["examples", str(out), "--force"]) == 0
    assert (out / "axis_x.toml").read_text() != "mine\n"


@pytest.mark.parametrize("name", EXAMPLE_FILES)
def test_help_names_the_command_that_writes_the_examples(name, capsys):
    with pytest.raises(SystemExit):
        main(["examples", "--help"])
    assert name in capsys.readouterr().out
