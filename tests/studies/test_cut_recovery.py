"""Figures of process-current recovery, and the strength at which a correlation target is reached."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.models.friction.coulomb import CoulombModel
from greybox.predict.process import predict_process
from greybox.twin import make_dataset
from greybox.twin.cutting import CuttingSpec
from studies.cut_recovery import correlation_at_strength, recovery_metrics, strength_for_correlation

#: A validation study's tests (runs of the study, its script, the real data sets): left out of the default
#: run (`pytest -m slow` runs them, as .ci/run does).
pytestmark = pytest.mark.slow


def square_cut(n=4000, seed=0):
    """A process current switched on and off (unit strength) and a smooth error."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.002
    unit = np.where((t % 2.0) < 1.0, -1.0, 0.0)
    error = 0.1 * np.sin(2 * np.pi * 0.7 * t) + 0.05 * rng.standard_normal(n)
    return unit, error


def test_perfect_recovery_has_no_error_and_full_correlation():
    unit, noise = square_cut()
    metrics = recovery_metrics(0.4 * unit, 0.4 * unit, noise, 700.0)
    assert metrics["process_rmse_A"] == 0.0 and metrics["force_rmse_N"] == 0.0
    assert metrics["correlation"] == pytest.approx(1.0)
    assert metrics["mean_cut_force_true_N"] == pytest.approx(-0.4 * 700.0)
    assert metrics["mean_cut_force_estimated_N"] == pytest.approx(-0.4 * 700.0)
    assert metrics["cut_share"] == pytest.approx(0.5)
    assert metrics["correlation_ceiling"] < 1.0


def test_force_figures_scale_with_the_force_constant():
    unit, error = square_cut()
    one = recovery_metrics(unit, unit + error, error, 1.0)
    scaled = recovery_metrics(unit, unit + error, error, 763.4)
    assert scaled["force_rmse_N"] == pytest.approx(763.4 * one["process_rmse_A"])
    assert scaled["mean_cut_force_estimated_N"] == pytest.approx(763.4 * one["mean_cut_force_estimated_N"])
    assert scaled["correlation"] == one["correlation"]


def test_a_log_without_cut_is_refused():
    with pytest.raises(ValueError, match="no cut"):
        recovery_metrics(np.zeros(10), np.ones(10), np.zeros(10), 1.0)


def test_correlation_rises_with_the_cut_strength():
    unit, error = square_cut()
    strengths = np.geomspace(0.01, 10.0, 30)
    r = [correlation_at_strength(unit, error, s) for s in strengths]
    assert np.all(np.diff(r) > 0.0)
    assert r[0] < 0.2 and r[-1] > 0.999


def test_strength_for_correlation_lands_on_the_target():
    unit, error = square_cut()
    for target in (0.5, 0.9, 0.95, 0.99):
        s = strength_for_correlation(unit, error, target)
        assert correlation_at_strength(unit, error, s) == pytest.approx(target, abs=1e-7)
        assert correlation_at_strength(unit, error, 0.999 * s) < target


def test_unreachable_and_already_reached_targets():
    unit, error = square_cut()
    assert strength_for_correlation(unit, error, 0.95, bracket=(1e-3, 1e-2)) == np.inf
    assert strength_for_correlation(unit, error, 0.95, bracket=(100.0, 1000.0)) == 100.0
    with pytest.raises(ValueError, match="target"):
        strength_for_correlation(unit, error, 1.0)


def test_twin_cut_leaves_the_recovery_error_unchanged_so_one_log_predicts_every_strength():
    """The premise of the strength sweep: on the synthetic axis the cut changes neither motion nor noise."""
    strengths = (0.3, 1.5)
    logs = [make_dataset("X", "D", seed=11, cutting=CuttingSpec(strength_A=s)) for s in strengths]
    air = make_dataset("X", "D", seed=12)
    model = CoulombModel(fit_offset=True).fit(prepare([air]))
    cuts = prepare(logs)
    recovered = [predict_process(model, cut).process for cut in cuts]
    truths = [cut.extras["truth_process_A"] for cut in cuts]
    np.testing.assert_allclose(truths[1], truths[0] * strengths[1] / strengths[0], atol=1e-12)
    errors = [r - t for r, t in zip(recovered, truths)]
    # Equal up to the 1 mA current quantisation of each log.
    assert np.max(np.abs(errors[1] - errors[0])) <= 1.0e-3 + 1e-9
    unit = truths[0] / strengths[0]
    predicted = correlation_at_strength(unit, errors[0], strengths[1])
    measured = np.corrcoef(truths[1], recovered[1])[0, 1]
    assert predicted == pytest.approx(measured, abs=2e-3)
    assert measured > np.corrcoef(truths[0], recovered[0])[0, 1] + 0.05
