"""AugmentedModel's parameter intervals: the shapes of its base and of its terms are identified, so they get one."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.identify.intervals import attach_intervals, parameter_intervals
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import effect
from greybox.models.friction import CoulombModel, StribeckModel
from greybox.twin import make_dataset

PERIOD, AMPLITUDE, PHASE = 2.5, 0.08, -0.7  # mm, A, rad: the hidden cogging-like force


@pytest.fixture(scope="module")
def stroke():
    """A prepared random-window log (motion only; the tests set the effort)."""
    return prepare([make_dataset("X", "A", seed=5, duration_s=20.0)])[0]


def _coulomb_current(run):
    return 3e-4 * run.acceleration + 0.9 * np.sign(run.velocity) + 0.006 * run.velocity


@pytest.fixture(scope="module")
def cogging_run(stroke):
    """Coulomb friction plus a force periodic in position of known period, plus AR(1) noise."""
    plain = AugmentedModel(base=CoulombModel()).fit(stroke.replace(effort=_coulomb_current(stroke)))
    hidden = effect("position_periodic_force").current(plain.with_base_friction(stroke)[0], plain.context,
                                                       AMPLITUDE * np.array([np.cos(PHASE), np.sin(PHASE)]), PERIOD)
    rng = np.random.default_rng(1)
    noise = np.zeros(len(stroke))
    shocks = rng.normal(0.0, 0.01, len(stroke))
    for i in range(1, len(stroke)):
        noise[i] = 0.9 * noise[i - 1] + shocks[i]
    return stroke.replace(effort=_coulomb_current(stroke) + hidden + noise)


def _row(model, name):
    return next(row for row in model.parameter_table() if row.name == name)


def test_a_refined_term_shape_gets_a_sandwich_interval_that_holds_the_truth(cogging_run):
    model = AugmentedModel(base=CoulombModel(), effects=["position_periodic_force"]).fit(cogging_run)
    before = model.predict(cogging_run)
    attach_intervals(model, cogging_run)
    row = _row(model, "1:position_periodic_force.period_mm")
    assert row.flag == ""
    assert row.lower < PERIOD < row.upper
    assert row.upper - row.lower < 0.02 * PERIOD  # a period seen over many cycles is well determined
    # the phase depends on the period too: its interval widens once the period is varied
    fixed = AugmentedModel(base=CoulombModel(), effects=[("position_periodic_force", row.value)],
                           refine_shapes=False).fit(cogging_run)
    phase_free = parameter_intervals(model, cogging_run)["rows"]["1:position_periodic_force.phase_rad"]
    phase_fixed = parameter_intervals(fixed, cogging_run)["rows"]["1:position_periodic_force.phase_rad"]
    assert phase_free["upper"] - phase_free["lower"] > 1.5 * (phase_fixed["upper"] - phase_fixed["lower"])
    # moving each coordinate and writing it back leaves the model as it was
    np.testing.assert_array_equal(model.predict(cogging_run), before)
    assert _row(model, "1:position_periodic_force.period_mm").value == row.value


def test_a_shape_not_refined_is_not_varied_and_says_so(cogging_run):
    model = AugmentedModel(base=CoulombModel(), effects=[("position_periodic_force", PERIOD)],
                           refine_shapes=False).fit(cogging_run)
    assert "1:position_periodic_force.shape" not in model.interval_coordinates()
    row = parameter_intervals(model, cogging_run)["rows"]["1:position_periodic_force.period_mm"]
    assert np.isnan(row["lower"]) and row["flag"].startswith("no interval")


def test_the_base_shape_moves_with_the_friction_the_terms_scale_and_gets_the_base_models_interval(stroke):
    rng = np.random.default_rng(1)
    velocity = stroke.velocity
    stribeck = 0.4 * np.exp(-np.abs(velocity) / 2.0) * np.sign(velocity)
    run = stroke.replace(effort=_coulomb_current(stroke) + stribeck + rng.normal(0.0, 0.02, len(stroke)))
    model = AugmentedModel(base=StribeckModel(), effects=["thermal_drift"]).fit(run)
    assert {"base.v_s_", "1:thermal_drift.shape"} <= set(model.interval_coordinates())
    v_s = model.interval_value("base.v_s_")
    model.set_interval_value("base.v_s_", 2.0 * v_s)
    assert model.base_.v_s_ == model.friction_shape_base_.v_s_ == 2.0 * v_s
    model.set_interval_value("base.v_s_", v_s)
    with pytest.raises(ValueError, match="no interval coordinate"):
        model.interval_value("2:thermal_drift.shape")
    # without terms the augmented model is its base, and so are the base's intervals
    alone = parameter_intervals(StribeckModel().fit(run), run)["rows"]["v_s"]
    bare = parameter_intervals(AugmentedModel(base=StribeckModel()).fit(run), run)["rows"]["base.v_s"]
    assert bare["flag"] == alone["flag"] == ""
    np.testing.assert_allclose([bare["lower"], bare["upper"]], [alone["lower"], alone["upper"]], rtol=1e-6)
    # with a term the base's shape and the term's get intervals of their own
    rows = parameter_intervals(model, run)["rows"]
    width = rows["base.v_s"]["upper"] / rows["base.v_s"]["lower"]
    assert rows["base.v_s"]["lower"] < v_s < rows["base.v_s"]["upper"]
    assert width < 2.0 * alone["upper"] / alone["lower"]
    assert not rows["1:thermal_drift.time_constant_s"]["flag"].startswith("no interval")
