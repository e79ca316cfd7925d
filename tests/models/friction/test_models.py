"""The estimator contract shared by all friction current models."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import STEP, motion_log, velocity_profile
from sklearn.base import clone

from greybox.errors import LogError, ParameterError
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.friction.gms import simulate_gms

QUICK = {
    "coulomb": lambda: CoulombModel(),
    "stribeck": lambda: StribeckModel(),
    "lugre": lambda: LuGreModel(n_starts=1, max_iter=40),
    "gms": lambda: GMSModel(n_starts=1, max_iter=30),
}


def make_log(seed, duration=4.0, unit="A", source="run.mcap"):
    velocity = velocity_profile(duration, seed=seed)
    log = motion_log(velocity, source=source, effort_unit=unit)
    friction, _ = simulate_gms(velocity, STEP, alpha=np.array([0.2, 0.3, 0.5]), k=np.array([50.0, 40.0, 30.0]),
                               C=2.0, sigma=0.002, s_0=0.02, s_inf=0.015, v_s=5.0, mu=0.005)
    return log.replace(effort=0.001 * log.acceleration + friction)


@pytest.fixture(scope="module")
def fitted_models():
    runs = [make_log(1), make_log(2, duration=3.0)]
    return runs, {name: factory().fit(runs) for name, factory in QUICK.items()}


@pytest.mark.parametrize("name", sorted(QUICK))
def test_predictions_of_runs_are_concatenated_and_restart(fitted_models, name):
    runs, models = fitted_models
    model = models[name]
    together = model.predict(runs)
    assert together.shape == (sum(len(run) for run in runs),)
    np.testing.assert_array_equal(together, np.concatenate([model.predict(run) for run in runs]))
    np.testing.assert_allclose(model.friction(runs[0]) + model.J_ * runs[0].acceleration + model.offset_,
                               model.predict(runs[0]), rtol=0, atol=1e-12)
    # a model of the friction does most of the work on these logs
    residual = together - np.concatenate([run.effort for run in runs])
    assert np.std(residual) < 0.5 * np.std(np.concatenate([run.effort for run in runs]))


@pytest.mark.parametrize("name", sorted(QUICK))
def test_every_model_is_odd(fitted_models, name):
    runs, models = fitted_models
    log = runs[0]
    mirrored = log.replace(position=-log.position, velocity=-log.velocity, acceleration=-log.acceleration)
    np.testing.assert_allclose(models[name].predict(mirrored), -models[name].predict(log), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", sorted(QUICK))
def test_learned_attributes_are_plain_values(fitted_models, name):
    _, models = fitted_models
    model = models[name]
    learned = {key: value for key, value in vars(model).items() if key.endswith("_") and not key.startswith("_")}
    assert {"J_", "offset_", "effort_unit_", "sample_time_", "n_samples_fit_"} <= set(learned)
    for key, value in learned.items():
        assert isinstance(value, (float, int, bool, str, list, dict, np.ndarray)), (key, type(value))
        assert not isinstance(value, np.generic), key
    assert isinstance(model.n_params, int) and model.n_params > 0
    assert model.sample_time_ == pytest.approx(STEP)


@pytest.mark.parametrize("name", sorted(QUICK))
def test_estimator_parameters_round_trip(name):
    model = QUICK[name]()
    params = model.get_params()
    twin = clone(model)
    assert twin.get_params() == params
    key = "fit_offset"
    twin.set_params(**{key: True})
    assert twin.get_params()[key] is True and model.get_params()[key] is False


@pytest.mark.parametrize("name", sorted(QUICK))
def test_unprepared_log_is_refused_naming_the_file(name):
    log = make_log(3).replace(acceleration=None, source="/data/x_axis.csv")
    with pytest.raises(LogError, match="x_axis.csv.*acceleration"):
        QUICK[name]().fit(log)


@pytest.mark.parametrize("name", sorted(QUICK))
def test_standing_axis_is_refused(name):
    log = motion_log(np.zeros(500), np.full(500, 0.3), source="idle.mcap")
    with pytest.raises(LogError, match="idle.mcap.*zero throughout"):
        QUICK[name]().fit(log)


def test_force_logs_keep_their_unit_and_mixed_units_are_refused():
    log = make_log(4, unit="N")
    model = CoulombModel().fit(log)
    assert model.effort_unit_ == "N"
    with pytest.raises(LogError, match="fitted on N"):
        model.predict(make_log(4, unit="A", source="amps.csv"))
    with pytest.raises(LogError, match="mix effort units"):
        CoulombModel().fit([log, make_log(5, unit="A")])


def test_non_finite_samples_are_refused():
    log = make_log(6)
    velocity = log.velocity.copy()
    velocity[17] = np.nan
    with pytest.raises(LogError, match="velocity.*sample 17"):
        StribeckModel().fit(log.replace(velocity=velocity))


def test_progress_true_prints_to_stderr(capsys):
    LuGreModel(n_starts=1, max_iter=5).fit(make_log(7, duration=2.0), progress=True)
    err = capsys.readouterr().err
    assert "LuGre: start 1/1" in err and "best" in err
    LuGreModel(n_starts=1, max_iter=5).fit(make_log(7, duration=2.0), progress=False)
    assert capsys.readouterr().err == ""


def test_unknown_method_is_a_parameter_error():
    with pytest.raises(ParameterError, match="unknown method"):
        GMSModel(method="powell").fit(make_log(8, duration=1.0))
