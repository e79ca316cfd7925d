"""A known inertia (an effort measured at the load), and an inertia that only stands in for a spring."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import motion_log, velocity_profile

from greybox.data.log import AxisLog
from greybox.errors import ParameterError
from greybox.identify.inertia import SPRING_SHARE_LIMIT, inertia_note, spring_share
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel, StribeckModel
from greybox.models.gmssvr import GMSSVRModel

STEP = 0.002


def _sine_run(frequency_hz: float, amplitude_mm: float = 20.0, periods: int = 6, spring: float = 0.0):
    """A sinusoidal run whose effort is Coulomb friction plus a spring force ``-spring x`` [A/mm]."""
    t = np.arange(int(periods / frequency_hz / STEP)) * STEP
    w = 2 * np.pi * frequency_hz
    x = amplitude_mm * np.sin(w * t)
    v = amplitude_mm * w * np.cos(w * t)
    a = -amplitude_mm * w ** 2 * np.sin(w * t)
    return AxisLog(time=t, position=x, effort=0.5 * np.sign(v) + spring * x, velocity=v, acceleration=a,
                   effort_unit="N")


def test_spring_share_tells_one_frequency_from_several():
    assert spring_share([_sine_run(0.5)]) > 0.99
    assert spring_share([_sine_run(0.5), _sine_run(0.5, amplitude_mm=40.0)]) > 0.99  # one law at any amplitude
    assert spring_share([_sine_run(0.25), _sine_run(2.0, periods=20)]) < SPRING_SHARE_LIMIT  # a = -w^2 x differs
    steps = motion_log(velocity_profile(20.0, seed=3))
    assert spring_share([steps]) < SPRING_SHARE_LIMIT
    still = steps.replace(acceleration=np.zeros(len(steps)))
    assert spring_share([still]) == 0.0


def test_a_fitted_inertia_on_sines_is_flagged_and_kept_in_the_model_file(tmp_path):
    runs = [_sine_run(0.5, spring=-0.01), _sine_run(0.5, amplitude_mm=40.0, spring=-0.01)]  # a spring pushing out
    model = CoulombModel().fit(runs)
    assert model.J_ > 0  # the spring force -(-0.01) x = 0.01 x = -(0.01 / w^2) a looks like an inertia
    notes = model.fit_notes()
    assert len(notes) == 1 and "cannot be told from a spring force" in notes[0] and "N s^2/mm" in notes[0]
    path = save_model(model, tmp_path / "m.gbm")
    assert load_model(path).fit_notes() == notes
    assert inertia_note(runs, 0.0, "N s^2/mm") is None  # no inertia, nothing to say
    several = [_sine_run(0.25, spring=-0.01), _sine_run(2.0, periods=20, spring=-0.01)]
    assert CoulombModel().fit(several).fit_notes() == []


@pytest.mark.parametrize("factory", [CoulombModel, StribeckModel, lambda **kw: GMSModel(n_starts=1, max_iter=20, **kw)])
def test_a_known_inertia_is_kept_and_the_friction_fitted_on_the_rest(factory):
    velocity = velocity_profile(3.0, seed=5)
    log = motion_log(velocity)
    known = 0.003
    log = log.replace(effort=known * log.acceleration + 0.7 * np.sign(velocity) + 0.004 * velocity)
    free = factory().fit([log])
    fixed = factory(inertia=known).fit([log])
    assert fixed.J_ == known
    rms = float(np.sqrt(np.mean(log.effort ** 2)))
    assert np.sqrt(np.mean((fixed.predict(log) - log.effort) ** 2)) < 0.1 * rms
    at_load = factory(inertia=0.0).fit([log])
    assert at_load.J_ == 0.0
    np.testing.assert_allclose(at_load.predict(log), at_load.predict(log.replace(acceleration=10 * log.acceleration)))
    assert free.J_ > 0.0


def test_the_grey_box_model_takes_its_inertia_from_its_stage():
    velocity = velocity_profile(6.0, seed=6)
    log = motion_log(velocity)
    log = log.replace(effort=0.7 * np.sign(velocity) + 0.004 * velocity)
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=20, inertia=0.0), n_subset=200, optimize=False).fit([log])
    assert model.J_ == 0.0 and model.gms_.J_ == 0.0


@pytest.mark.parametrize("bad", [-1.0, float("nan"), "0.1", True])
def test_an_invalid_inertia_is_refused(bad):
    log = motion_log(velocity_profile(2.0, seed=1))
    with pytest.raises(ParameterError, match="inertia must be None"):
        CoulombModel(inertia=bad).fit([log])
