"""The SVR benchmark current model I = J a + offset + f(p, v)."""

from __future__ import annotations

import numpy as np
import pytest
from multisine import multisine_motion
from sklearn.base import clone
from svr_runs import FIXED, J_TRUE, OFFSET_TRUE, sweep_run

from greybox.data.log import AxisLog
from greybox.errors import LogError
from greybox.models.kernel.expansion import default_bounds
from greybox.models.svr import SVRCurrentModel, coulomb_viscous_proxy


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def test_proxy_recovers_inertia_and_offset_of_a_coulomb_viscous_axis():
    runs = [sweep_run(s, ripple=0.0, noise=0.0) for s in (1, 2)]
    # Replace the smooth tanh by an exact Coulomb step: the proxy then is the truth.
    runs = [r.replace(effort=J_TRUE * r.acceleration + 0.8 * np.sign(r.velocity) + 0.003 * r.velocity
                      + OFFSET_TRUE) for r in runs]
    J, offset = coulomb_viscous_proxy(runs)[:2]
    assert J == pytest.approx(J_TRUE, rel=1e-9)
    assert offset == pytest.approx(OFFSET_TRUE, rel=1e-9)
    J, offset = coulomb_viscous_proxy(runs, inertia=3e-4)[:2]
    assert J == 3e-4


def test_proxy_inertia_is_never_negative():
    runs = [sweep_run(s, ripple=0.0, noise=0.0) for s in (1, 2)]
    runs = [r.replace(effort=-J_TRUE * r.acceleration + 0.8 * np.sign(r.velocity) + OFFSET_TRUE) for r in runs]
    J, offset = coulomb_viscous_proxy(runs)[:2]
    assert J == 0.0
    assert np.isfinite(offset)


def test_learns_a_position_dependent_friction_a_position_blind_model_cannot():
    # 40 s runs: long enough for the (p, v) curves to cover the plane.
    train = [sweep_run(1, n=20000), sweep_run(2, n=20000)]
    test = sweep_run(3, n=20000)
    model = SVRCurrentModel(**FIXED).fit(train)
    # Same model, same data, but the position channel carries no information.
    blind = SVRCurrentModel(**FIXED).fit([r.replace(position=np.zeros(len(r))) for r in train])
    error = rmse(model.predict(test), test.current)
    blind_error = rmse(blind.predict(test.replace(position=np.zeros(len(test)))), test.current)
    # The ripple (amplitude 0.3 A, rms 0.21 A) is what the blind model misses.
    assert blind_error > 0.18
    assert error < 0.3 * blind_error
    # Friction + inertia + offset add up to the prediction.
    np.testing.assert_allclose(model.J_ * test.acceleration + model.friction(test) + model.offset_,
                               model.predict(test), atol=1e-12)


def test_predict_concatenates_runs_in_order():
    model = SVRCurrentModel(**FIXED).fit(sweep_run(1))
    a, b = sweep_run(4, n=500), sweep_run(5, n=300)
    both = model.predict([a, b])
    assert both.shape == (800,)
    np.testing.assert_array_equal(both[:500], model.predict(a))
    np.testing.assert_array_equal(both[500:], model.predict(b))


def test_bayesian_optimisation_chooses_free_hyperparameters_within_bounds():
    train = [sweep_run(1, n=3000), sweep_run(2, n=3000)]
    model = SVRCurrentModel(C=3.0, n_subset=250, n_calls=5, cv_folds=2, cv_blocks=6).fit(train)
    table = model.hyperparameters_table()
    assert table["kernel"] == "rbf" and table["C"] == 3.0
    assert table["optimised"] == ["epsilon", "gamma", "velocity_weight"]
    assert len(model.search_history_) == 5
    target = np.concatenate([r.current - model.J_ * r.acceleration for r in train]) - model.offset_
    bounds = default_bounds(np.std(target))
    for name in ("epsilon", "gamma"):
        assert bounds[name][0] <= table[name] <= bounds[name][1]
        assert all(bounds[name][0] <= h[name] <= bounds[name][1] for h in model.search_history_)
    assert table["cv_rmse"] == min(h["cv_rmse"] for h in model.search_history_)
    assert 0 < table["n_support"] <= table["n_train"] == 250
    # Seeded: the same settings give the same model.
    again = clone(model).fit(train)
    np.testing.assert_array_equal(again.dual_coef_, model.dual_coef_)


def test_unprepared_log_is_refused():
    run = sweep_run(1, n=100)
    with pytest.raises(LogError, match="not prepared"):
        SVRCurrentModel(**FIXED).fit(run.replace(acceleration=None))


