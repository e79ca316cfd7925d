"""The in-memory axis log type."""

import numpy as np
import pytest

from greybox.data.log import AxisLog, as_log_list, split_runs
from greybox.errors import LogError


def make_log(n=5, **kw):
    t = np.arange(n) * 0.002
    return AxisLog(time=t, position=np.linspace(0, 1, n), effort=np.ones(n), **kw)


def test_channels_are_float_arrays_and_step_is_median():
    log = AxisLog(time=[0, 0.002, 0.004, 0.0061], position=[0, 1, 2, 3], effort=[1, 2, 3, 4])
    assert log.time.dtype == np.float64 and log.position.flags.c_contiguous
    assert log.sample_time == pytest.approx(0.002)
    assert log.duration == pytest.approx(0.0061)
    assert len(log) == 4 and not log.is_prepared


def test_channel_of_wrong_length_names_the_source_and_channel():
    with pytest.raises(LogError, match=r"run\.csv: channel 'velocity' has 3 samples, expected 5"):
        make_log(velocity=np.zeros(3), source="run.csv")
    with pytest.raises(LogError, match="extra channel|'truth_A'"):
        make_log(extras={"truth_A": np.zeros(2)})


def test_unknown_effort_unit_is_rejected():
    with pytest.raises(LogError, match="effort unit 'V' does not fit a linear axis"):
        make_log(effort_unit="V")
    with pytest.raises(LogError, match="effort unit 'Nm' does not fit a linear axis"):
        make_log(effort_unit="Nm")
    with pytest.raises(LogError, match="effort unit 'N' does not fit a rotary axis"):
        make_log(effort_unit="N", motion="rotary")
    with pytest.raises(LogError, match="unknown motion 'angular'"):
        make_log(motion="angular")


def test_current_requires_ampere_effort():
    assert np.array_equal(make_log().current, np.ones(5))
    with pytest.raises(LogError, match="effort in N"):
        _ = make_log(effort_unit="N").current


def test_select_keeps_every_channel_aligned():
    log = make_log(n=10, velocity=np.arange(10.0), acceleration=-np.arange(10.0), extras={"x_A": np.arange(10.0) * 2})
    part = log.select(slice(2, 6))
    assert np.array_equal(part.velocity, [2, 3, 4, 5])
    assert np.array_equal(part.acceleration, [-2, -3, -4, -5])
    assert np.array_equal(part.extras["x_A"], [4, 6, 8, 10])
    assert np.array_equal(part.time, log.time[2:6]) and part.is_prepared


def test_to_frame_uses_canonical_names_and_effort_unit():
    frame = make_log(effort_unit="N", velocity=np.zeros(5)).to_frame()
    assert list(frame.columns) == ["time_s", "position_mm", "velocity_mm_s", "force_N"]


def test_as_log_list_accepts_one_log_or_many():
    log = make_log()
    assert as_log_list(log) == [log]
    assert as_log_list((log, log)) == [log, log]
    with pytest.raises(ValueError):
        as_log_list([])
    with pytest.raises(TypeError):
        as_log_list([log, "file.csv"])


def test_split_runs():
    runs = [make_log(10), make_log(5)]
    parts = split_runs(runs, np.arange(15.0))
    assert [p.tolist() for p in parts] == [list(range(10)), list(range(10, 15))]
    with pytest.raises(ValueError):
        split_runs(runs, np.arange(14.0))
    with pytest.raises(ValueError):
        split_runs(runs, [np.zeros(10), np.zeros(4)])
