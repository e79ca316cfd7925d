"""Time-base and finiteness checks."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.validate import check_finite, check_time
from greybox.errors import LogError


def _problem(time, **options):
    with pytest.raises(LogError) as error:
        check_time(np.asarray(time, dtype=float), source="trace.csv", **options)
    message = str(error.value)
    assert message.startswith("trace.csv: ")
    return message


def test_nominal_step_is_the_median_step():
    time = np.arange(1000) * 0.002 + np.random.default_rng(0).uniform(-1e-4, 1e-4, 1000)
    assert check_time(time) == pytest.approx(np.median(np.diff(time)))


@pytest.mark.parametrize("time", [[], [0.0]])
def test_too_few_samples(time):
    assert "at least 2" in _problem(time)


def test_non_finite_time():
    assert "time holds nan at sample 2" in _problem([0, 1, np.nan, 3])


def test_backwards():
    message = _problem([0.0, 0.002, 0.004, 0.003, 0.006])
    assert "time goes backwards at sample 3: t = 0.003 s after 0.004 s" in message


def test_repeated():
    assert "time repeats at sample 2: t = 0.002 s twice" in _problem([0.0, 0.002, 0.002, 0.004])


def test_gap():
    time = np.r_[np.arange(10) * 0.002, 0.018 + 0.040 + np.arange(10) * 0.002]
    assert "gap of 40 ms at t = 0.018 s" in _problem(time)


def test_gap_within_a_wider_tolerance_passes():
    time = np.r_[np.arange(10) * 0.002, 0.018 + 0.0029 + np.arange(10) * 0.002]
    assert "gap" in _problem(time)
    assert check_time(time, tolerance=0.5) == pytest.approx(0.002)


def test_first_offence_is_reported_jitter_or_gap():
    time = np.arange(20) * 0.002
    time[7] -= 0.0008  # steps of 1.2 ms then 2.8 ms
    assert "jitter: step of 1.2 ms at t = 0.012 s" in _problem(time)
    time[7] += 0.0016  # steps of 2.8 ms then 1.2 ms
    assert "gap of 2.8 ms at t = 0.012 s" in _problem(time)
    assert check_time(time, tolerance=0.45) == pytest.approx(0.002)


def test_check_finite_names_channel_and_time(make_log):
    log = make_log(n=100)
    extra = np.zeros(100)
    extra[42] = np.inf
    with pytest.raises(LogError, match=r"channel 'motor_temperature_C' holds inf at t = 0.084 s \(sample 42"):
        check_finite(log.replace(extras={"motor_temperature_C": extra}, source="run.csv"))
    check_finite(log)
