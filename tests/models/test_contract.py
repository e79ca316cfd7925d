"""The model protocol, checked on every registered model kind (and on a kind added by a test).

One contract for every model: scikit-learn conventions (keyword-only
constructor that only stores its arguments, ``clone``, ``fit`` returns self,
learned attributes end in ``_``, ``score`` is the negative RMSE and model
selection accepts it), model files round-trip to identical predictions,
chunked prediction equals one-shot prediction, the parameter table lists every
identified parameter with a unit, and a log the model was not fitted on
predicts within the kind's bound over the twin's noise floor.

The module runs in the default set: 16 s of training runs, one search start,
and every GMS searched in one pass (``staged=False``: about a seventh of the
staged search's evaluations, at the same test error on the twin); the staged
search is tested in tests/models/friction/test_gms.py.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import cross_validate

from greybox.base import EFFORT, Parameter
from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.metrics import rmse
from greybox.models import registry
from greybox.models.augmented import AugmentedModel
from greybox.models.chunked import predict_chunked
from greybox.models.estimator import CurrentModel
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel
from greybox.models.friction.backlash import BacklashModel
from greybox.twin import make_dataset


def _quick_gms(**options) -> GMSModel:
    """A quick GMS: one start, one search pass."""
    return GMSModel(n_starts=1, max_iter=60, staged=False, **options)


#: Quick settings of every kind a model file may hold (short searches, no Bayesian optimisation).
CASES = {
    "coulomb": lambda: CoulombModel(fit_offset=True),
    "stribeck": lambda: registry.model_class("stribeck")(),
    "stribeck-asymmetric": lambda: registry.model_class("stribeck")(asymmetric=True),
    "lugre": lambda: LuGreModel(n_starts=1, max_iter=60),
    "lugre-asymmetric": lambda: LuGreModel(asymmetric=True, n_starts=1, max_iter=60),
    "gms": lambda: _quick_gms(),
    "gms-asymmetric": lambda: _quick_gms(asymmetric=True),
    "svr": lambda: registry.model_class("svr")(optimize=False, n_subset=300),
    "gmssvr": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300,
                                                     gms=_quick_gms()),
    "gmssvr-current": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300, target="current",
                                                             gms=_quick_gms()),
    "gmssvr-asymmetric": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300,
                                                                gms=_quick_gms(asymmetric=True)),
    "augmented-gms": lambda: AugmentedModel(base=_quick_gms(), refine_shapes=False,
                                            effects=[("thermal_drift", 3.0), ("position_periodic_force", 10.0),
                                                     "inertia_mismatch", "constant_offset"]),
    "augmented-coulomb": lambda: AugmentedModel(base=CoulombModel(), effects=["stribeck", "position_trend"]),
    "backlash-coulomb": lambda: BacklashModel(base=CoulombModel(fit_offset=True)),
    "backlash-gms_asymmetric": lambda: BacklashModel(base=_quick_gms(asymmetric=True),
                                                     width=0.05),
    "augmented-gms_asymmetric": lambda: AugmentedModel(base=_quick_gms(asymmetric=True),
                                                       refine_shapes=False, effects=["constant_offset"]),
}

#: Learned attributes that describe the fit, the data scaling or a nested stage rather than a parameter.
NOT_PARAMETERS = {"effort_unit_", "motion_", "sample_time_", "n_samples_fit_", "cost_", "n_evaluations_", "n_train_",
                  "n_pruned_", "block_", "notes_", "selection_",
                  "cv_rmse_", "optimised_", "at_bounds_", "search_history_", "input_mean_", "input_scale_",
                  "input_weights_", "support_vectors_",
                  "dual_coef_", "gms_", "base_", "effects_", "velocity_scale_mm_s_", "position_range_mm_",
                  "friction_shape_base_", "friction_shape_viscous_", "velocity_range_mm_s_", "input_range_",
                  "effort_range_"}

#: Chunk length [s] that puts chunk boundaries inside motions.
CHUNK_S = 0.77


def _kind_of(case: str) -> str:
    return case.split("-")[0]


def test_every_kind_a_model_file_may_hold_is_covered():
    covered = {_kind_of(case) for case in CASES}
    assert covered == set(registry.MODEL_CLASSES) | set(registry.DERIVED_MODEL_CLASSES)


@pytest.fixture(scope="module")
def train_runs():
    return prepare([make_dataset("X", "A", seed=3, duration_s=10), make_dataset("X", "B", seed=5, duration_s=6)])


@pytest.fixture(scope="module")
def unseen_log():
    return prepare([make_dataset("X", "C", seed=4, duration_s=8, cutting=True)])[0]


@pytest.fixture(scope="module")
def unseen_aircut():
    return prepare([make_dataset("X", "C", seed=4, duration_s=8)])[0]


def noise_floor_A(log) -> float:
    """RMSE [A] of a perfect model on a twin log: the configured current noise and the current's quantisation.

    ``sqrt(std^2 + q^2 / 12)`` from the settings the twin wrote into ``log.attrs`` (AR(1) noise of standard
    deviation ``std``, rounding to steps of ``q``): what no model of the current can explain.
    """
    return float(np.hypot(log.attrs["noise"]["std_A"], log.attrs["sensors"]["current_resolution_A"] / np.sqrt(12)))


def cogging_floor_A(log) -> float:
    """RMS [A] of the twin's cogging current ``a_cog sin(2 pi x / lambda_cog)``: no kind here models it."""
    return log.attrs["plant"]["cogging_A"] / np.sqrt(2)


