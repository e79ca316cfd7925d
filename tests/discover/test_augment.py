"""AugmentedModel: a base friction model plus effect terms, fitted jointly."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import effect
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, StribeckModel
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def stroke():
    """A prepared random-window log (motion only; the tests set the effort)."""
    return prepare([make_dataset("X", "A", seed=5, duration_s=20.0)])[0]


def coulomb_current(run):
    return 3e-4 * run.acceleration + 0.9 * np.sign(run.velocity) + 0.006 * run.velocity


def test_joint_fit_is_one_least_squares_solve_over_base_and_terms(stroke):
    rng = np.random.default_rng(0)
    run = stroke.replace(effort=coulomb_current(stroke) + 0.1 + rng.normal(0, 0.05, len(stroke)))
    model = AugmentedModel(base=CoulombModel(), effects=[("constant_offset", None), ("thermal_drift", 7.0)],
                           refine_shapes=False, refit_base=False).fit(run)
    context, (carried,) = model.context, model.with_base_friction(run)  # friction terms scale the base's friction
    columns = np.column_stack([model.base_.linear_part(run).columns,
                               effect("constant_offset").columns(carried, context),
                               effect("thermal_drift").columns(carried, context, 7.0)])
    expected, *_ = np.linalg.lstsq(columns, run.effort, rcond=None)
    np.testing.assert_allclose(model.linear_coefficients(), expected, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(model.predict(run), columns @ expected, atol=1e-10)
    # the constant term is reported in the offset, the rest of the prediction is inertia + friction
    assert model.offset_ == pytest.approx(expected[3])
    np.testing.assert_allclose(model.predict(run), model.J_ * run.acceleration + model.friction(run)
                               + model.offset_, atol=1e-12)


def test_inertia_mismatch_is_reported_in_the_inertia(stroke):
    run = stroke.replace(effort=coulomb_current(stroke))
    model = AugmentedModel(base=CoulombModel(), effects=["inertia_mismatch"]).fit(run)
    assert model.J_ == pytest.approx(3e-4, rel=1e-6)
    np.testing.assert_allclose(model.predict(run), run.effort, atol=1e-9)


@pytest.mark.parametrize("name, period", [("position_periodic_friction", 6.0), ("position_periodic_force", 2.5)])
def test_a_periodic_term_recovers_period_amplitude_and_phase(stroke, name, period):
    plain = AugmentedModel(base=CoulombModel()).fit(stroke.replace(effort=coulomb_current(stroke)))
    amplitude, phase = 0.08, -0.7
    hidden = effect(name).current(plain.with_base_friction(stroke)[0], plain.context,
                                  amplitude * np.array([np.cos(phase), np.sin(phase)]), period)
    rng = np.random.default_rng(1)
    run = stroke.replace(effort=coulomb_current(stroke) + hidden + rng.normal(0, 0.03, len(stroke)))
    model = AugmentedModel(base=CoulombModel(), effects=[(name, None)]).fit(run)
    parameters = model.effects_[0]["parameters"]
    assert parameters["period_mm"] == pytest.approx(period, rel=0.01)
    assert parameters["amplitude_A"] == pytest.approx(amplitude, rel=0.05)
    # the phase refers to x = 0, far outside the data: compare the currents instead
    fitted = model.term_currents(run)[f"1:{name}"]
    assert np.sqrt(np.mean((fitted - hidden) ** 2)) < 0.1 * np.sqrt(np.mean(hidden ** 2))


def test_refit_base_moves_the_stribeck_shape_once_the_term_is_removed(stroke):
    rng = np.random.default_rng(2)
    hidden = 0.3 * np.sin(2 * np.pi * stroke.position / 6.0) * np.tanh(stroke.velocity / 0.3)
    run = stroke.replace(effort=coulomb_current(stroke) + hidden + rng.normal(0, 0.03, len(stroke)))
    fixed = AugmentedModel(base=StribeckModel(), effects=[("position_periodic_friction", 6.0)],
                           refit_base=False).fit(run)
    refit = AugmentedModel(base=StribeckModel(), effects=[("position_periodic_friction", 6.0)],
                           refit_base=True).fit(run)
    residual = [np.mean((run.effort - m.predict(run)) ** 2) for m in (fixed, refit)]
    assert residual[1] <= residual[0] * (1 + 1e-9)


def test_term_currents_add_up_to_the_prediction_minus_the_base(stroke):
    rng = np.random.default_rng(3)
    run = stroke.replace(effort=coulomb_current(stroke) + rng.normal(0, 0.05, len(stroke)))
    model = AugmentedModel(base=CoulombModel(), effects=["direction_asymmetry", ("stribeck", 3.0)]).fit(run)
    terms = model.term_currents(run)
    assert list(terms) == ["1:direction_asymmetry", "2:stribeck"]
    np.testing.assert_allclose(model.predict(run), model.base_.predict(run) + sum(terms.values()), atol=1e-12)


def test_bad_effects_are_refused(stroke):
    run = stroke.replace(effort=coulomb_current(stroke))
    with pytest.raises(GreyboxError, match="unknown effect"):
        AugmentedModel(base=CoulombModel(), effects=["gravity"]).fit(run)
    with pytest.raises(GreyboxError, match="given twice"):
        AugmentedModel(base=CoulombModel(), effects=["constant_offset", "constant_offset"]).fit(run)
    with pytest.raises(GreyboxError, match="has no shape"):
        AugmentedModel(base=CoulombModel(), effects=[("constant_offset", 2.0)]).fit(run)


def test_saved_model_predicts_identically(stroke, tmp_path, monkeypatch):
    rng = np.random.default_rng(4)
    run = stroke.replace(effort=coulomb_current(stroke) + rng.normal(0, 0.05, len(stroke)))
    model = AugmentedModel(base=StribeckModel(fit_offset=True),
                           effects=[("position_periodic_force", 2.5), "position_trend"]).fit(run)
    path = save_model(model, tmp_path / "augmented.gbm")
    loaded = load_model(path)
    assert type(loaded) is AugmentedModel and type(loaded.base_) is StribeckModel
    np.testing.assert_array_equal(loaded.predict(run), model.predict(run))
    assert loaded.effects_ == model.effects_


def test_two_terms_of_one_periodic_effect_stay_apart(stroke):
    plain = AugmentedModel(base=CoulombModel()).fit(stroke.replace(effort=coulomb_current(stroke)))
    context, (carried,) = plain.context, plain.with_base_friction(stroke)
    hidden = effect("position_periodic_friction").current(carried, context, [0.05, 0.0], 6.0) \
        + effect("position_periodic_friction").current(carried, context, [0.0, 0.04], 3.0)
    rng = np.random.default_rng(5)
    run = stroke.replace(effort=coulomb_current(stroke) + hidden + rng.normal(0, 0.02, len(stroke)))
    model = AugmentedModel(base=CoulombModel(), effects=[("position_periodic_friction", 6.0),
                                                         ("position_periodic_friction", 3.0)]).fit(run)
    periods = sorted(e["parameters"]["period_mm"] for e in model.effects_)
    assert periods == [pytest.approx(3.0, rel=0.01), pytest.approx(6.0, rel=0.01)]
    with pytest.raises(GreyboxError, match="cannot tell them apart"):
        AugmentedModel(base=CoulombModel(), effects=[("position_periodic_friction", 6.0),
                                                     ("position_periodic_friction", 6.001)]).fit(run)


def test_refinement_never_brings_a_period_next_to_another_of_the_same_effect():
    from greybox.models.augmented import _apart

    step = 0.01
    # bracket [4, 6] mm (0.167 ... 0.25 1/mm) around 5 mm; other terms 3 steps above and below in frequency
    low, high = _apart(5.0, 4.0, 6.0, [1.0 / 0.23, 1.0 / 0.17], step)
    assert 1.0 / low == pytest.approx(0.23 - 2 * step) and 1.0 / high == pytest.approx(0.17 + 2 * step)
    # a term far away leaves the bracket as it is
    assert _apart(5.0, 4.0, 6.0, [1.0], step) == (pytest.approx(4.0), pytest.approx(6.0))


def test_a_model_file_from_before_the_friction_scaling_loads_and_scales_the_direction(stroke, tmp_path):
    rng = np.random.default_rng(7)
    run = stroke.replace(effort=coulomb_current(stroke) + rng.normal(0, 0.03, len(stroke)))
    model = AugmentedModel(base=CoulombModel(), effects=[("thermal_drift", 7.0)]).fit(run)
    for name in ("friction_level_", "friction_shape_base_", "friction_shape_viscous_"):
        delattr(model, name)  # as written by greybox before friction terms scaled the base's friction
    path = save_model(model, tmp_path / "old.gbm")
    loaded = load_model(path)
    assert loaded.context.friction_level is None
    (coefficient,), tau = loaded.effects_[0]["coefficients"], loaded.effects_[0]["shape"]
    expected = coefficient * (1.0 - np.exp(-(run.time - run.time[0]) / tau)) * np.tanh(
        run.velocity / loaded.velocity_scale_mm_s_)
    np.testing.assert_allclose(loaded.term_currents(run)["1:thermal_drift"], expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(loaded.predict(run), model.predict(run))
