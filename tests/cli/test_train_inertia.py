"""``greybox train --axis-config``: an identified inertia that disagrees with the axis file is noted, and
``--model auto`` fits with the axis file's inertia."""

from __future__ import annotations

import math

import numpy as np
import pytest
from friction_signals import motion_log, velocity_profile

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.identify.inertia import AXIS_INERTIA_FACTOR
from greybox.models.files import load_model

#: Inertia of the runs [A s^2/mm] and the axis: k_t = 1.35 Nm/A, a 10 mm screw coupled directly.
J_TRUE = 0.002
AXIS = 'torque_constant_Nm_per_A = 1.35\nscrew_lead_mm = 10.0\nefficiency = 0.9\n'


def _motor_inertia(j_model: float) -> float:
    """J_m [kg m^2] whose reflection is ``j_model`` [A s^2/mm] on the axis of :data:`AXIS`."""
    return j_model * 10.0 * 1.35 / (2 * math.pi)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("axis_inertia")
    paths = []
    for seed in range(2):
        velocity = velocity_profile(5.0, seed=seed, v_max=60.0)
        log = motion_log(velocity)
        noise = 0.01 * np.random.default_rng(seed).standard_normal(len(velocity))
        log = log.replace(effort=J_TRUE * log.acceleration + 0.9 * np.sign(velocity) + 0.01 * velocity + noise,
                          velocity=None, acceleration=None)
        paths.append(folder / f"run{seed}.csv")
        write_log(log, paths[-1])
    return paths


def _axis_file(folder, factor: float | None):
    path = folder / f"axis_{factor}.toml"
    path.write_text(AXIS + ("" if factor is None else f"inertia_kg_m2 = {_motor_inertia(factor * J_TRUE)!r}\n"))
    return path


def _main(capsys, *args):
    status = cli.main([str(arg) for arg in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize("factor, flagged", [(1.2, False), (1 / 1.2, False), (3 * AXIS_INERTIA_FACTOR, True),
                                             (1 / (3 * AXIS_INERTIA_FACTOR), True)])
def test_an_identified_inertia_far_from_the_axis_files_is_noted(logs, tmp_path, capsys, factor, flagged):
    out = tmp_path / "m.gbm"
    status, stdout, _ = _main(capsys, "train", "--model", "coulomb", "--train", *logs, "--out", out, "--quiet",
                              "--intervals", "none", "--axis-config", _axis_file(tmp_path, factor))
    assert status == 0
    model = load_model(out)
    assert model.J_ == pytest.approx(J_TRUE, rel=0.05)  # identified from the runs, not taken from the file
    notes = [note for note in model.fit_notes() if "axis file" in note]
    assert bool(notes) == flagged
    assert ("times the" in stdout and "axis_" in stdout) == flagged


def test_auto_fits_every_candidate_with_the_axis_files_inertia(logs, tmp_path, capsys):
    out = tmp_path / "auto.gbm"
    axis = _axis_file(tmp_path, 1.5)
    status, stdout, _ = _main(capsys, "train", "--model", "auto", "--candidates", "coulomb:offset", "stribeck:offset",
                              "--train", *logs, "--out", out, "--quiet", "--intervals", "none", "--workers", "1",
                              "--axis-config", axis)
    assert status == 0
    assert load_model(out).J_ == pytest.approx(1.5 * J_TRUE, rel=1e-9)
    assert f"from the axis file {axis.name}: every candidate is fitted with it" in stdout
    status, _, _ = _main(capsys, "train", "--model", "auto", "--candidates", "coulomb:offset", "--train", *logs,
                         "--out", out, "--force", "--quiet", "--intervals", "none", "--workers", "1",
                         "--axis-config", axis, "--load-side")
    assert status == 0 and load_model(out).J_ == 0.0  # the option says more than the file


def test_an_axis_file_without_inertia_is_refused_before_the_fit(logs, tmp_path, capsys):
    status, _, stderr = _main(capsys, "train", "--model", "coulomb", "--train", *logs, "--out", tmp_path / "m.gbm",
                              "--quiet", "--axis-config", _axis_file(tmp_path, None))
    assert status == 2
    assert "gives no inertia_kg_m2" in stderr and len(stderr.strip().splitlines()) == 1
    assert not (tmp_path / "m.gbm").exists()


def test_a_machine_files_axis_inertia_checks_that_axis_model(tmp_path, capsys):
    from greybox.models.machine import load_machine

    velocity = velocity_profile(5.0, seed=4, v_max=60.0)
    log = motion_log(velocity)
    log = log.replace(effort=J_TRUE * log.acceleration + 0.9 * np.sign(velocity) + 0.01 * velocity,
                      velocity=None, acceleration=None)
    path = tmp_path / "machine.csv"
    write_log([log.replace(axis="X"), log.replace(axis="Y")], path)
    machine = tmp_path / "machine.toml"
    machine.write_text("".join(f"[axes.{name}]\n{AXIS}inertia_kg_m2 = {_motor_inertia(factor * J_TRUE)!r}\n\n"
                               for name, factor in (("X", 1.1), ("Y", 3 * AXIS_INERTIA_FACTOR))))
    out = tmp_path / "machine_model"
    status, stdout, _ = _main(capsys, "train", "--model", "coulomb", "--train", path, "--machine", machine,
                              "--out", out, "--quiet", "--intervals", "none")
    assert status == 0
    models = load_machine(out).models
    assert not [note for note in models["X"].fit_notes() if "machine file" in note]
    assert [note for note in models["Y"].fit_notes() if "axis Y of the machine file" in note]