#: Largest test RMSE of each case on an unseen air cut, as a multiple of :func:`noise_floor_A`, and why the
#: kind cannot come closer. (RMSE over the noise floor equals RE over the floor's RE: one denominator.) Every
#: kind leaves the twin's cogging unexplained, so no bound can lie below sqrt(1 + (cogging / noise)^2) = 1.27.
#: The bounds leave about 15 % over the ratios measured when they were set (static 2.10-2.12, LuGre/GMS
#: 1.42-1.44, GMS+SVR 1.35-1.37, SVR 3.90); a kind that loses the physics its class has lands above its bound
#: (a GMS without pre-sliding is a Coulomb model: 2.1). The SVR stage of GMS+SVR gains only ~5 % on this twin,
#: less than any margin: it is held to beating its own GMS stage instead (the test after this one).
ACCURACY = {
    "coulomb": (2.45, "no pre-sliding and no memory: the current held at dwells and the pre-sliding ramps after "
                      "each reversal are its error"),
    "stribeck": (2.45, "the twin's Stribeck dip is 10 % of its level below 3 mm/s: a static curve, with Coulomb's "
                       "missing pre-sliding and dwells"),
    "stribeck-asymmetric": (2.45, "a static curve per direction: no pre-sliding, no memory, as the symmetric one"),
    "augmented-coulomb": (2.45, "a Stribeck shape and a position trend on a static base: still no pre-sliding"),
    "backlash-coulomb": (2.45, "a backlash band on a static base: the twin has no backlash, so Coulomb's error"),
    "lugre": (1.65, "one bristle: a single pre-sliding stiffness against the twin's 24 elements, and the cogging"),
    "lugre-asymmetric": (1.65, "one bristle per direction; the twin is symmetric, so the symmetric LuGre's error"),
    "gms": (1.65, "a few Maxwell-slip elements for the twin's 24, one search start, and the cogging"),
    "gms-asymmetric": (1.65, "the GMS per direction on a symmetric twin, searched in one pass: as the GMS"),
    "gmssvr": (1.55, "the SVR takes part of the GMS's residual in position and velocity; cogging's 0.4 mm period "
                     "is finer than what 300 support samples resolve"),
    "gmssvr-current": (1.55, "the same SVR fitted to the current instead of the GMS residual: as GMS+SVR"),
    "gmssvr-asymmetric": (1.6, "an asymmetric GMS stage on a symmetric twin under the SVR: as GMS+SVR"),
    "augmented-gms": (2.0, "four effects fitted beside the GMS on 16 s of data, their shapes not refined: the thermal "
                           "drift and the periodic force extrapolate into the unseen run"),
    "augmented-gms_asymmetric": (1.7, "a constant offset beside the asymmetric GMS: the GMS's error"),
    "backlash-gms_asymmetric": (1.85, "a 0.05 mm backlash band the twin does not have delays the GMS's pre-sliding "
                                      "after each reversal"),
    "svr": (4.5, "a function of position and velocity from 300 samples of a 50 mm window, not tuned: no "
                 "pre-sliding, and the unseen run leaves the window"),
}


def test_every_case_has_an_accuracy_bound_above_what_the_twin_allows_with_a_reason(unseen_aircut):
    assert set(ACCURACY) == set(CASES) and all(len(reason) > 40 for _, reason in ACCURACY.values())
    reachable = np.hypot(noise_floor_A(unseen_aircut), cogging_floor_A(unseen_aircut)) / noise_floor_A(unseen_aircut)
    assert 1.2 < reachable < min(bound for bound, _ in ACCURACY.values())


def test_the_noise_floor_is_the_twins_configured_noise(unseen_aircut):
    """The configured floor agrees with the noise the twin drew (the noise-free current against the logged one)."""
    drawn = rmse(unseen_aircut.effort, unseen_aircut.extras["truth_current_A"])
    assert drawn == pytest.approx(noise_floor_A(unseen_aircut), rel=0.1)