def test_an_optimum_at_the_end_of_its_interval_is_reported():
    from greybox.models.kernel.expansion import _near_bound

    assert _near_bound(1.0, (1.0, 100.0)) and _near_bound(99.0, (1.0, 100.0))
    assert not _near_bound(10.0, (1.0, 100.0))
    train = [sweep_run(1, n=2000), sweep_run(2, n=2000)]
    # An interval too narrow to leave its ends: whatever is chosen sits at one.
    model = SVRCurrentModel(C=3.0, epsilon=0.01, velocity_weight=1.0, n_subset=150, n_calls=2, cv_folds=2,
                            cv_blocks=4, bounds={"gamma": (0.5, 0.5000001)})
    with pytest.warns(UserWarning, match="gamma = 0.5 ended at the end of its search interval"):
        model.fit(train)
    assert model.hyperparameters_table()["at_bounds"] == ["gamma"]


def test_bad_settings_are_refused_with_a_clear_error():
    from greybox.errors import ParameterError

    run = sweep_run(1, n=500)
    with pytest.raises(ParameterError, match="unknown SVR hyperparameter"):
        SVRCurrentModel(bounds={"nu": (0.1, 0.9)}, n_calls=2).fit(run)
    with pytest.raises(ParameterError, match="C must be positive"):
        SVRCurrentModel(C=-1.0, optimize=False).fit(run)
    with pytest.raises(ParameterError, match="random_state"):
        SVRCurrentModel(random_state=None, optimize=False).fit(run)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_velocity_weight_is_an_anisotropic_kernel_in_the_standardised_plane():
    from sklearn.svm import SVR

    run = sweep_run(1, n=3000)
    weight = 16.0
    model = SVRCurrentModel(**{**FIXED, "n_subset": 3000}, velocity_weight=weight).fit(run)
    # libsvm on the standardised inputs with the velocity column stretched by sqrt(weight): the same model.
    X = np.column_stack((run.position, run.velocity))
    scaled = (X - X.mean(axis=0)) / X.std(axis=0) * np.array([1.0, np.sqrt(weight)])
    target = run.current - model.J_ * run.acceleration - model.offset_
    reference = SVR(C=FIXED["C"], epsilon=FIXED["epsilon"], gamma=FIXED["gamma"]).fit(scaled, target)
    test = sweep_run(3, n=1000)
    X_test = np.column_stack((test.position, test.velocity))
    expected = reference.predict((X_test - X.mean(axis=0)) / X.std(axis=0) * np.array([1.0, np.sqrt(weight)]))
    np.testing.assert_allclose(model.friction(test), expected, atol=1e-9)
    np.testing.assert_array_equal(model.input_weights_, [1.0, weight])
    assert model.hyperparameters_table()["velocity_weight"] == weight
    assert {row.name: row.value for row in model.parameter_table()}["velocity_weight"] == weight
    isotropic = SVRCurrentModel(**{**FIXED, "n_subset": 3000}).fit(run)  # not optimised: weight 1
    np.testing.assert_array_equal(isotropic.input_weights_, [1.0, 1.0])
    assert np.max(np.abs(isotropic.friction(test) - model.friction(test))) > 0.01


def step_run(seed, n=4000, dt=0.002):
    """A Coulomb step in velocity over a gentle position trend: the kernel must be narrow in v, wide in p."""
    rng = np.random.default_rng(seed)
    t, p, v, a = multisine_motion(rng, n, dt)
    current = J_TRUE * a + 0.8 * np.sign(v) * (1.0 + p / 2000.0) + 0.01 * rng.standard_normal(n)
    return AxisLog(time=t, position=p, effort=current, velocity=v, acceleration=a)


@pytest.mark.filterwarnings("ignore:SVR hyperparameters:UserWarning")  # a pure step: the weight may reach its top
@pytest.mark.slow  # a Bayesian search, > 5 s
def test_a_searched_velocity_weight_narrows_the_kernel_across_the_coulomb_step():
    from greybox.models.kernel.expansion import WEIGHT_BOUNDS

    train = [step_run(1), step_run(2)]
    settings = dict(n_subset=600, n_calls=12, cv_folds=2, cv_blocks=8)
    searched = SVRCurrentModel(velocity_weight=None, **settings).fit(train)
    isotropic = SVRCurrentModel(velocity_weight=1.0, **settings).fit(train)
    assert "velocity_weight" in searched.optimised_ and "velocity_weight" not in isotropic.optimised_
    weight = searched.hyperparameters_table()["velocity_weight"]
    assert 1.0 < weight <= WEIGHT_BOUNDS[1]
    assert all(WEIGHT_BOUNDS[0] <= h["velocity_weight"] <= WEIGHT_BOUNDS[1] for h in searched.search_history_)
    test = step_run(3)
    assert rmse(searched.predict(test), test.current) < 0.8 * rmse(isotropic.predict(test), test.current)


def test_bad_velocity_weights_are_refused():
    from greybox.errors import ParameterError

    run = sweep_run(1, n=500)
    for weight in (0.0, -1.0, float("nan"), "wide"):
        with pytest.raises(ParameterError, match="velocity_weight must be positive"):
            SVRCurrentModel(velocity_weight=weight, optimize=False).fit(run)
    with pytest.raises(ParameterError, match="bounds of 'velocity_weight' must satisfy"):
        SVRCurrentModel(velocity_weight=None, bounds={"velocity_weight": (10.0, 1.0)}).fit(run)
