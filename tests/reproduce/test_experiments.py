"""Tests of the paper's experiments as data and of running them on (short) synthetic logs."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.io import write_log
from greybox.data.prepare import prepare, trim
from greybox.errors import GreyboxError, Setting, SettingWarning
from greybox.evaluate.records import NOISE_FLOOR
from greybox.evaluate.report import svr_generalisation
from greybox.metrics import rmse
from greybox.models.files import load_model
from greybox.reproduce.experiments import (
    EXPERIMENTS,
    MODEL_SETTINGS,
    Experiment,
    ModelSpec,
    find_log,
    load_axis_logs,
    reproduce,
    run_experiments,
)
from greybox.twin import make_dataset

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

#: Fast model settings for the tests: few GMS starts, fixed (default) SVR hyperparameters.
FAST = {
    "coulomb": {},
    "stribeck": {},
    "lugre": {"n_starts": 1, "max_iter": 60},
    "gms": {"n_starts": 1, "max_iter": 60},
    "svr": {"optimize": False, "n_subset": 200},
    "gmssvr": {"target": "residual", "optimize": False, "n_subset": 200, "gms": {"n_starts": 1, "max_iter": 60}},
}


def short_logs(axis="X", seed=5, seconds=12.0):
    """Raw synthetic logs A-D of ``seconds`` each (B and D cut to their first ``seconds``)."""
    return {d: trim(make_dataset(axis, d, seed=seed, duration_s=seconds), stop_s=seconds) for d in "ABCD"}


@pytest.fixture(scope="module")
def logs():
    return {d: prepare(log)[0] for d, log in short_logs().items()}


@pytest.fixture(scope="module")
def results(logs):
    return run_experiments(logs, "X", settings=FAST)


# ---------------------------------------------------------------- definitions
def test_experiments_follow_the_paper():
    first, second = EXPERIMENTS
    assert (first.number, first.paper_table, first.test) == (1, "Table 3", ("C",))
    assert {"stribeck", "svr", "gms"} <= {spec.kind for spec in first.models}
    assert all(spec.train == ("A",) and not spec.stage2 for spec in first.models)
    assert (second.number, second.paper_table, second.test) == (2, "Table 4", ("C", "D"))
    by_name = {spec.name: spec for spec in second.models}
    assert set(by_name) == {"stribeck", "gms", "svr", "gmssvr", "gmssvr_eq8"}
    for name in ("stribeck", "gms", "svr"):
        assert by_name[name].train == ("A", "B") and not by_name[name].stage2
    for name in ("gmssvr", "gmssvr_eq8"):
        assert by_name[name].kind == "gmssvr"
        assert (by_name[name].train, by_name[name].stage2) == (("A",), ("B",))
        assert by_name[name].training == "GMS on A, SVR on B"
    assert by_name["gmssvr_eq8"].params["target"] == "current"  # the paper's eq. 8 as printed
    assert second.datasets == ("A", "B", "C", "D") and second.train == ("A", "B")


# ---------------------------------------------------------------- reading logs
def test_find_and_load_axis_logs(tmp_path):
    raw = short_logs(seconds=4.0)
    for d, log in raw.items():
        write_log(log, tmp_path / f"X_{d}.mcap")
    (tmp_path / "X_A.csv").write_text("not read: MCAP comes first\n")
    assert find_log(tmp_path, "X", "A") == tmp_path / "X_A.mcap"
    with pytest.raises(GreyboxError, match="Y_A"):
        find_log(tmp_path, "Y", "A")
    with pytest.raises(GreyboxError, match="does not exist"):
        find_log(tmp_path / "missing", "X", "A")
    loaded = load_axis_logs(tmp_path, "X", "AC", max_duration_s=2.0)
    assert list(loaded) == ["A", "C"]
    for d, log in loaded.items():
        assert log.is_prepared and log.duration <= 2.0 + 1e-9
        np.testing.assert_allclose(log.effort, raw[d].effort[: len(log)], atol=1e-3)  # 1 mA resolution
        assert "truth_current_A" in log.extras


# ---------------------------------------------------------------- running
def test_records_agree_with_the_models_predictions(results, logs):
    for experiment in EXPERIMENTS:
        fitted = results.experiments[experiment.number]
        assert [m.spec for m in fitted] == list(experiment.models)
        for result in fitted:
            for dataset, names in (("train", result.spec.fitted_on), ("test", experiment.test)):
                (record,) = [r for r in results.records if (r["experiment"], r["model"], r["dataset"])
                             == (experiment.number, result.name, dataset)]
                runs = [logs[d] for d in names]
                measured = np.concatenate([run.effort for run in runs])
                assert record["logs"] == "+".join(names) and record["n"] == measured.size
                assert record["rmse"] == pytest.approx(rmse(measured, result.model.predict(runs)), rel=1e-12)
                assert record["re"] == pytest.approx(100 * record["rmse"] / np.mean(np.abs(measured)))
                assert set(record["per_log"]) == set(names)


def test_noise_floor_is_the_logged_noise(results, logs):
    for experiment in EXPERIMENTS:
        (record,) = [r for r in results.records if (r["experiment"], r["model"], r["dataset"])
                     == (experiment.number, NOISE_FLOOR, "test")]
        # make_dataset keeps the noise on its own channel: the truth's error is exactly its RMS
        # (up to the 1 mA quantisation of the logged current).
        noise = np.concatenate([logs[d].extras["truth_noise_A"] for d in experiment.test])
        assert record["rmse"] == pytest.approx(np.sqrt(np.mean(noise**2)), rel=0.02)


def test_gmssvr_reuses_the_gms_stage_identified_on_a(results, logs):
    gms_on_a = results.experiments[1][[m.name for m in results.experiments[1]].index("gms")].model
    for number in (1, 2):
        (gmssvr,) = [m for m in results.experiments[number] if m.name == "gmssvr"]
        np.testing.assert_array_equal(gmssvr.model.gms_.k_, gms_on_a.k_)
        np.testing.assert_array_equal(gmssvr.model.gms_.alpha_, gms_on_a.alpha_)
    (two_step,) = [m for m in results.experiments[2] if m.name == "gmssvr"]
    assert two_step.model.n_samples_fit_ == len(logs["B"])  # the SVR stage saw B only
    rows = [(h["experiment"], h["model"]) for h in results.hyperparameters]
    assert rows == [(1, "svr"), (1, "gmssvr"), (2, "svr"), (2, "gmssvr"), (2, "gmssvr_eq8")]


def test_model_params_override_the_settings_of_their_kind(results):
    by_name = {m.name: m for m in results.experiments[2]}
    assert by_name["gmssvr"].model.target == "residual"  # the settings of the kind
    assert by_name["gmssvr_eq8"].model.target == "current"  # the spec's own params
    assert by_name["gmssvr_eq8"].model.n_subset == FAST["gmssvr"]["n_subset"]
    assert by_name["gmssvr_eq8"].fit_seconds > 0  # a different model: not a shared fit


def test_svr_generalisation_is_computed_from_the_runs_records(results):
    for entry in svr_generalisation(results.records):
        train = [r for r in results.records if (r["experiment"], r["model"], r["dataset"])
                 == (entry["experiment"], "svr", "train")][0]
        assert entry["train_re"] == train["re"]
        assert entry["loses_accuracy_on"] == [log for log, re in entry["test_re"].items() if re > train["re"]]


def _lowest_corner(objective, intervals, **kwargs):
    """Stand-in for the Bayesian optimisation that picks the lower end of every interval."""
    point = {name: low for name, (low, _) in intervals.items()}
    return point, [{**point, "objective": objective(point)}]


def test_a_fits_warning_reaches_progress_with_the_settings_it_names(logs, monkeypatch):
    from greybox.models.kernel import expansion

    monkeypatch.setattr(expansion, "minimize_log_uniform", _lowest_corner)
    one = (Experiment(1, "train on A, test on C", "Table 3", (ModelSpec("svr", ("A",)),), ("C",)),)
    items = []
    result = run_experiments({d: logs[d] for d in "AC"}, "X", one, progress=items.append,
                             settings={"svr": {**FAST["svr"], "optimize": True, "n_calls": 1}})
    (note,) = [item for item in items if isinstance(item, Warning)]
    assert isinstance(note, SettingWarning) and "ended at the end of its search interval" in str(note)
    assert [part.name for part in note.parts if isinstance(part, Setting)] == ["bounds"]
    assert result.experiments[1][0].notes == [str(note)]  # the report keeps the text


def test_missing_dataset_is_reported():
    logs = {d: None for d in "ABC"}
    with pytest.raises(GreyboxError, match="dataset.*D"):
        run_experiments(logs, "X", settings=FAST)


def test_reproduce_writes_the_report_and_model_files(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    for axis in ("X", "Y"):
        for d, log in short_logs(axis, seconds=6.0).items():
            write_log(log, data / f"{axis}_{d}.mcap")
    one = (Experiment(1, "train on A, test on C", "Table 3",
                      (ModelSpec("stribeck", ("A",)), ModelSpec("gmssvr", ("A",), ("B",))), ("C",)),)
    lines = []
    out = tmp_path / "report"
    result = reproduce(out, data, experiments=one, settings=FAST, jobs=2, progress=lines.append)
    names = {p.name for p in out.iterdir()}
    assert {"metrics.json", "metrics.csv", "tables.md", "index.html", "models", "exp1_error_boxplot.png",
            "exp1_time_X.png", "exp1_time_Y.png", "exp1_residual_position_Y.png"} <= names
    assert any(isinstance(line, str) and line.startswith("axis Y, experiment 1: gmssvr")
               for line in lines)  # from the worker process
    assert [(r["axis"], r["model"], r["dataset"]) for r in result.records] == [
        (axis, model, dataset) for axis in ("X", "Y") for model in ("stribeck", "gmssvr", NOISE_FLOOR)
        for dataset in ("train", "test")]
    for path in result.files["models"]:
        experiment, axis, model = path.stem.split("_")
        (fitted,) = [m.model for m in result.results[("X", "Y").index(axis)].experiments[1] if m.name == model]
        test = result.results[0].logs["C"] if axis == "X" else result.results[1].logs["C"]
        np.testing.assert_array_equal(load_model(path).predict(test), fitted.predict(test))


@pytest.mark.slow  # end to end, real fits with Bayesian optimisation: 5-10 s on 2 cores
def test_gmssvr_beats_gms_and_stribeck_on_c_and_d():
    """Experiment 2 on shortened logs (A, C: 20 s; D: its first 25 s; B whole), with real fits:
    Bayesian optimisation of the SVR stage included. The synthetic axis has a position-dependent
    friction that neither GMS nor Stribeck can represent; the grey-box model must capture it."""
    raw = {"A": make_dataset("X", "A", seed=1, duration_s=20.0), "B": make_dataset("X", "B", seed=1),
           "C": make_dataset("X", "C", seed=1, duration_s=20.0), "D": trim(make_dataset("X", "D", seed=1), stop_s=25.0)}
    logs = {d: prepare(log)[0] for d, log in raw.items()}
    settings = {"stribeck": {}, "gms": {"n_starts": 2},
                "gmssvr": {**MODEL_SETTINGS["gmssvr"], "n_subset": 500, "n_calls": 8, "gms": {"n_starts": 2}}}
    experiment = Experiment(2, "shortened", "Table 4", tuple(s for s in EXPERIMENTS[1].models
                                                            if s.name in ("stribeck", "gms", "gmssvr")), ("C", "D"))
    results = run_experiments(logs, "X", [experiment], settings=settings)
    test = {r["model"]: r for r in results.records if r["dataset"] == "test"}
    assert test["gmssvr"]["re"] < test["gms"]["re"] < test["stribeck"]["re"]
    for log in ("C", "D"):
        assert test["gmssvr"]["per_log"][log]["re"] < test["gms"]["per_log"][log]["re"]
    assert test["gmssvr"]["re"] > test[NOISE_FLOOR]["re"]  # no model beats the noise on average