@pytest.fixture(scope="module")
def fitted_with_attributes(train_runs):
    """Per case: the model returned by ``fit``, its attribute names before the fit and the template fitted."""
    out = {}
    for case, make in CASES.items():
        template = make()
        before = set(vars(template))
        out[case] = (template.fit(train_runs), before, template)
    return out


@pytest.fixture(scope="module")
def fitted(fitted_with_attributes):
    return {case: returned for case, (returned, _, _) in fitted_with_attributes.items()}


@pytest.mark.parametrize("case", sorted(CASES))
def test_constructor_is_keyword_only_and_only_stores_its_arguments(case):
    model = CASES[case]()
    parameters = list(inspect.signature(type(model).__init__).parameters.values())[1:]
    assert parameters and all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in parameters)
    assert set(vars(model)) == set(model.get_params(deep=False))
    assert not any(name.endswith("_") for name in vars(model))


@pytest.mark.parametrize("case", sorted(CASES))
def test_fit_returns_self_sets_only_underscore_attributes_and_clone_is_unfitted(case, fitted_with_attributes):
    returned, before, template = fitted_with_attributes[case]
    assert returned is template
    added = set(vars(template)) - before
    assert added and all(name.endswith("_") and not name.startswith("_") for name in added)
    copy = clone(returned)
    assert not any(name.endswith("_") for name in vars(copy))
    assert copy.get_params(deep=False).keys() == returned.get_params(deep=False).keys()


@pytest.mark.parametrize("case", sorted(CASES))
def test_model_file_round_trip_predicts_identically(case, fitted, unseen_log, tmp_path):
    model = fitted[case]
    path = save_model(model, tmp_path / "model.gbm")
    loaded = load_model(path)
    assert type(loaded) is type(model)
    np.testing.assert_array_equal(loaded.predict(unseen_log), model.predict(unseen_log))


