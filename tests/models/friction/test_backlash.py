"""A friction model behind a backlash: the gap kernel, the physics of the gap, identification of its width."""

from __future__ import annotations

import numpy as np
import pytest
from friction_reference import backlash_gap_reference
from friction_signals import STEP, motion_log, velocity_profile

from greybox.errors import ParameterError
from greybox.models.friction import CoulombModel, GMSModel
from greybox.models.friction.backlash import BacklashModel, BacklashState, gaps_of
from greybox.models.friction.gms import simulate_gms

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

TRUTH = {"alpha": np.array([0.3, 0.7]), "k": np.array([60.0, 20.0]), "sigma": 0.0, "s_0": 0.03, "s_inf": 0.025,
         "v_s": 5.0, "C": 2.0, "mu": 0.004}
WIDTH = 0.4  # mm


def gms_truth():
    """A GMS model carrying TRUTH, as if fitted on current logs."""
    model = GMSModel(n_elements=2)
    model.alpha_, model.k_, model.slip_rate_, model.sigma_ = TRUTH["alpha"], TRUTH["k"], TRUTH["C"], TRUTH["sigma"]
    model.s_0_, model.s_inf_, model.v_s_, model.viscous_ = TRUTH["s_0"], TRUTH["s_inf"], TRUTH["v_s"], TRUTH["mu"]
    model.J_, model.offset_, model.effort_unit_, model.sample_time_ = 0.001, 0.0, "A", STEP
    return model


def behind_backlash(width=WIDTH, threshold=0.05):
    model = BacklashModel(base=GMSModel(n_elements=2), width=width)
    model.base_, model.width_, model.threshold_ = gms_truth(), width, threshold
    model.J_, model.offset_, model.effort_unit_, model.sample_time_ = 0.001, 0.0, "A", STEP
    return model


def sine_log(amplitude_mm=3.0, period_s=2.0, cycles=3):
    t = np.arange(int(cycles * period_s / STEP)) * STEP
    w = 2 * np.pi / period_s
    log = motion_log(amplitude_mm * w * np.cos(w * t))
    return log


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gap_kernel_matches_the_python_reference(seed):
    rng = np.random.default_rng(seed)
    position = np.cumsum(rng.standard_normal(3000)) * 0.05
    force = np.sin(position) + 0.1 * rng.standard_normal(3000)
    state = BacklashState(np.nan, np.nan, 0, None)
    in_gap, low, high, loaded = gaps_of(position, force, 0.3, 0.2, state)
    ref_gap, ref_low, ref_high, ref_loaded = backlash_gap_reference(position, force, 0.3, 0.2, np.nan, np.nan, 0)
    np.testing.assert_array_equal(in_gap, ref_gap)
    np.testing.assert_equal((low, high, loaded), (ref_low, ref_high, ref_loaded))
    assert 0.01 < in_gap.mean() < 0.99 and np.any(np.diff(in_gap.astype(int)) != 0)


