"""The model protocol, checked on every registered model kind (and on a kind added by a test).

One contract for every model: scikit-learn conventions (keyword-only
constructor that only stores its arguments, ``clone``, ``fit`` returns self,
learned attributes end in ``_``, ``score`` is the negative RMSE and model
selection accepts it), model files round-trip to identical predictions,
chunked prediction equals one-shot prediction, the parameter table lists every
identified parameter with a unit, and a log the model was not fitted on
predicts.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import cross_val_score

from greybox.base import EFFORT, Parameter
from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.evaluate.records import TRUTH_CHANNEL
from greybox.metrics import relative_error
from greybox.models import registry
from greybox.models.augmented import AugmentedModel
from greybox.models.chunked import predict_chunked
from greybox.models.estimator import CurrentModel
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel
from greybox.models.friction.backlash import BacklashModel
from greybox.twin import make_dataset

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

#: Quick settings of every kind a model file may hold (short searches, no Bayesian optimisation).
CASES = {
    "coulomb": lambda: CoulombModel(fit_offset=True),
    "stribeck": lambda: registry.model_class("stribeck")(),
    "stribeck-asymmetric": lambda: registry.model_class("stribeck")(asymmetric=True),
    "lugre": lambda: LuGreModel(n_starts=1, max_iter=60),
    "lugre-asymmetric": lambda: LuGreModel(asymmetric=True, n_starts=1, max_iter=60),
    "gms": lambda: GMSModel(n_starts=1, max_iter=60),
    "gms-asymmetric": lambda: GMSModel(asymmetric=True, n_starts=1, max_iter=60),
    "svr": lambda: registry.model_class("svr")(optimize=False, n_subset=300),
    "gmssvr": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300,
                                                     gms=GMSModel(n_starts=1, max_iter=60)),
    "gmssvr-current": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300, target="current",
                                                             gms=GMSModel(n_starts=1, max_iter=60)),
    "gmssvr-asymmetric": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300,
                                                                gms=GMSModel(asymmetric=True, n_starts=1, max_iter=60)),
    "augmented-gms": lambda: AugmentedModel(base=GMSModel(n_starts=1, max_iter=60), refine_shapes=False,
                                            effects=[("thermal_drift", 3.0), ("position_periodic_force", 10.0),
                                                     "inertia_mismatch", "constant_offset"]),
    "augmented-coulomb": lambda: AugmentedModel(base=CoulombModel(), effects=["stribeck", "position_trend"]),
    "backlash-coulomb": lambda: BacklashModel(base=CoulombModel(fit_offset=True)),
    "backlash-gms_asymmetric": lambda: BacklashModel(base=GMSModel(asymmetric=True, n_starts=1, max_iter=60),
                                                     width=0.05),
    "augmented-gms_asymmetric": lambda: AugmentedModel(base=GMSModel(asymmetric=True, n_starts=1, max_iter=60),
                                                       refine_shapes=False, effects=["constant_offset"]),
}

#: Learned attributes that describe the fit, the data scaling or a nested stage rather than a parameter.
NOT_PARAMETERS = {"effort_unit_", "motion_", "sample_time_", "n_samples_fit_", "cost_", "n_evaluations_", "n_train_",
                  "n_pruned_", "notes_", "selection_",
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


#: Largest test RE of each kind on an unseen air cut, as a multiple of the noise floor's RE (the noise-free
#: current against the measured one: the best any model can do), and why the kind cannot come closer. The
#: kinds measured 83-90 % of their class's bound when the bounds were set (static 2.14-2.16, dynamic
#: 1.37-1.62, augmented 1.77, SVR 3.96); a kind that loses its physics lands well above its bound.
ACCURACY = {
    "static": (2.6, "no pre-sliding and no memory: the current held at dwells and the pre-sliding ramps after "
                    "each reversal are its error"),
    "dynamic": (1.8, "pre-sliding and dwells represented; what is left is the motor's cogging (part of the "
                     "noise-free current, no model here has it) and a short, quick search"),
    "augmented": (2.1, "four effects fitted beside the GMS on 16 s of data, their shapes not refined: the thermal "
                       "drift and the periodic force extrapolate into the unseen run"),
    "svr": (4.5, "a function of position and velocity from 300 samples of a 50 mm window, not tuned: no "
                 "pre-sliding, and the unseen run leaves the window"),
}
#: The accuracy class of each case.
ACCURACY_CLASS = {"coulomb": "static", "stribeck": "static", "stribeck-asymmetric": "static",
                  "augmented-coulomb": "static", "backlash-coulomb": "static", "svr": "svr",
                  "augmented-gms": "augmented"}


def test_every_case_has_an_accuracy_bound_with_a_reason():
    classes = {ACCURACY_CLASS.get(case, "dynamic") for case in CASES}
    assert classes <= set(ACCURACY) and all(len(reason) > 40 for _, reason in ACCURACY.values())
    assert all(case in CASES for case in ACCURACY_CLASS)


@pytest.fixture(scope="module")
def fitted(train_runs):
    return {case: make().fit(train_runs) for case, make in CASES.items()}


@pytest.mark.parametrize("case", sorted(CASES))
def test_constructor_is_keyword_only_and_only_stores_its_arguments(case):
    model = CASES[case]()
    parameters = list(inspect.signature(type(model).__init__).parameters.values())[1:]
    assert parameters and all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in parameters)
    assert set(vars(model)) == set(model.get_params(deep=False))
    assert not any(name.endswith("_") for name in vars(model))


@pytest.mark.parametrize("case", sorted(CASES))
def test_fit_returns_self_sets_only_underscore_attributes_and_clone_is_unfitted(case, train_runs, fitted):
    template = CASES[case]()
    before = set(vars(template))
    assert template.fit(train_runs) is template
    added = set(vars(template)) - before
    assert added and all(name.endswith("_") and not name.startswith("_") for name in added)
    copy = clone(fitted[case])
    assert not any(name.endswith("_") for name in vars(copy))
    assert copy.get_params(deep=False).keys() == fitted[case].get_params(deep=False).keys()


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
def test_unseen_log_predicts_a_finite_current_close_to_the_measurement(case, fitted, unseen_log):
    prediction = fitted[case].predict(unseen_log)
    assert prediction.shape == unseen_log.effort.shape and np.all(np.isfinite(prediction))
    # every kind explains a good part of the current of an air-cut-like log it was not fitted on
    assert np.std(unseen_log.effort - prediction) < np.std(unseen_log.effort)


@pytest.mark.parametrize("case", sorted(CASES))
def test_unseen_air_cut_is_predicted_within_the_kinds_bound_over_the_noise_floor(case, fitted, unseen_aircut):
    floor = relative_error(unseen_aircut.effort, unseen_aircut.extras[TRUTH_CHANNEL])
    bound, reason = ACCURACY[ACCURACY_CLASS.get(case, "dynamic")]
    ratio = relative_error(unseen_aircut.effort, fitted[case].predict(unseen_aircut)) / floor
    assert ratio <= bound, f"{case}: test RE {ratio:.2f} times the noise floor's, bound {bound} ({reason})"


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
    rmse = np.sqrt(np.mean((model.predict(unseen_log) - unseen_log.effort) ** 2))
    assert model.score(unseen_log) == pytest.approx(-rmse, rel=1e-12)
    scores = cross_val_score(CASES[case](), train_runs, cv=2)
    folds = [(train_runs[1], train_runs[0]), (train_runs[0], train_runs[1])]  # KFold(2) on the two runs
    held_out = [-np.sqrt(np.mean((CASES[case]().fit([fit]).predict(test) - test.effort) ** 2)) for fit, test in folds]
    np.testing.assert_allclose(scores, held_out, rtol=1e-9)


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
def test_staged_fit_on_the_same_runs_is_the_fit(case, fitted, train_runs, unseen_log):
    model = CASES[case]()
    stage = model.first_stage()
    assert stage is None or (isinstance(stage, CurrentModel) and not any(n.endswith("_") for n in vars(stage)))
    staged = model.fit_staged(train_runs)
    np.testing.assert_array_equal(staged.predict(unseen_log), fitted[case].predict(unseen_log))
    if stage is None:
        with pytest.raises(GreyboxError, match="one stage"):
            CASES[case]().fit_staged(train_runs[:1], train_runs[1:])


@pytest.mark.parametrize("case", sorted(CASES))
def test_fit_summary_reports_the_data_and_the_search(case, fitted, train_runs):
    summary = fitted[case].fit_summary()
    assert summary["n_samples"] == sum(len(run) for run in train_runs)
    assert summary["sample_time_s"] == pytest.approx(0.002)
    if hasattr(fitted[case], "cv_rmse_"):
        assert "optimised" in summary and "cv_rmse_A" in summary
