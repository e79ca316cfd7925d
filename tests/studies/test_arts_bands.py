"""The ARTS benchmark's split of a model's error into the band of the motion and the ripple above it.

Checked on signals whose parts are known: a slow force plus a 50 Hz ripple of
given amplitude, a model that gets the slow part right or scaled, and two
files whose levels differ (each file is filtered on its own).
"""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from studies.arts import MOTION_BAND_HZ, band_split

RATE = 1024.0


def _log(force):
    n = force.size
    time = np.arange(n) / RATE
    return AxisLog(time=time, position=np.zeros(n), velocity=np.zeros(n), acceleration=np.zeros(n), effort=force,
                   effort_unit="N")


def _slow_and_ripple(seconds=8.0, ripple=1.0):
    time = np.arange(int(seconds * RATE)) / RATE
    slow = 10.0 * np.sin(2 * np.pi * 0.5 * time) + 4.0 * np.sin(2 * np.pi * 1.5 * time)
    return slow, slow + ripple * np.sin(2 * np.pi * 50.0 * time)


def test_a_model_of_the_slow_part_has_no_error_in_the_band_and_the_floor_is_the_ripple():
    slow, force = _slow_and_ripple(ripple=1.0)
    split = band_split([_log(force)], [slow])
    mean_abs = np.mean(np.abs(force))
    assert split["band_hz"] == MOTION_BAND_HZ
    assert split["re_band"] < 0.01 * split["floor"]
    assert split["floor"] == pytest.approx(100 * (1 / np.sqrt(2)) / mean_abs, rel=0.01)
    assert split["re_above"] == pytest.approx(split["floor"], rel=0.01)  # the model adds nothing above the band


def test_an_error_in_the_band_is_measured_there_and_adds_in_quadrature_to_the_ripple():
    slow, force = _slow_and_ripple(ripple=2.0)
    split = band_split([_log(force)], [0.9 * slow])
    scale = 100 / np.mean(np.abs(force))
    assert split["re_band"] == pytest.approx(scale * np.sqrt(np.mean((0.1 * slow) ** 2)), rel=0.01)
    total = scale * np.sqrt(np.mean((force - 0.9 * slow) ** 2))
    assert np.hypot(split["re_band"], split["re_above"]) == pytest.approx(total, rel=0.01)


def test_each_file_is_filtered_on_its_own():
    # two files at different constant levels: filtered across the joint, the step would show above the band
    first, second = np.full(4096, 10.0), np.full(4096, -10.0)
    split = band_split([_log(first), _log(second)], [first, second])
    assert split["floor"] < 1e-9 and split["re_band"] < 1e-9 and split["re_above"] < 1e-9
    joined = band_split([_log(np.concatenate([first, second]))], [np.concatenate([first, second])])
    assert joined["floor"] > 1.0  # the step itself, when the two are one file
