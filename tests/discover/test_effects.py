"""The candidate-effect library: names, regressors and physical parameters."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.errors import GreyboxError
from greybox.models.effects import EFFECT_NAMES, EFFECTS, EffectContext, effect, period_scan
from greybox.twin import EFFECTS as TWIN_EFFECTS
from greybox.twin import EffectInputs, effect_current


def stroke(n=4000, step=0.002, amplitude=20.0, frequency=0.5, offset=-250.0):
    """A prepared sinusoidal stroke (analytic velocity and acceleration)."""
    t = np.arange(n) * step
    w = 2 * np.pi * frequency
    return AxisLog(time=t, position=offset + amplitude * np.sin(w * t), effort=np.zeros(n),
                   velocity=amplitude * w * np.cos(w * t), acceleration=-amplitude * w * w * np.sin(w * t))


def test_library_names_are_the_issue_list_and_contain_the_twin_effects():
    assert EFFECT_NAMES == ("direction_asymmetry", "constant_offset", "position_trend", "position_periodic_friction",
                            "position_periodic_force", "thermal_drift", "inertia_mismatch", "viscous_friction",
                            "stribeck", "load_dependent_friction")
    assert set(TWIN_EFFECTS) <= set(EFFECTS)


def test_unknown_effect_and_bad_shapes_are_refused():
    with pytest.raises(GreyboxError, match="unknown effect"):
        effect("gravity")
    with pytest.raises(GreyboxError, match="needs a positive period_mm"):
        effect("position_periodic_force").columns(stroke(), EffectContext(0.5, (-270.0, -230.0)), None)
    with pytest.raises(GreyboxError, match="has no shape"):
        effect("constant_offset").columns(stroke(), EffectContext(0.5, (-270.0, -230.0)), 3.0)


@pytest.mark.parametrize("name", ["position_periodic_force", "position_periodic_friction"])
def test_periodic_columns_reproduce_the_twin_effect_and_its_amplitude_and_phase(name):
    run = stroke()
    context = EffectContext(0.5, (-270.0, -230.0))  # the twin's velocity scale
    period, phase, amplitude = 7.0, 0.9, 0.3
    inputs = EffectInputs(run.time, run.position, run.velocity, run.acceleration, (-510.0, 0.0))
    truth = effect_current(name, inputs, amplitude, period_mm=period, phase_rad=phase)
    # sin(x + phase) = cos(phase) sin(x) + sin(phase) cos(x)
    coefficients = amplitude * np.array([np.cos(phase), np.sin(phase)])
    term = effect(name)
    np.testing.assert_allclose(term.current(run, context, coefficients, period), truth, atol=1e-12)
    parameters = term.parameters(coefficients, context, period, "A")
    assert parameters["period_mm"] == period
    assert parameters["amplitude_A"] == pytest.approx(amplitude)
    assert parameters["phase_rad"] == pytest.approx(phase)


def test_friction_terms_flip_with_the_direction_and_force_terms_do_not():
    run = stroke()
    reverse = run.replace(velocity=-run.velocity)
    context = EffectContext(0.5, (-270.0, -230.0))
    for name in ("position_periodic_friction", "position_trend", "thermal_drift", "stribeck",
                 "load_dependent_friction"):
        shape = {"position_periodic_friction": 5.0, "thermal_drift": 3.0, "stribeck": 2.0}.get(name)
        np.testing.assert_allclose(effect(name).columns(reverse, context, shape),
                                   -effect(name).columns(run, context, shape), atol=1e-12)
    np.testing.assert_allclose(effect("position_periodic_force").columns(reverse, context, 5.0),
                               effect("position_periodic_force").columns(run, context, 5.0))


def test_direction_asymmetry_adds_level_and_viscous_friction_in_positive_motion_only():
    run = stroke()
    context = EffectContext(1e-6, (-270.0, -230.0))
    term = effect("direction_asymmetry")
    current = term.current(run, context, [0.2, 0.01])
    moving_up, moving_down = run.velocity > 1e-3, run.velocity < 0
    np.testing.assert_allclose(current[moving_up], 0.2 + 0.01 * run.velocity[moving_up])
    assert np.all(current[moving_down] == 0.0)
    assert term.parameters([0.2, 0.01], context, None, "N") == {"level_difference_N": 0.2,
                                                                "viscous_difference_N_s_per_mm": 0.01}
    # the twin's (level-only) asymmetry with the same velocity scale is the first column
    inputs = EffectInputs(run.time, run.position, run.velocity, run.acceleration, (-510.0, 0.0))
    twin = effect_current("direction_asymmetry", inputs, 0.3, velocity_scale_mm_s=0.5)
    np.testing.assert_allclose(term.current(run, EffectContext(0.5, (-270.0, -230.0)), [0.3, 0.0]), twin)


def test_position_trend_spans_the_twin_trend_up_to_the_direction_term():
    run = stroke()
    context = EffectContext(0.5, (float(run.position.min()), float(run.position.max())))
    inputs = EffectInputs(run.time, run.position, run.velocity, run.acceleration, (-510.0, 0.0))
    truth = effect_current("position_trend", inputs, 0.4)
    columns = np.column_stack((effect("position_trend").columns(run, context), context.direction(run)))
    coefficients, *_ = np.linalg.lstsq(columns, truth, rcond=None)
    np.testing.assert_allclose(columns @ coefficients, truth, atol=1e-12)
    # the twin's u runs over the 510 mm travel: slope 2 * 0.4 / 510 A/mm in the direction of motion
    parameters = effect("position_trend").parameters(coefficients[:2], context, None, "A")
    assert parameters["slope_A_per_mm"] == pytest.approx(0.8 / 510.0)
    assert parameters["end_rise_A"] == pytest.approx(0.0, abs=1e-12)


def test_thermal_drift_starts_at_zero_and_settles_to_the_direction():
    run = stroke(n=20000)
    context = EffectContext(0.5, (-270.0, -230.0))
    column = effect("thermal_drift").columns(run, context, 2.0)[:, 0]
    assert column[0] == 0.0
    late = run.time > 30.0
    np.testing.assert_allclose(column[late], context.direction(run)[late], atol=1e-6)


def test_period_scan_is_a_grid_of_integer_frequency_multiples_within_the_range():
    run = stroke()
    context = EffectContext.from_runs([run])
    step, periods = period_scan([run], context)
    multiples = 1.0 / (periods * step)
    np.testing.assert_allclose(multiples, np.round(multiples), atol=1e-6)
    span = context.position_range_mm[1] - context.position_range_mm[0]
    assert periods.max() <= span / 2 * (1 + 1e-9)  # two periods at least in the range
    assert step <= 1.0 / (4.0 * span) * (1 + 1e-9)
    median_step = np.median(np.abs(np.diff(run.position)))
    assert periods.min() >= 4.0 * median_step * (1 - 1e-9)


def test_context_from_runs_takes_the_position_range_and_one_percent_of_the_speed():
    run = stroke()
    context = EffectContext.from_runs([run])
    assert context.position_range_mm == (run.position.min(), run.position.max())
    assert context.velocity_scale_mm_s == pytest.approx(0.01 * np.percentile(np.abs(run.velocity), 99))


def test_a_long_travel_scanned_in_fine_steps_keeps_at_most_4000_periods():
    run = stroke(n=20000, amplitude=500.0, frequency=0.002)  # 240 mm in 40 s: about 0.012 mm per sample
    context = EffectContext.from_runs([run])
    span = context.position_range_mm[1] - context.position_range_mm[0]
    step, periods = period_scan([run], context)
    assert periods.size == 4000
    assert periods.min() == pytest.approx(span / 1000.0, rel=0.01)
    assert step == pytest.approx(1.0 / (4.0 * span), rel=1e-9)


def test_position_trend_holds_its_end_values_beyond_the_training_range():
    run = stroke()
    context = EffectContext(0.5, (-260.0, -250.0))  # the stroke runs from -270 to -230 mm
    u = context.unit_position(run)
    assert u.min() == -1.0 and u.max() == 1.0
    inside = (run.position >= -260.0) & (run.position <= -250.0)
    np.testing.assert_allclose(u[inside], (2 * run.position[inside] + 510.0) / 10.0)
