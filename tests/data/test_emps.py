"""The EMPS benchmark reader: units, effort = gtau * vir, bad files."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import loadmat, savemat

from greybox.data.io import read_log
from greybox.errors import LogError


@pytest.fixture
def emps(real_data):
    """The folder of the EMPS benchmark files (skips without it)."""
    return real_data("EMPS")


@pytest.mark.parametrize("name", ["DATA_EMPS", "DATA_EMPS_PULSES"])
def test_emps_units(emps, name):
    path = emps / f"{name}.mat"
    log = read_log(path)
    raw = loadmat(path)
    assert log.effort_unit == "N" and log.dataset == name
    assert len(log) == 24841 and log.sample_time == pytest.approx(1e-3, rel=1e-4)
    assert -0.03 < log.position.min() < 0.0 and 246.0 < log.position.max() < 247.0  # qm: -2.2e-5 ... 0.2464 m
    gtau = float(raw["gtau"][0, 0])
    assert gtau == pytest.approx(35.15, abs=0.01)  # the data set's motor-force gain, 35.15 N/V
    np.testing.assert_array_equal(log.effort, gtau * raw["vir"].ravel())
    np.testing.assert_array_equal(log.position, 1e3 * raw["qm"].ravel())
    np.testing.assert_array_equal(log.extras["reference_position_mm"], 1e3 * raw["qg"].ravel())
    assert log.attrs == {"gtau": gtau, "kp": pytest.approx(160.18), "kv": pytest.approx(243.45)}
    assert ("pulses_N" in log.extras) == (name == "DATA_EMPS_PULSES")


def test_pulses_are_a_zero_five_square_wave(emps):
    pulses = read_log(emps / "DATA_EMPS_PULSES.mat").extras["pulses_N"]
    assert set(np.unique(pulses)) == {0.0, 5.0}
    assert np.count_nonzero(pulses == 5.0) == 12497  # README


def test_missing_variable(tmp_path):
    path = tmp_path / "partial.mat"
    savemat(path, {"t": np.arange(10) * 1e-3, "qm": np.zeros(10), "gtau": 35.0})
    with pytest.raises(LogError) as error:
        read_log(path)
    assert str(path) in str(error.value) and "missing EMPS variable(s) vir" in str(error.value)


@pytest.mark.parametrize("content", [b"short", b"this is not MATLAB " * 40, bytes(range(256)) * 4])
def test_not_a_mat_file(tmp_path, content):
    path = tmp_path / "text.mat"
    path.write_bytes(content)
    with pytest.raises(LogError, match="not a readable MATLAB") as error:
        read_log(path)
    assert str(path) in str(error.value)
