"""The training defaults are the library's (issue 43, ask 3): ``train_logs(kind, logs)`` with no options gives
the model of ``greybox train --model KIND`` on the same logs, for every kind, one axis or a machine's."""

from __future__ import annotations

import json

import numpy as np
import pytest
from friction_signals import motion_log, velocity_profile

from greybox.cli import main
from greybox.data.io import write_log
from greybox.data.machine_config import MachineAxis
from greybox.models.files import load_model
from greybox.models.machine import load_machine
from greybox.models.registry import MODEL_CLASSES
from greybox.train import train_logs, train_machine_logs
from greybox.train.defaults import with_training_defaults

#: Effort offset of the logs [A]: a sensor's offset, which the training default fits.
OFFSET = 0.25


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    """A short two-axis log whose effort is inertia, Coulomb and viscous friction and an offset."""
    velocity = velocity_profile(1.2, seed=3, v_max=60.0)
    run = motion_log(velocity)
    noise = 0.01 * np.random.default_rng(3).standard_normal(len(velocity))
    run = run.replace(effort=0.002 * run.acceleration + 0.9 * np.sign(velocity) + 0.01 * velocity + OFFSET + noise,
                      velocity=None, acceleration=None)
    path = tmp_path_factory.mktemp("defaults") / "run.csv"
    write_log([run.replace(axis="X"), run.replace(axis="Y")], path)
    return path


def _summary(capsys, path) -> dict:
    """``greybox info --json`` of a model file: its parameters, hyperparameters' effects and records."""
    assert main(["info", "--json", str(path)]) == 0
    summary = json.loads(capsys.readouterr().out)
    summary.pop("file")
    return summary


def _params(model) -> dict:
    """Hyperparameters, a nested model's by its own (estimators compare by identity)."""
    return {name: _params(value) if hasattr(value, "get_params") else value
            for name, value in model.get_params(deep=False).items()}


#: Kinds whose fit takes seconds (multi-start searches, a Bayesian search of an SVR): in the slow set; the
#: static curves check the default in the default set.
SLOW = {"gms", "svr", "gmssvr", "lugre"}


@pytest.mark.parametrize("kind", [pytest.param(kind, marks=pytest.mark.slow) if kind in SLOW else kind
                                  for kind in sorted(MODEL_CLASSES)])
def test_a_kind_named_without_options_is_the_command_lines_model(kind, log, tmp_path, capsys):
    cli_file = tmp_path / "cli.gbm"
    assert main(["train", "--model", kind, "--axis", "X", "--train", str(log), "--out", str(cli_file), "--quiet",
                 "--intervals", "none"]) == 0
    capsys.readouterr()
    python_file = tmp_path / "python.gbm"
    model = train_logs(kind, [log], read={"axis": "X"}, intervals="none", out=python_file)
    assert _params(model) == _params(load_model(cli_file))
    assert _summary(capsys, python_file) == _summary(capsys, cli_file)  # parameters and training record


def test_a_machine_model_of_a_kind_named_without_options_is_the_command_lines(log, tmp_path, capsys):
    assert main(["train", "--model", "stribeck", "--axes", "X,Y", "--train", str(log), "--out", str(tmp_path / "cli"),
                 "--quiet", "--intervals", "none"]) == 0
    capsys.readouterr()
    machine = train_machine_logs("stribeck", [log], [MachineAxis("X", "linear"), MachineAxis("Y", "linear")],
                                 intervals="none", out=tmp_path / "python")
    cli_machine = load_machine(tmp_path / "cli")
    for axis in ("X", "Y"):
        assert machine.models[axis].fit_offset and _params(machine.models[axis]) == _params(cli_machine.models[axis])
        python_file, cli_file = (tmp_path / folder / f"{axis}.gbm" for folder in ("python", "cli"))
        assert _summary(capsys, python_file) == _summary(capsys, cli_file)


def test_the_default_fits_the_offset_the_logs_hold(log):
    model = train_logs("coulomb", [log], read={"axis": "X"}, intervals="none")
    plain = train_logs("coulomb", [log], params={"fit_offset": False}, read={"axis": "X"}, intervals="none")
    assert model.fit_offset and not plain.fit_offset
    assert abs(model.offset_) > 0.5 * OFFSET  # the logs' offset, which the plain model cannot carry


@pytest.mark.parametrize("kind, params, offset", [
    ("gms", {}, True),
    ("gms", {"fit_offset": False}, False),
    ("gms", {"asymmetric": True}, False),
    ("gms", {"n_elements": 2}, True),
    ("svr", {}, None),
])
def test_an_offset_is_the_default_unless_the_caller_chose(kind, params, offset):
    model = with_training_defaults(MODEL_CLASSES[kind](**params), given=params)
    assert model.get_params(deep=False).get("fit_offset") is offset


def test_a_two_stage_models_first_stage_gets_the_default_unless_given_whole():
    model = with_training_defaults(MODEL_CLASSES["gmssvr"]())
    assert model.first_stage().fit_offset and not model.first_stage().asymmetric
    staged = with_training_defaults(MODEL_CLASSES["gmssvr"](gms=MODEL_CLASSES["gms"](n_elements=2)),
                                    given={"n_elements"})
    assert staged.first_stage().fit_offset and staged.first_stage().n_elements == 2
    whole = MODEL_CLASSES["gms"](n_elements=2)
    given = with_training_defaults(MODEL_CLASSES["gmssvr"](gms=whole), given={"gms"})
    assert not given.first_stage().fit_offset
    asymmetric = with_training_defaults(MODEL_CLASSES["gmssvr"](gms=MODEL_CLASSES["gms"](asymmetric=True)),
                                        given={"asymmetric"})
    assert not asymmetric.first_stage().fit_offset
