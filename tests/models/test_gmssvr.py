"""The grey-box model GMS + SVR (residual target by default; eq. 8 with target="current") with a frozen GMS stage."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from svr_runs import RIPPLE_A, SVR_FIXED, gms_run, quick_gms

from greybox.errors import ParameterError
from greybox.models.friction.gms import GMSModel
from greybox.models.gmssvr import GMSSVRModel


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


@pytest.fixture(scope="module")
def fitted():
    train = [gms_run(1), gms_run(2)]
    return GMSSVRModel(gms=quick_gms(), target="current", **SVR_FIXED).fit(train), train


def test_beats_gms_alone_on_position_dependent_friction(fitted):
    model, _ = fitted
    test = gms_run(3)
    gms_error = rmse(model.gms_predict(test), test.current)
    error = rmse(model.predict(test), test.current)
    # The GMS stage misses the ripple (rms 0.21 A); the SVR recovers most of it.
    assert gms_error > 0.8 * RIPPLE_A / np.sqrt(2)
    assert error < 0.5 * gms_error
    np.testing.assert_allclose(model.J_ * test.acceleration + model.friction(test) + model.offset_,
                               model.predict(test), atol=1e-9)


def test_inputs_are_position_gms_current_and_states(fitted):
    model, train = fitted
    n_elements = len(model.gms_.alpha_)
    assert n_elements == 4 - model.gms_.n_pruned_  # elements without stiffness are pruned from the GMS stage
    assert model.input_names == ("position_mm", "gms_current_A") + tuple(f"z{i}_mm" for i in range(1, n_elements + 1))
    assert model.support_vectors_.shape[1] == 2 + n_elements
    z, stick = model.states(train)
    assert z.shape == stick.shape == (sum(len(r) for r in train), n_elements)
    z_gms, stick_gms = model.gms_.states(train)
    np.testing.assert_array_equal(z, z_gms)
    np.testing.assert_array_equal(stick, stick_gms)
    # The SVR stage was trained on standardised inputs: mean and scale of the training columns.
    X = np.concatenate([np.column_stack((r.position, model.gms_.predict(r), model.gms_.states(r)[0]))
                        for r in train])
    np.testing.assert_allclose(model.input_mean_, X.mean(0), rtol=1e-10, atol=1e-12)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_stages_on_different_data_keep_the_gms_frozen():
    first, second = gms_run(4, n=8000), gms_run(5, n=8000)
    model = GMSSVRModel(gms=quick_gms(), **SVR_FIXED).fit_gms(first)
    k_before = model.gms_.k_.copy()
    model.fit_svr(second)
    np.testing.assert_array_equal(model.gms_.k_, k_before)
    assert model.n_samples_fit_ == len(second)

    external = quick_gms().fit(first)
    other = GMSSVRModel(**SVR_FIXED).fit_svr(second, gms=external)
    assert other.gms_ is not external
    np.testing.assert_array_equal(other.gms_.k_, external.k_)
    np.testing.assert_array_equal(other.predict(second), model.predict(second))


def test_incomplete_models_are_refused():
    run = gms_run(6, n=3000)
    with pytest.raises(ParameterError, match="fit_gms"):
        GMSSVRModel(**SVR_FIXED).fit_svr(run)
    with pytest.raises(ParameterError, match="GMSModel"):
        GMSSVRModel(gms="gms", **SVR_FIXED).fit(run)
    half = GMSSVRModel(gms=quick_gms(), **SVR_FIXED).fit_gms(run)
    with pytest.raises(NotFittedError):
        half.predict(run)
    with pytest.raises(NotFittedError):
        GMSSVRModel(**SVR_FIXED).fit_svr(run, gms=GMSModel())


def test_far_from_the_training_data_both_targets_hand_over_to_the_gms_stage(fitted):
    model, train = fitted
    residual = GMSSVRModel(gms=quick_gms(), **SVR_FIXED).fit_svr(train, gms=model.gms_)
    assert residual.target == "residual" and residual.handover  # the defaults
    test = gms_run(3)
    assert rmse(residual.predict(test), test.current) < 0.5 * rmse(model.gms_predict(test), test.current)
    # 10 m away from the travel: the GMS stage alone, whatever the target
    far = test.replace(position=test.position + 1e4)
    np.testing.assert_allclose(residual.predict(far), model.gms_predict(far), atol=1e-9)
    np.testing.assert_allclose(model.predict(far), model.gms_predict(far), atol=1e-9)
    # without the hand-over the kernel terms vanish there: the prediction is I_GMS + intercept,
    # while the "current" target collapses to its intercept alone
    old_residual = GMSSVRModel(gms=quick_gms(), **SVR_FIXED, handover=False).fit_svr(train, gms=model.gms_)
    np.testing.assert_allclose(old_residual.predict(far), model.gms_predict(far) + old_residual.intercept_,
                               atol=1e-9)
    old_current = clone(model).set_params(handover=False).fit_svr(train, gms=model.gms_)
    np.testing.assert_allclose(old_current.predict(far), old_current.intercept_, atol=1e-9)
    # inside the box of the training inputs the hand-over changes nothing
    inside = ~residual.outside_training(test)["inputs"]
    assert inside.mean() > 0.5
    np.testing.assert_array_equal(residual.predict(test)[inside], old_residual.predict(test)[inside])
    np.testing.assert_array_equal(model.predict(test)[inside], old_current.predict(test)[inside])
    with pytest.raises(ParameterError, match="target"):
        GMSSVRModel(target="force", **SVR_FIXED).fit_svr(train, gms=model.gms_)


def _lowest_corner(objective, intervals, n_calls, random_state, progress=None):
    """Stand-in for the Bayesian optimisation that picks the lower end of every interval."""
    point = {name: low for name, (low, _) in intervals.items()}
    return point, [{**point, "objective": objective(point)}]


def test_both_targets_search_the_default_intervals_and_ending_at_an_end_warns(fitted, monkeypatch):
    """No prior narrows the residual target's search (chosen on the family's training runs, docs/svr.md)."""
    from greybox.models.kernel import expansion as kernel

    monkeypatch.setattr(kernel, "minimize_log_uniform", _lowest_corner)
    model, train = fitted
    search = dict(C=3.0, epsilon=0.01, n_subset=200, n_calls=1, cv_folds=2, cv_blocks=4)
    for target in ("residual", "current"):
        fitted_model = GMSSVRModel(**search, target=target)
        with pytest.warns(UserWarning, match="gamma = 0.01 ended at the end"):
            fitted_model.fit_svr(train, gms=model.gms_)
        assert fitted_model.gamma_ == kernel.default_bounds(1.0)["gamma"][0] and fitted_model.at_bounds_ == ["gamma"]
    narrowed = GMSSVRModel(**search, bounds={"gamma": (2.0, 50.0)})
    with pytest.warns(UserWarning, match="gamma = 2 ended at the end"):
        narrowed.fit_svr(train, gms=model.gms_)
    assert narrowed.gamma_ == 2.0
