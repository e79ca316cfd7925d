"""Friction fingerprints (greybox.monitor.fingerprint) of the ageing twin's air moves."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.errors import LogError, ParameterError
from greybox.monitor.fingerprint import FEATURES, FrictionFingerprint, unloaded_samples
from greybox.twin.ageing import Drift, aged_log

LEVELS = ("sliding_pos", "sliding_neg", "breakaway_pos", "breakaway_neg")


@pytest.fixture(scope="module")
def day_logs():
    """The same day of the twin, as it is and with its friction levels raised by 20 %."""
    return aged_log("X", 1, 5), aged_log("X", 1, 5, [Drift("lubrication", 0, 0.2)])


def test_fingerprint_scales_with_the_friction_level(day_logs):
    plain, raised = (FrictionFingerprint(n_boot=50).fit(prepare(log)) for log in day_logs)
    for name in LEVELS:  # the same noise and motion: the levels follow the plant's factor 1.2
        assert raised.values_[name] / plain.values_[name] == pytest.approx(1.2, abs=0.03), name
    for name in ("viscous_pos", "viscous_neg"):
        assert raised.values_[name] == pytest.approx(plain.values_[name], abs=0.003)
    for name in FEATURES:
        assert plain.lower_[name] <= plain.values_[name] <= plain.upper_[name], name
        assert plain.lower_[name] < plain.upper_[name], name


def test_fingerprint_levels_near_the_twin_truth(day_logs):
    log = day_logs[0]
    fitted = FrictionFingerprint(n_boot=50).fit(prepare(log))
    truth = log.attrs["plant"]
    sliding = truth["coulomb_ratio"] * sum(truth["breakaway_A"])  # before the position factor (+- 10 % here)
    for name in ("sliding_pos", "sliding_neg"):
        assert fitted.values_[name] == pytest.approx(sliding, rel=0.12)
    for name in ("breakaway_pos", "breakaway_neg"):  # the Stribeck rise: above the sliding level
        assert fitted.values_[name] > fitted.values_[name.replace("breakaway", "sliding")]
    assert fitted.values_["noise"] == pytest.approx(log.attrs["noise"]["std_A"], rel=0.5)


def test_same_log_same_fingerprint(day_logs):
    runs = prepare(day_logs[0])
    first, second = FrictionFingerprint(n_boot=20).fit(runs), FrictionFingerprint(n_boot=20).fit(runs)
    assert first.values_ == second.values_ and first.lower_ == second.lower_ and first.upper_ == second.upper_


def test_unloaded_samples_mask_a_process_load(day_logs):
    log = day_logs[0]
    run = prepare(log)[0]
    rng = np.random.default_rng(0)
    first = int(np.flatnonzero(np.abs(run.velocity) >= 15.0)[0])  # the fast moves, which set the sliding levels
    cut = slice(first, first + 1500)
    load = np.zeros(len(run))
    load[cut] = 0.8  # a process force pushing one way for 3 s
    loaded = run.replace(effort=run.effort + load)
    residual = load + rng.normal(0.0, 0.1, len(run))  # what a reference model would leave
    mask = unloaded_samples(residual)
    assert not mask[first + 50:first + 1450].any()
    assert mask[:first - 50].mean() > 0.95 and mask[first + 1550:].mean() > 0.95
    clean = FrictionFingerprint(n_boot=20).fit([run])
    blind = FrictionFingerprint(n_boot=20).fit([loaded])
    masked = FrictionFingerprint(n_boot=20).fit([loaded], unloaded=[mask])
    for name in ("sliding_pos", "sliding_neg"):
        assert abs(masked.values_[name] - clean.values_[name]) < 0.5 * abs(blind.values_[name] - clean.values_[name])


def test_one_direction_is_refused():
    n = 2000
    time = np.arange(n) * 0.002
    velocity = np.where(time < 3.5, 20.0, 1.0)
    run = AxisLog(time=time, position=np.cumsum(velocity) * 0.002, effort=np.ones(n), velocity=velocity,
                  acceleration=np.zeros(n), source="one_way.csv")
    with pytest.raises(LogError, match=r"one_way.csv: 0 unloaded samples of negative motion"):
        FrictionFingerprint(n_boot=10).fit(run)


def test_unprepared_log_and_bad_settings_are_refused(day_logs):
    with pytest.raises(LogError, match="not prepared"):
        FrictionFingerprint().fit(day_logs[0].replace(velocity=None))
    with pytest.raises(ParameterError, match="breakaway_speed < sliding_speed"):
        FrictionFingerprint(breakaway_speed=20.0).fit(prepare(day_logs[0]))
    with pytest.raises(ParameterError, match="n_boot"):
        FrictionFingerprint(n_boot=3).fit(prepare(day_logs[0]))
