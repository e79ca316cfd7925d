"""Trajectories of the synthetic datasets: windows, travels, speed and acceleration bounds, smoothness."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin.axes import AXES, axis_geometry
from greybox.twin.motion import MotionLimits, MotionProfile, _Sine
from greybox.twin.presliding import PreslidingExcitation, rectangular_envelope
from greybox.twin.trajectories import dataset_trajectory, random_window_trajectory

MM_MIN = 1.0 / 60.0
STEP = 2.5e-4


def sampled(trajectory, step=STEP):
    t = np.arange(int(trajectory.duration_s / step) + 1) * step
    return (t, *trajectory.motion.evaluate(t))


@pytest.mark.parametrize("axis", ["X", "Y"])
@pytest.mark.parametrize("dataset", ["A", "C"])
def test_random_datasets_stay_in_the_window_and_speed_range(axis, dataset):
    geometry = axis_geometry(axis)
    trajectory = dataset_trajectory(geometry, dataset, np.random.default_rng(11), duration_s=40.0)
    t, x, v, a = sampled(trajectory)
    low, high = geometry.window_mm
    assert low <= x.min() and x.max() <= high
    assert np.abs(v).max() <= 2000.0 * MM_MIN * (1 + 1e-4)
    speeds = trajectory.motion.cruise_speeds_mm_s()
    assert speeds.size > 5
    assert np.all(speeds >= 100.0 * MM_MIN * (1 - 1e-9)) and np.all(speeds <= 2000.0 * MM_MIN * (1 + 1e-4))
    assert trajectory.description["oscillations"] >= 1
    # sine oscillations peak between 300 mm/min (recalibrated lower bound) and 2000 mm/min
    peaks = np.array([p.amplitude_mm * p.peak_speed_per_mm() for p in trajectory.motion._pieces
                      if isinstance(p, _Sine)])
    assert peaks.size == trajectory.description["oscillations"]
    assert np.all(peaks >= 300.0 * MM_MIN * (1 - 1e-9)) and np.all(peaks <= 2000.0 * MM_MIN * (1 + 1e-4))
    # reversals; after the initial 0.5 s at rest the axis keeps moving except for rare short dwells
    moving = np.abs(v) > 1e-9
    assert np.count_nonzero(np.diff(np.sign(v[moving])) != 0) >= 4
    starts, ends = standstills(~moving)
    assert starts[0] == 0 and (ends[0] - 1) * STEP == pytest.approx(0.5, abs=STEP)
    dwell_s = (ends[1:] - starts[1:]) * STEP
    assert np.all(dwell_s <= trajectory.description["dwell_s"][1] + STEP)
    assert dwell_s.sum() < 0.01 * trajectory.duration_s
    # starts and ends at rest (the last sample of the grid may lie a little before the end of the motion)
    end = trajectory.motion.evaluate(np.array([trajectory.duration_s]))
    assert v[0] == 0.0 and end[1][0] == 0.0 and end[2][0] == pytest.approx(0.0, abs=1e-6)
    assert 35.0 <= trajectory.duration_s <= 80.0


def standstills(at_rest):
    """Start and end (exclusive) indices of the runs of samples at rest."""
    edges = np.diff(np.concatenate(([0], at_rest.astype(int), [0])))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


@pytest.mark.parametrize("dwell_probability", [0.0, 1.0])
def test_random_dataset_dwells_have_the_configured_length(dwell_probability):
    geometry = axis_geometry("X")
    trajectory = random_window_trajectory(geometry, np.random.default_rng(4), duration_s=40.0,
                                          dwell_probability=dwell_probability, dwell_s=(0.02, 0.1))
    t, x, v, a = sampled(trajectory)
    starts, ends = standstills(np.abs(v) <= 1e-9)
    assert (ends[-1] - starts[-1]) * STEP >= 0.1 - STEP  # the final rest
    dwell_s = (ends[1:-1] - starts[1:-1]) * STEP  # between the initial and the final rest
    if dwell_probability == 0.0:
        assert dwell_s.size == 0  # reversals pass through zero speed without stopping
    else:  # after every move and every oscillation
        assert dwell_s.size >= trajectory.description["moves"] + trajectory.description["oscillations"] - 1
        assert np.all(dwell_s >= 0.02 - STEP) and np.all(dwell_s <= 0.1 + STEP)


@pytest.mark.parametrize("axis", ["X", "Y"])
@pytest.mark.parametrize("dataset, speeds", [("B", [600.0, 1800.0]), ("D", [1200.0])])
def test_constant_speed_datasets_cross_the_travel(axis, dataset, speeds):
    geometry = AXES[axis]
    trajectory = dataset_trajectory(geometry, dataset, np.random.default_rng(0))
    t, x, v, a = sampled(trajectory, step=1e-3)
    low, high = geometry.travel_mm
    assert x.min() == pytest.approx(low, abs=1e-9) and x.max() == pytest.approx(high, abs=1e-9)
    assert x[0] == high and x[-1] == pytest.approx(high, abs=1e-9)
    plateaus = np.unique(np.round(np.abs(v[np.abs(a) == 0.0]) / MM_MIN, 6))
    np.testing.assert_allclose(plateaus[plateaus > 0], speeds)
    # once back and forth per speed: two reversals per speed
    moving = np.abs(v) > 0
    assert np.count_nonzero(np.diff(np.sign(v[moving])) != 0) == 2 * len(speeds) - 1


@pytest.mark.parametrize("dataset", ["A", "B"])
def test_motion_is_consistent_and_jerk_limited(dataset):
    limits = MotionLimits()
    trajectory = dataset_trajectory(AXES["X"], dataset, np.random.default_rng(5), duration_s=30.0)
    t, x, v, a = sampled(trajectory, step=1e-4)
    # velocity is the derivative of position, acceleration of velocity (central differences)
    np.testing.assert_allclose((x[2:] - x[:-2]) / 2e-4, v[1:-1], atol=2e-3)
    np.testing.assert_allclose((v[2:] - v[:-2]) / 2e-4, a[1:-1], atol=limits.max_jerk_mm_s3 * 1e-4)
    assert np.abs(a).max() <= limits.max_acceleration_mm_s2 * (1 + 1e-9)
    jerk = np.diff(a) / 1e-4
    assert np.abs(jerk).max() <= limits.max_jerk_mm_s3 * 1.01
    assert np.abs(a).max() > 300.0  # machine-tool-like accelerations are reached


def test_move_reaches_its_target_exactly():
    profile = MotionProfile(-250.0)
    profile.move(-12.5, [5.0, 30.0, 2.0], [1.0, 2.0, 1.0])
    profile.hold(0.2)
    profile.move(7.25, [20.0])
    assert profile.position_mm == pytest.approx(-255.25, abs=1e-12)
    x, v, a = profile.evaluate(np.array([profile.duration_s, profile.duration_s + 1.0]))
    np.testing.assert_allclose(x, -255.25, atol=1e-12)
    np.testing.assert_allclose(v, 0.0, atol=1e-12)
    with pytest.raises(ValueError, match="shorter than its ramps"):
        profile.move(0.001, [30.0])


def test_oscillation_has_the_requested_peak_speed_and_returns():
    profile = MotionProfile(-250.0)
    amplitude = profile.oscillate(10.0, 2 * np.pi * 0.5, periods=4)
    t = np.linspace(0.0, profile.duration_s, 200001)
    x, v, a = profile.evaluate(t)
    assert np.abs(v).max() == pytest.approx(10.0, rel=1e-4)
    assert np.abs(x + 250.0).max() <= amplitude + 1e-12
    assert x[-1] == pytest.approx(-250.0, abs=1e-12) and v[-1] == pytest.approx(0.0, abs=1e-12)
    assert a[0] == pytest.approx(0.0, abs=1e-9) and a[-1] == pytest.approx(0.0, abs=1e-9)


def test_presliding_excitation_shape():
    rng = np.random.default_rng(2)
    excitation = PreslidingExcitation.random(rng, -250.0, duration_s=40.0)
    t = np.arange(int(excitation.duration_s / 1e-3) + 1) * 1e-3
    x, v, a = excitation.evaluate(t)
    assert excitation.duration_s == pytest.approx(40.0)
    assert v[0] == pytest.approx(0.0, abs=1e-12) and abs(v[-1]) < 1e-9
    # enveloped: small velocity where the rectangular envelope changes sign (every 5 s)
    envelope = np.abs(rectangular_envelope(t))
    quiet, loud = envelope < 0.2, envelope > 0.9
    assert np.sqrt(np.mean(v[quiet] ** 2)) < 0.3 * np.sqrt(np.mean(v[loud] ** 2))
    # band-limited to 4 Hz (envelope up to 0.5 Hz widens the band a little)
    power = np.abs(np.fft.rfft(v)) ** 2
    f = np.fft.rfftfreq(v.size, 1e-3)
    assert power[f > 8.0].sum() < 1e-3 * power.sum()
    # many reversals, mostly within the pre-sliding range (< 50 um) of the plant, some sliding strokes
    reversals = np.flatnonzero(np.diff(np.sign(v[1:-1])) != 0)
    strokes = np.abs(np.diff(x[1:-1][reversals]))
    assert reversals.size > 100 and np.median(strokes) < 0.05 < strokes.max()
    # position derivative consistency
    np.testing.assert_allclose(np.gradient(x, 1e-3)[1:-1], v[1:-1], atol=1e-3)


def test_presliding_dataset_stays_in_the_window():
    geometry = AXES["Y"]
    trajectory = dataset_trajectory(geometry, "P", np.random.default_rng(0), duration_s=20.0)
    t, x, v, a = sampled(trajectory, step=1e-3)
    assert geometry.window_mm[0] < x.min() and x.max() < geometry.window_mm[1]
    assert np.abs(v).max() < 100.0 * MM_MIN * 2


def test_unknown_dataset_and_axis():
    with pytest.raises(GreyboxError, match="unknown dataset 'Q'"):
        dataset_trajectory(AXES["X"], "Q", np.random.default_rng(0))
    with pytest.raises(GreyboxError, match="unknown axis 'Z'"):
        axis_geometry("Z")
    with pytest.raises(GreyboxError, match="positive"):
        dataset_trajectory(AXES["X"], "A", np.random.default_rng(0), duration_s=-1.0)
