"""Null-calibrated evidence for candidate effects, and telling effects apart."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.discover.evidence import score_step
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import EffectContext
from greybox.models.friction import CoulombModel


def sine_stroke(n=6000, step=0.002, seed=0):
    """A stroke whose velocity never vanishes at a sample (no rest), effort of a Coulomb axis plus AR(1) noise."""
    t = np.arange(n) * step
    w = 2 * np.pi * 0.4
    phase = 0.3  # keeps cos(w t + phase) away from exact zeros at the samples
    position = -250.0 + 20.0 * np.sin(w * t + phase)
    velocity = 20.0 * w * np.cos(w * t + phase)
    acceleration = -20.0 * w * w * np.sin(w * t + phase)
    rng = np.random.default_rng(seed)
    noise = np.zeros(n)
    for k in range(1, n):
        noise[k] = 0.7 * noise[k - 1] + 0.05 * rng.standard_normal()
    effort = 3e-4 * acceleration + 0.9 * np.sign(velocity) + 0.006 * velocity + noise
    return AxisLog(time=t, position=position, effort=effort, velocity=velocity, acceleration=acceleration)


def evidence(run, names, context=None, seed=0):
    model = AugmentedModel(base=CoulombModel()).fit(run)
    return score_step(model.with_base_friction([run]), model.linear_part([run]), context or model.context, names,
                      rng=np.random.default_rng(seed), n_null=49)


def test_offset_and_asymmetry_cannot_be_told_apart_without_rest():
    # with a sharp direction factor and no sample at rest, max(d, 0) = (sgn v + 1) / 2: the asymmetry
    # column equals the offset column up to the Coulomb column the base fits anyway
    run = sine_stroke()
    run = run.replace(effort=run.effort + 0.05)
    sharp = EffectContext(1e-9, (float(run.position.min()), float(run.position.max())))
    step = evidence(run, ["constant_offset", "direction_asymmetry"], context=sharp)
    assert step.candidates["constant_offset"].passes and step.candidates["direction_asymmetry"].passes
    assert step.winner in ("constant_offset", "direction_asymmetry")
    other = {"constant_offset", "direction_asymmetry"} - {step.winner}
    assert step.indistinguishable == list(other)


def test_columns_the_base_fits_anyway_are_absorbed():
    run = sine_stroke()
    run = run.replace(effort=run.effort + 2e-4 * run.acceleration)
    step = evidence(run, ["inertia_mismatch", "viscous_friction"])
    for name in ("inertia_mismatch", "viscous_friction"):
        assert step.candidates[name].absorbed and not step.candidates[name].passes
    assert step.winner is None


def test_a_hidden_periodic_force_is_found_with_its_period():
    run = sine_stroke(seed=1)
    run = run.replace(effort=run.effort + 0.04 * np.sin(2 * np.pi * run.position / 3.0))
    step = evidence(run, ["position_periodic_force", "position_periodic_friction", "constant_offset"])
    assert step.winner == "position_periodic_force"
    assert step.candidates["position_periodic_force"].shape == pytest.approx(3.0, rel=0.03)
    assert step.candidates["position_periodic_force"].explained_fraction > \
        step.candidates["position_periodic_force"].threshold_fraction


def test_the_winner_explains_most_beyond_chance_and_the_report_is_consistent():
    run = sine_stroke(seed=2)
    hidden = 0.03 * (run.position - run.position.mean()) / 20.0 * np.sign(run.velocity)
    step = evidence(run.replace(effort=run.effort + hidden), ["position_trend", "thermal_drift", "constant_offset"])
    assert step.winner == "position_trend"
    for score in list(step.candidates.values()) + [step.structure]:
        assert score.passes == (score.p_value <= step.alpha)
        assert score.passes == (score.z >= step.threshold_z)
    summary = step.to_dict()
    assert summary["winner"] == "position_trend" and set(summary["candidates"]) == set(step.candidates)


@pytest.mark.parametrize("n", [4, 21, 100])
def test_leave_one_out_quantiles_match_quantiles_of_the_others(n):
    from greybox.discover.evidence import _leave_one_out_quantile

    values = np.random.default_rng(n).normal(size=n)
    values[1] = values[0]  # a tie
    order = np.argsort(values, kind="stable")
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    for level in (0.5, 0.9):
        expected = [np.quantile(np.delete(values, i), level) for i in range(n)]
        np.testing.assert_allclose(_leave_one_out_quantile(values[order], rank, level), expected, atol=1e-15)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_on_pure_noise_the_family_wise_p_values_are_not_too_small():
    # exchangeable observed and null residuals: P(p <= 0.2) must stay near 0.2 over many noise draws
    rejections = 0
    for seed in range(30):
        run = sine_stroke(n=3000, seed=100 + seed)
        step = evidence(run, ["constant_offset", "position_trend", "position_periodic_force"], seed=seed)
        rejections += min(s.p_value for s in step.candidates.values()) <= 0.2
    assert rejections <= 12  # expected 6 of 30; 12 or more has chance < 1 %
