"""Friction fingerprints (greybox.monitor.fingerprint) of the ageing twin's air moves."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.errors import LogError, ParameterError
from greybox.monitor.fingerprint import (
    FEATURES,
    FrictionFingerprint,
    reversal_widths,
    spindle_idle_samples,
    unloaded_samples,
)
from greybox.twin.ageing import (
    DEFECT_CENTRE_OFFSET_MM,
    DEFECT_WIDTH_MM,
    AgedPlant,
    Drift,
    aged_log,
    air_move_trajectory,
)
from greybox.twin.axes import axis_geometry
from greybox.twin.datasets import make_dataset
from greybox.twin.plant import default_plant_parameters

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


def _reference_widths(x, v, f, level_pos, level_neg):
    """Reversal widths written out: each start against the previous direction, travel to half the new level."""
    widths, previous = [], 0.0
    for i in range(1, len(x)):
        s = np.sign(v[i])
        if s == 0.0:
            continue
        if previous != 0.0 and s != previous:
            half = 0.5 * (level_pos if s > 0 else level_neg)
            k = i
            while k < len(x) and np.sign(v[k]) == s and s * f[k] < half:
                k += 1
            if k < len(x) and np.sign(v[k]) == s:
                share = (half - s * f[k - 1]) / (s * f[k] - s * f[k - 1])
                widths.append(abs(x[k - 1] + min(max(share, 0.0), 1.0) * (x[k] - x[k - 1]) - x[i - 1]))
        previous = s
    return np.array(widths)


def test_reversal_widths_measure_a_known_play():
    # back and forth at 1 mm/s with rests; the friction flips to the new level 0.02 mm after each reversal
    t = np.arange(0.0, 12.0, 0.002)
    v = np.where(np.sin(2 * np.pi * t / 4) > 0.2, 1.0, np.where(np.sin(2 * np.pi * t / 4) < -0.2, -1.0, 0.0))
    x = np.concatenate([[0.0], np.cumsum(v[1:] * 0.002)])
    f = np.zeros_like(t)
    state, anchor = 0.0, 0.0
    for i in range(len(t)):
        if v[i] != 0.0 and np.sign(v[i]) != state and abs(x[i] - anchor) >= 0.02:
            state = np.sign(v[i])
        if v[i] == 0.0 or np.sign(v[i]) == state:
            anchor = x[i]
        f[i] = 1.0 * state
    widths = reversal_widths(x, v, f, 1.0, 1.0)
    np.testing.assert_allclose(widths, _reference_widths(x, v, f, 1.0, 1.0))
    assert len(widths) >= 4 and np.all(np.abs(widths - 0.02) <= 0.0021)  # within one sample of travel
    keep = np.ones(len(t), dtype=bool)
    keep[: len(t) // 2] = False
    assert 0 < len(reversal_widths(x, v, f, 1.0, 1.0, keep=keep)) < len(widths)


def test_backlash_and_local_defect_show_in_the_fingerprint():
    plain, play, defect = (FrictionFingerprint(n_boot=30).fit(prepare(aged_log("X", 4, 8, drifts)))
                           for drifts in ([], [Drift("backlash", 0, 0.004)], [Drift("defect", 0, 0.05)]))
    assert plain.n_reversals_ >= 5 and plain.values_["backlash"] < 0.005  # pre-sliding only: micrometres
    assert play.values_["backlash"] - plain.values_["backlash"] == pytest.approx(0.016, abs=0.003)  # 16 um play
    assert play.lower_["backlash"] <= play.values_["backlash"] <= play.upper_["backlash"]
    for name in ("sliding_pos", "sliding_neg", "local_excess"):  # the play leaves the sliding friction alone
        assert play.values_[name] == pytest.approx(plain.values_[name], abs=0.01)
    assert defect.values_["local_excess"] > plain.values_["local_excess"] + 0.03  # 20 % raised at its centre
    np.testing.assert_array_equal(defect.map_position_mm_, plain.map_position_mm_)
    rise = defect.map_excess_A_ - plain.map_excess_A_
    centre = axis_geometry("X").window_centre_mm + DEFECT_CENTRE_OFFSET_MM
    assert abs(defect.map_position_mm_[np.argmax(rise)] - centre) <= 2.5  # the map finds the stretch
    far = np.abs(defect.map_position_mm_ - centre) > DEFECT_WIDTH_MM / 2 + 2.5
    assert np.max(np.abs(rise[far])) < 0.5 * np.max(rise)


def test_periodic_amplitude_follows_the_screw_lead_component():
    base = default_plant_parameters("X")
    amplitudes = []
    for gain in (0.0, base.lead_gain, 2 * base.lead_gain):
        log = make_dataset("X", "H", 3, plant=AgedPlant(base.replace(lead_gain=gain)),
                           trajectory=air_move_trajectory("X"))
        amplitudes.append(FrictionFingerprint(n_boot=20).fit(prepare(log)).values_["periodic_amp"])
    level = base.coulomb_ratio * base.static_friction_A
    assert amplitudes[0] < 0.5 * base.lead_gain * level  # the noise floor of an amplitude
    assert amplitudes[1] < amplitudes[2] and amplitudes[2] - amplitudes[1] == pytest.approx(
        base.lead_gain * level, rel=0.4)


def test_spindle_idle_samples_pad_the_cuts():
    load = np.full(1000, 5.0)
    load[400:500] = 60.0
    idle = spindle_idle_samples(load, pad=10)
    assert not idle[390:510].any() and idle[:390].all() and idle[510:].all()
    assert spindle_idle_samples(load, threshold=70.0).all()  # a threshold above every value: no cut
    for bad in ([], [1.0, np.nan]):
        with pytest.raises(ParameterError, match="spindle load"):
            spindle_idle_samples(bad)
    with pytest.raises(ParameterError, match="pad"):
        spindle_idle_samples(load, pad=-1)


def test_production_day_fingerprint_by_its_spindle_load():
    from greybox.twin.ageing import SPINDLE_COLUMN
    from greybox.twin.cutting import CuttingSpec

    air = FrictionFingerprint(n_boot=20).fit(prepare(aged_log("X", 3, 4)))
    runs = prepare(aged_log("X", 3, 4, cutting=CuttingSpec()))
    idle = [spindle_idle_samples(run.extras[SPINDLE_COLUMN]) for run in runs]
    assert all(np.max(np.abs(run.extras["truth_process_A"][keep])) < 0.05 for run, keep in zip(runs, idle))
    assert all(np.count_nonzero(run.extras["truth_process_A"]) > 500 for run in runs)  # there was a cut
    by_spindle = FrictionFingerprint(n_boot=20).fit(runs, unloaded=idle)
    whole = FrictionFingerprint(n_boot=20).fit(runs)
    for name in ("noise", "local_excess"):  # the cut (negative strokes) biases a whole-log fit
        assert abs(by_spindle.values_[name] - air.values_[name]) < 0.5 * abs(whole.values_[name] - air.values_[name])
    # the idle negative strokes are only their ends: fewer speeds, the level trades off with the viscous part
    assert abs(by_spindle.values_["sliding_neg"] - air.values_["sliding_neg"]) < abs(
        whole.values_["sliding_neg"] - air.values_["sliding_neg"])
    assert by_spindle.values_["sliding_pos"] == pytest.approx(air.values_["sliding_pos"], abs=0.01)


def _reference_travel(x, excess, period_mm, bin_mm, min_count):
    """Plain reference of the travel features: every leave-three-bins-out trend refitted on the samples."""
    u = (2.0 * x - x.min() - x.max()) / (x.max() - x.min())
    design = np.column_stack([np.ones_like(x), u, np.sin(2 * np.pi * x / period_mm), np.cos(2 * np.pi * x / period_mm)])
    index = np.floor(x / bin_mm).astype(int)
    first = index.min()
    index -= first
    counts = np.bincount(index)
    full = np.flatnonzero(counts >= min_count)
    interior = full[(full - 2 >= full.min()) & (full + 2 <= full.max())]
    level = np.array([excess[index == j].mean() for j in full])
    coef = np.linalg.lstsq(design, excess, rcond=None)[0]
    trend = excess - design[:, 2:] @ coef[2:]
    local = {}
    for j in interior:
        out = np.abs(index - j) <= 1
        line = np.linalg.lstsq(design[~out, :2], trend[~out], rcond=None)[0]
        local[j] = np.mean(trend[index == j] - design[index == j, :2] @ line)
    worst = max(local, key=local.get)
    kept = np.abs(index - worst) > 1
    refit = np.linalg.lstsq(design[kept], excess[kept], rcond=None)[0]
    return np.hypot(refit[2], refit[3]), local[worst], (full + first + 0.5) * bin_mm, level


def _reference_features(x, v, a, y, fingerprint):
    """Plain reference of the features but the backlash: the sliding fit and the means on the samples."""
    from greybox.identify.static import fit_coulomb

    fast = np.abs(v) >= fingerprint.sliding_speed
    p = fit_coulomb(v[fast], a[fast], y[fast], asymmetric=True)
    viscous = np.where(v > 0.0, p["viscous_pos"], p["viscous_neg"])
    friction = y - p["J"] * a - viscous * v
    level = np.where(v > 0.0, p["coulomb_pos"], -p["coulomb_neg"])
    noise = np.sqrt(np.mean((friction - level)[fast] ** 2))
    slow = np.abs(v) < fingerprint.breakaway_speed
    sign = np.sign(v[fast])
    excess = sign * friction[fast] - np.where(sign > 0.0, p["coulomb_pos"], p["coulomb_neg"])
    periodic, local, centres, level_map = _reference_travel(x[fast], excess, fingerprint.period_mm,
                                                            fingerprint.map_bin_mm, fingerprint.map_min_samples)
    values = [p["coulomb_pos"], p["coulomb_neg"], friction[slow & (v > 0)].mean(), -friction[slow & (v < 0)].mean(),
              p["viscous_pos"], p["viscous_neg"], noise, np.nan, periodic, local]
    return np.array(values), centres, level_map


def test_block_sums_give_the_features_of_the_drawn_samples():
    """A bootstrap replicate from the blocks' sums equals the features refitted on the replicate's samples."""
    from greybox.monitor.fingerprint import _block_counts, _Statistics

    run = prepare(aged_log("X", 2, 9, [Drift("defect", 0, 0.05)]))[0]
    keep = run.velocity != 0.0
    x, v, a, y = run.position[keep], run.velocity[keep], run.acceleration[keep], run.effort[keep]
    fingerprint = FrictionFingerprint()
    settings = (fingerprint.sliding_speed, fingerprint.breakaway_speed, fingerprint.period_mm,
                fingerprint.map_bin_mm, fingerprint.map_min_samples)
    block = 100
    stats = _Statistics(x, v, a, y, block, *settings[:4])
    weights = np.vstack([np.ones(stats.n_blocks), _block_counts(stats.n_blocks, 2, np.random.default_rng(3))])
    for w in weights:
        rows = np.concatenate([np.arange(b * block, min((b + 1) * block, len(y)))
                               for b in range(stats.n_blocks) for _ in range(int(w[b]))])
        expected, centres, level = _reference_features(x[rows], v[rows], a[rows], y[rows], fingerprint)
        values, _, (got_centres, got_level) = stats.features(w, settings)
        np.testing.assert_allclose(values, expected, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(got_centres, centres)
        np.testing.assert_allclose(got_level, level, rtol=1e-7, atol=1e-9)
    assert not np.allclose(stats.features(weights[1], settings)[0][:7], stats.features(weights[0], settings)[0][:7])