def test_no_force_passes_while_the_motor_crosses_the_gap():
    """After each reversal the friction falls to zero, is held there over WIDTH of motor travel, then reloads."""
    log = sine_log()
    model = behind_backlash()
    friction = model.friction(log)
    held = np.append(np.diff(friction) == 0.0, False)  # the base model stands still: its friction is frozen
    half = int(1.0 / STEP)  # half a period of the sine
    for start in range(half // 2, len(log) - half, half):  # each window holds one reversal
        window = slice(start, start + half)
        gap = np.flatnonzero(held[window])
        assert gap.size > 0
        assert np.ptp(log.position[window][gap]) == pytest.approx(WIDTH, abs=np.max(np.abs(log.velocity)) * STEP)
        assert np.max(np.abs(friction[window][gap])) < 0.05  # the force had just crossed zero
    sliding = (np.abs(log.velocity) > 0.8 * np.max(np.abs(log.velocity))) & (log.time > 1.0)  # far from reversals
    np.testing.assert_allclose(friction[sliding], gms_truth().friction(log)[sliding], atol=0.02)
    assert np.max(np.abs(model.predict(log) - gms_truth().predict(log))) > 0.5


def test_zero_width_is_the_base_model():
    log = motion_log(velocity_profile(6.0, seed=3))
    np.testing.assert_array_equal(behind_backlash(width=0.0).predict(log), gms_truth().predict(log))


def test_chunks_carry_the_gap_and_the_base_state():
    log = motion_log(velocity_profile(8.0, seed=4))
    model = behind_backlash()
    whole = model.predict(log)
    state, parts = None, []
    for start in range(0, len(log), 317):
        part, state = model.predict_chunk(log.select(slice(start, min(start + 317, len(log)))), state,
                                          sample_time=STEP)
        parts.append(part)
    np.testing.assert_allclose(np.concatenate(parts), whole, rtol=0, atol=1e-12)


def test_identification_finds_the_width():
    t = np.arange(int(12.0 / STEP)) * STEP
    velocity = 2.0 * np.pi * (3.0 * np.cos(2.0 * np.pi * t) + 1.5 * np.cos(2.0 * np.pi * 2.3 * t))  # two sines [mm/s]
    log = motion_log(velocity)
    truth = behind_backlash()
    noise = 0.003 * np.random.default_rng(5).standard_normal(len(log))
    log = log.replace(effort=truth.predict(log) + noise)
    model = BacklashModel(base=GMSModel(n_elements=2, n_starts=2)).fit(log)
    assert model.width_ == pytest.approx(WIDTH, rel=0.1)
    rmse = np.sqrt(np.mean((model.predict(log) - log.effort) ** 2))
    plain = GMSModel(n_elements=2, n_starts=2).fit(log)
    assert rmse < 0.5 * np.sqrt(np.mean((plain.predict(log) - log.effort) ** 2))
    assert model.n_params == plain.n_params + 1


def test_without_backlash_in_the_data_the_width_is_small():
    velocity = velocity_profile(20.0, seed=6)
    log = motion_log(velocity)
    friction, _ = simulate_gms(velocity, STEP, **TRUTH)
    log = log.replace(effort=0.001 * log.acceleration + friction)
    model = BacklashModel(base=CoulombModel(fit_offset=True)).fit(log)
    assert model.width_ < 0.1


@pytest.mark.parametrize("width", [-1.0, float("nan"), True, "wide"])
def test_bad_width_is_refused(width):
    log = sine_log()
    with pytest.raises(ParameterError, match="width must be"):
        BacklashModel(width=width).fit(log.replace(effort=np.sign(log.velocity)))


def test_on_oversampled_runs_the_width_is_searched_on_block_means_and_found():
    # slow motion (0.2 Hz sines at 500 Hz) and the truth's deflections ten times wider: a sample spans far less
    # than a tenth of the pre-sliding deflection, so the width search runs on block means
    t = np.arange(int(20.0 / STEP)) * STEP
    velocity = 2.0 * np.pi * 0.2 * (3.0 * np.cos(2.0 * np.pi * 0.2 * t) + 1.5 * np.cos(2.0 * np.pi * 0.46 * t))
    log = motion_log(velocity)
    truth = behind_backlash()
    truth.base_.s_0_, truth.base_.s_inf_ = 10.0 * TRUTH["s_0"], 10.0 * TRUTH["s_inf"]
    log = log.replace(effort=truth.predict(log) + 0.003 * np.random.default_rng(5).standard_normal(len(log)))
    full = BacklashModel(base=GMSModel(n_elements=2, n_starts=2)).fit(log)
    held_out = full.held_out_search().fit(log)
    assert full.block_ > 1 and held_out.block_ == full.block_
    for model in (full, held_out):
        assert model.width_ == pytest.approx(WIDTH, rel=0.1)
        rmse = np.sqrt(np.mean((model.predict(log) - log.effort) ** 2))
        assert rmse < 0.1 * np.std(log.effort)
    # the full fit refits its base on the runs themselves; the held-out search keeps the block means' fit
    assert full.base_.sample_time_ == pytest.approx(STEP)
    assert held_out.base_.sample_time_ == pytest.approx(full.block_ * STEP)