@pytest.mark.parametrize("case", sorted(CASES))
def test_chunked_prediction_equals_one_shot(case, fitted, unseen_log):
    model = fitted[case]
    np.testing.assert_allclose(predict_chunked(model, unseen_log, chunk_s=CHUNK_S), model.predict(unseen_log),
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("case", sorted(CASES))
def test_unseen_air_cut_is_predicted_within_the_kinds_bound_over_the_noise_floor(case, fitted, unseen_aircut):
    prediction = fitted[case].predict(unseen_aircut)
    assert prediction.shape == unseen_aircut.effort.shape and np.all(np.isfinite(prediction))
    bound, reason = ACCURACY[case]
    ratio = rmse(unseen_aircut.effort, prediction) / noise_floor_A(unseen_aircut)
    assert ratio <= bound, f"{case}: test RMSE {ratio:.2f} times the noise floor, bound {bound} ({reason})"


@pytest.mark.parametrize("case", sorted(case for case in CASES if _kind_of(case) == "gmssvr"))
def test_the_svr_stage_explains_part_of_its_gms_stages_error(case, fitted, unseen_aircut):
    """The SVR corrects the GMS in position and velocity: on an unseen air cut it lowers the GMS stage's RMSE."""
    model = fitted[case]
    assert rmse(unseen_aircut.effort, model.predict(unseen_aircut)) < 0.99 * rmse(
        unseen_aircut.effort, model.gms_.predict(unseen_aircut))

@pytest.mark.parametrize("case", sorted(CASES))
def test_parameter_table_lists_every_identified_parameter_with_a_unit(case, fitted):
    model = fitted[case]
    table = model.parameter_table()
    assert all(isinstance(row, Parameter) for row in table)
    names = [row.name for row in table]
    assert len(names) == len(set(names)) and {"J", "offset"} <= set(names)
    for row in table:
        assert row.unit and EFFORT not in row.unit and row.description, row
        assert np.all(np.isfinite(np.asarray(row.value, dtype=float))), row
    learned = [name for name in vars(model) if name.endswith("_") and not name.startswith("_")]
    missing = [name for name in learned if name not in NOT_PARAMETERS and name[:-1] not in names]
    assert not missing, f"{type(model).__name__} learned {missing} without a row in its parameter table"
    rows = {row.name: row for row in table}
    assert rows["J"].value == model.J_ and rows["J"].unit == "A s^2/mm"


@pytest.mark.parametrize("case", sorted(CASES))
def test_score_is_negative_rmse_and_model_selection_accepts_it(case, fitted, train_runs, unseen_log):
    model = fitted[case]
    assert model.score(unseen_log) == pytest.approx(-rmse(unseen_log.effort, model.predict(unseen_log)), rel=1e-12)
    # scikit-learn's cross-validation fits a clone on one run and scores it on the other with the model's score
    result = cross_validate(CASES[case](), train_runs, cv=[([1], [0])], return_estimator=True)
    held_out = train_runs[0]
    estimator = result["estimator"][0]
    assert estimator is not model and estimator.n_samples_fit_ == len(train_runs[1])
    np.testing.assert_allclose(result["test_score"], [-rmse(held_out.effort, estimator.predict(held_out))],
                               rtol=1e-12)


@pytest.mark.parametrize("case", sorted(CASES))
def test_linear_part_reproduces_the_prediction(case, fitted, unseen_log):
    model = fitted[case]
    part = model.linear_part(unseen_log)
    coefficients = model.linear_coefficients()
    assert part.columns.shape == (len(unseen_log), coefficients.size) == (len(unseen_log), len(part.names))
    np.testing.assert_allclose(part.columns @ coefficients + part.fixed, model.predict(unseen_log),
                               rtol=0, atol=1e-9)


class ViscousModel(CurrentModel):
    """A kind a test adds: inertia + viscous friction, the viscous coefficient fitted by least squares."""

    def __init__(self, *, fit_offset: bool = False):
        self.fit_offset = fit_offset

    def _fit_runs(self, runs, progress):
        a = np.concatenate([run.acceleration for run in runs])
        v = np.concatenate([run.velocity for run in runs])
        columns = [a, v] + ([np.ones_like(v)] if self.fit_offset else [])
        x, *_ = np.linalg.lstsq(np.column_stack(columns), np.concatenate([run.effort for run in runs]), rcond=None)
        self.J_, self.viscous_ = float(x[0]), float(x[1])
        self.offset_ = float(x[2]) if self.fit_offset else 0.0

    def _simulate(self, run, state, sample_time):
        return self.viscous_ * run.velocity, None

    def _n_params(self):
        return 2 + int(self.fit_offset)

    def _own_parameters(self):
        return [Parameter("viscous", self.viscous_, f"{EFFORT} s/mm", "viscous coefficient")]


def test_a_new_kind_is_one_class_and_one_registry_line(monkeypatch, train_runs, unseen_log, tmp_path):
    """Registered, the new kind saves, loads, predicts in chunks, trains from the command line and prints."""
    from greybox.cli import main

    monkeypatch.setitem(registry.MODEL_CLASSES, "added_viscous", ViscousModel)
    model = ViscousModel(fit_offset=True).fit(train_runs)
    loaded = load_model(save_model(model, tmp_path / "v.gbm"))
    np.testing.assert_array_equal(loaded.predict(unseen_log), model.predict(unseen_log))
    np.testing.assert_allclose(predict_chunked(model, unseen_log, chunk_s=CHUNK_S), model.predict(unseen_log),
                               rtol=0, atol=1e-12)
    logs = [tmp_path / f"run{index}.parquet" for index in range(len(train_runs))]
    for run, path in zip(train_runs, logs):
        write_log(run, path)
    out = tmp_path / "cli.gbm"
    assert main(["train", "--model", "added_viscous", "--offset", "--quiet", "--train", *map(str, logs),
                 "--out", str(out)]) == 0
    assert isinstance(load_model(out), ViscousModel)


@pytest.mark.parametrize("case", sorted(CASES))
def test_staged_fit_on_the_same_runs_is_the_fit(case, fitted, train_runs, unseen_log, monkeypatch):
    model = CASES[case]()
    stage = model.first_stage()
    assert stage is None or (isinstance(stage, CurrentModel) and not any(n.endswith("_") for n in vars(stage)))
    if stage is None:
        # one stage: the staged fit is the fit (spied on, not repeated), and a second set of runs is refused
        calls = []
        monkeypatch.setattr(model, "fit", lambda logs, progress=None: calls.append(logs) or model)
        assert model.fit_staged(train_runs) is model and calls == [train_runs]
        with pytest.raises(GreyboxError, match="one stage"):
            CASES[case]().fit_staged(train_runs[:1], train_runs[1:])
    else:
        staged = model.fit_staged(train_runs)
        np.testing.assert_array_equal(staged.predict(unseen_log), fitted[case].predict(unseen_log))


@pytest.mark.parametrize("case", sorted(CASES))
def test_fit_summary_reports_the_data_and_the_search(case, fitted, train_runs):
    summary = fitted[case].fit_summary()
    assert summary["n_samples"] == sum(len(run) for run in train_runs)
    assert summary["sample_time_s"] == pytest.approx(0.002)
    if hasattr(fitted[case], "cv_rmse_"):
        assert "optimised" in summary and "cv_rmse_A" in summary
