"""95 % parameter intervals (greybox.identify.intervals): coverage on simulated data of known parameters,
shrinking with more data, flags for what the data cannot determine, every model kind, model files."""

from __future__ import annotations

import json
import re
import zipfile

import numpy as np
import pytest
from model_files import write_members
from scipy.signal import lfilter

import greybox.cli as cli
from greybox.base import Parameter
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.errors import ModelFileError
from greybox.identify.intervals import attach_intervals, cluster_covariance, cluster_labels, parameter_intervals
from greybox.models import registry
from greybox.models.augmented import AugmentedModel
from greybox.models.estimator import CurrentModel
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.twin import make_dataset

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

#: Truth of the linear-in-parameters simulation: J [A s^2/mm], Coulomb level [A], viscous [A s/mm].
TRUTH = {"J": 2e-3, "coulomb_pos": 0.8, "viscous_pos": 0.01}
STEP = 0.002


def _noise(rng, n: int, sd: float = 0.05, pole: float = 0.98) -> np.ndarray:
    """AR(1) noise [A]: strongly autocorrelated, as the residuals of an axis log are (time constant 0.1 s)."""
    shocks = rng.normal(0.0, sd, n)
    shocks[0] /= np.sqrt(1.0 - pole**2)  # stationary from the first sample
    return lfilter([1.0], [1.0, -pole], shocks)


def _coulomb_run(seed: int, n: int = 10_000, *, velocity=None) -> AxisLog:
    """A run whose effort is inertia + Coulomb + viscous friction of its motion plus AR(1) noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * STEP
    if velocity is None:
        velocity = 30.0 * np.sin(2 * np.pi * 0.5 * t) + 10.0 * np.sin(2 * np.pi * 1.3 * t)
    acceleration = np.gradient(velocity, STEP)
    effort = (TRUTH["J"] * acceleration + TRUTH["coulomb_pos"] * np.sign(velocity) + TRUTH["viscous_pos"] * velocity
              + _noise(rng, n))
    return AxisLog(time=t, position=np.cumsum(velocity) * STEP, effort=effort, velocity=velocity,
                   acceleration=acceleration)


def _intervals(run, **options) -> dict:
    model = CoulombModel().fit(run)
    return parameter_intervals(model, run, **options)["rows"]


def _coverage(n_seeds: int, **options) -> dict:
    hits = {name: 0 for name in TRUTH}
    for seed in range(n_seeds):
        rows = _intervals(_coulomb_run(seed), **options)
        for name, value in TRUTH.items():
            hits[name] += rows[name]["lower"] <= value <= rows[name]["upper"]
    return {name: count / n_seeds for name, count in hits.items()}


def test_intervals_cover_the_true_parameters_in_about_95_percent_of_seeds():
    coverage = _coverage(200)
    # 200 seeds: the binomial standard error of a 95 % coverage is 1.5 points
    for name, share in coverage.items():
        assert 0.89 <= share <= 0.99, (name, coverage)


def test_intervals_that_ignore_the_autocorrelation_would_not_cover():
    # one cluster per sample (an independent-sample sandwich) on AR(1) noise: far too narrow
    coverage = _coverage(40, n_blocks=10_000)
    assert min(coverage.values()) < 0.6, coverage


def test_intervals_shrink_as_one_over_the_square_root_of_the_data():
    def width(n):
        rows = [_intervals(_coulomb_run(seed, n)) for seed in range(6)]
        return {name: np.mean([r[name]["upper"] - r[name]["lower"] for r in rows]) for name in TRUTH}

    short, long = width(8_000), width(32_000)
    for name in TRUTH:
        assert 0.35 < long[name] / short[name] < 0.7, (name, long[name] / short[name])  # 1/sqrt(4) = 0.5


def test_inertia_of_runs_at_constant_speed_is_flagged_not_identifiable():
    runs = [_coulomb_run(seed, 3_000, velocity=np.full(3_000, speed))
            for seed, speed in enumerate((5.0, -5.0, 20.0, -20.0, 40.0, -40.0))]
    model = attach_intervals(CoulombModel().fit(runs), runs)
    rows = {row.name: row for row in model.parameter_table()}
    assert rows["J"].flag == "not identifiable" and np.isnan(rows["J"].lower)
    assert rows["coulomb_pos"].flag == "" and rows["coulomb_pos"].lower < 0.8 < rows["coulomb_pos"].upper


def test_stribeck_velocity_without_low_speed_data_is_flagged():
    t = np.arange(20_000) * STEP
    velocity = np.sign(np.sin(2 * np.pi * 0.25 * t)) * (60.0 + 20.0 * np.sin(2 * np.pi * 1.1 * t))  # |v| >= 40 mm/s
    rng = np.random.default_rng(0)
    effort = (np.sign(velocity) * (0.8 + 0.6 * np.exp(-np.abs(velocity) / 2.0)) + 0.01 * velocity
              + _noise(rng, t.size, sd=0.02))
    run = AxisLog(time=t, position=np.cumsum(velocity) * STEP, effort=effort, velocity=velocity,
                  acceleration=np.zeros(t.size))
    model = attach_intervals(StribeckModel().fit(run), run)
    rows = {row.name: row for row in model.parameter_table()}
    assert rows["v_s"].flag in ("not identifiable", "poorly determined"), rows["v_s"]
    assert rows["v_s"].flag == "not identifiable" or rows["v_s"].upper > 10.0 * rows["v_s"].lower


def test_stribeck_velocity_with_low_speed_data_is_determined_and_covered():
    t = np.arange(20_000) * STEP
    velocity = 30.0 * np.sin(2 * np.pi * 0.5 * t)
    effort = (np.sign(velocity) * (0.8 + 0.6 * np.exp(-np.abs(velocity) / 2.0)) + 0.01 * velocity
              + _noise(np.random.default_rng(1), t.size, sd=0.02))
    run = AxisLog(time=t, position=np.cumsum(velocity) * STEP, effort=effort, velocity=velocity,
                  acceleration=np.gradient(velocity, STEP))
    model = attach_intervals(StribeckModel().fit(run), run)
    rows = {row.name: row for row in model.parameter_table()}
    assert rows["v_s"].flag == "" and rows["v_s"].lower < 2.0 < rows["v_s"].upper
    assert 0.0 < rows["v_s"].lower and rows["v_s"].upper < 4.0


def test_inertia_held_at_its_bound_is_flagged():
    run = _coulomb_run(0)
    run = run.replace(effort=run.effort - 2.0 * TRUTH["J"] * run.acceleration)  # a negative inertia: J = 0 fitted
    model = attach_intervals(CoulombModel().fit(run), run)
    row = {row.name: row for row in model.parameter_table()}["J"]
    assert model.J_ == 0.0 and row.flag == "at bound" and row.lower == 0.0


def test_equal_elements_of_a_gms_model_are_not_separately_identifiable():
    # two elements of equal fraction follow the same trajectory: only the sum of their stiffnesses shows
    runs = prepare([make_dataset("X", "A", seed=3, duration_s=6)])
    model = GMSModel(n_elements=2, n_starts=1, max_iter=30).fit(runs)
    # two equal elements made from the first the fit kept (the pre-sliding limits of the data may prune one)
    model.alpha_, model.k_ = np.array([0.5, 0.5]), np.full(2, model.k_[0])
    rows = {row.name: row for row in attach_intervals(model, runs).parameter_table()}
    assert rows["k"].flag == "not identifiable" and np.all(np.isnan(rows["k"].lower))
    assert rows["J"].flag != "not identifiable"


def test_bootstrap_agrees_with_the_sandwich_on_a_linear_model():
    run = _coulomb_run(3)
    sandwich = _intervals(run)
    bootstrap = _intervals(run, method="bootstrap", n_bootstrap=200)
    for name in TRUTH:
        ratio = (bootstrap[name]["upper"] - bootstrap[name]["lower"]) / (sandwich[name]["upper"]
                                                                        - sandwich[name]["lower"])
        assert 0.7 < ratio < 1.4, (name, ratio)


def test_jackknife_covariance_is_that_of_refits_leaving_each_cluster_out():
    # linear least squares: leaving cluster g out moves the estimate by exactly -(A - A_g)^-1 X_g' r_g
    rng = np.random.default_rng(0)
    x = rng.normal(size=(600, 3))
    y = x @ np.array([1.0, -2.0, 0.5]) + rng.normal(size=600)
    labels = np.repeat(np.arange(12), 50)
    estimate = np.linalg.lstsq(x, y, rcond=None)[0]
    moves = np.array([np.linalg.lstsq(x[labels != g], y[labels != g], rcond=None)[0] - estimate
                      for g in range(12)])
    covariance, null, carried = cluster_covariance(x, y - x @ estimate, labels)
    np.testing.assert_allclose(covariance, 11 / 12 * moves.T @ moves, rtol=1e-9)
    assert null.shape == (3, 0) and carried.shape == (3, 0)
    plain, _, _ = cluster_covariance(x, y - x @ estimate, labels, jackknife=False)
    inverse = np.linalg.inv(x.T @ x)
    scores = np.array([x[labels == g].T @ (y - x @ estimate)[labels == g] for g in range(12)])
    np.testing.assert_allclose(plain, 12 / 11 * inverse @ scores.T @ scores @ inverse, rtol=1e-9)


def test_a_direction_the_data_do_not_determine_is_the_null_space():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(400, 2))
    x = np.column_stack((x, x[:, 0] + x[:, 1]))  # the third column repeats the sum of the first two
    covariance, null, _ = cluster_covariance(x, rng.normal(size=400), np.repeat(np.arange(10), 40))
    assert null.shape == (3, 1)
    np.testing.assert_allclose(np.abs(null[:, 0]), np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0), rtol=1e-9)
    np.testing.assert_allclose(covariance @ null, 0.0, atol=1e-12)


def test_a_parameter_that_only_one_cluster_determines_gets_no_interval():
    # runs as clusters, and only one of the 24 runs accelerates: nothing else tells the inertia
    runs = [_coulomb_run(seed, 1_000, velocity=np.full(1_000, (10.0 + seed) * (-1) ** seed)) for seed in range(23)]
    runs.append(_coulomb_run(99, 1_000))
    model = attach_intervals(CoulombModel().fit(runs), runs)
    assert model.parameter_intervals_["clusters"] == "runs"
    rows = {row.name: row for row in model.parameter_table()}
    assert rows["J"].flag == "poorly determined: rests on one run or block" and np.isnan(rows["J"].lower)
    assert rows["coulomb_pos"].flag == "" and rows["viscous_pos"].flag == ""


def test_clusters_are_whole_runs_when_there_are_many_else_time_blocks():
    many = cluster_labels([100] * 30, n_params=3)
    assert many.max() == 29 and np.all(many[:100] == 0)
    few = cluster_labels([1000, 3000], n_params=3)
    assert few.max() + 1 == 40 and np.all(np.diff(few) >= 0)
    assert cluster_labels([1000, 3000], n_params=30).max() + 1 == 60  # twice the parameters


def test_slowly_decorrelating_residuals_get_longer_blocks():
    rng = np.random.default_rng(0)
    slow = _noise(rng, 20_000, pole=0.999)  # correlation length 1000 samples
    labels = cluster_labels([20_000], n_params=3, residuals=slow)
    assert labels.max() + 1 == 6  # raised from 2 (ten correlation lengths each) to twice the parameters


# ------------------------------------------------------------------ every model kind
CASES = {
    "coulomb": lambda: CoulombModel(fit_offset=True),
    "stribeck": lambda: StribeckModel(asymmetric=True),
    "lugre": lambda: LuGreModel(n_starts=1, max_iter=60),
    "gms": lambda: GMSModel(asymmetric=True, n_starts=1, max_iter=60),
    "svr": lambda: registry.model_class("svr")(optimize=False, n_subset=300),
    "gmssvr": lambda: registry.model_class("gmssvr")(optimize=False, n_subset=300,
                                                     gms=GMSModel(n_starts=1, max_iter=60)),
    "augmented": lambda: AugmentedModel(base=CoulombModel(), effects=["stribeck", "position_trend"]),
    "backlash": lambda: BacklashModel(base=CoulombModel(fit_offset=True)),
}


#: Cases that take more than a few seconds (a GMS search).
SLOW = ("gms", "gmssvr")


def test_every_kind_is_covered():
    assert set(CASES) == set(registry.MODEL_CLASSES) | set(registry.DERIVED_MODEL_CLASSES)


@pytest.fixture(scope="module")
def train_runs():
    return prepare([make_dataset("X", "A", seed=3, duration_s=10), make_dataset("X", "B", seed=5, duration_s=6)])


@pytest.mark.parametrize("case", [pytest.param(case, marks=pytest.mark.slow) if case in SLOW else case
                                  for case in sorted(CASES)])
def test_every_row_of_every_kind_has_an_interval_or_a_flag_and_survives_the_model_file(case, train_runs, tmp_path):
    model = attach_intervals(CASES[case]().fit(train_runs), train_runs)
    table = model.parameter_table()
    for row in table:
        value = np.asarray(row.value, dtype=float)
        lower, upper = np.asarray(row.lower, dtype=float), np.asarray(row.upper, dtype=float)
        assert lower.shape == upper.shape == value.shape, row
        missing = np.isnan(lower)
        assert np.array_equal(missing, np.isnan(upper)) and (row.flag or not missing.any()), row
        assert np.all(lower[~missing] <= value[~missing]) and np.all(value[~missing] <= upper[~missing]), row
    assert any(not np.all(np.isnan(np.asarray(row.lower, dtype=float))) for row in table) or case == "svr"
    if case == "gmssvr":  # the GMS stage's own least-squares problem gives its rows their intervals
        assert not np.isnan(model.parameter_table()[[r.name for r in table].index("gms.sigma")].lower)
    loaded = load_model(save_model(model, tmp_path / "model.gbm"))
    for before, after in zip(table, loaded.parameter_table()):
        assert after.flag == before.flag
        np.testing.assert_array_equal(np.asarray(after.lower, dtype=float), np.asarray(before.lower, dtype=float))


def test_chosen_hyperparameters_are_flagged_not_identified(train_runs):
    model = attach_intervals(CASES["svr"]().fit(train_runs), train_runs)
    rows = {row.name: row for row in model.parameter_table()}
    assert "chosen by cross-validation" in rows["C"].flag and "chosen by cross-validation" in rows["gamma"].flag
    assert all(np.isnan(row.lower) and row.flag.startswith("no interval: ") for row in rows.values())


class _ViscousModel(CurrentModel):
    """A kind that offers no linear part: the intervals cannot vary anything of it."""

    def _fit_runs(self, runs, progress):
        v = np.concatenate([run.velocity for run in runs])
        self.viscous_ = float(v @ np.concatenate([run.effort for run in runs]) / (v @ v))
        self.J_, self.offset_ = 0.0, 0.0

    def _simulate(self, run, state, sample_time):
        return self.viscous_ * run.velocity, None

    def _n_params(self):
        return 1

    def _own_parameters(self):
        return [Parameter("viscous", self.viscous_, "A s/mm", "viscous coefficient")]


def test_a_kind_without_a_linear_part_gets_flags_not_intervals():
    run = _coulomb_run(0, 2_000)
    rows = attach_intervals(_ViscousModel().fit(run), run).parameter_table()
    assert all(np.isnan(row.lower) and row.flag.startswith("no interval") for row in rows)


def test_a_refit_drops_the_intervals_of_the_earlier_fit():
    run = _coulomb_run(0, 2_000)
    model = attach_intervals(CoulombModel().fit(run), run)
    assert model.parameter_table()[0].lower is not None
    assert model.fit(run).parameter_table()[0].lower is None


# ------------------------------------------------------------------ model files
def test_a_record_of_another_level_is_refused(tmp_path):
    run = _coulomb_run(0, 2_000)
    model = attach_intervals(CoulombModel().fit(run), run)
    model.parameter_intervals_["level"] = 0.5
    with pytest.raises(ModelFileError, match="level must be 0.95"):
        load_model(save_model(model, tmp_path / "model.gbm"))


def _tampered(tmp_path, change) -> str:
    run = _coulomb_run(0, 2_000)
    model = attach_intervals(CoulombModel().fit(run), run)
    path = save_model(model, tmp_path / "model.gbm")
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    document = json.loads(members["model.json"])
    change(document["model"]["attributes"]["parameter_intervals_"]["rows"])
    members["model.json"] = json.dumps(document).encode()
    hostile = tmp_path / "hostile.gbm"
    return write_members(hostile, members)


@pytest.mark.parametrize("change, message", [
    (lambda rows: rows["J"].update(lower=1.0), "does not contain the value"),
    (lambda rows: rows["J"].update(upper={"__float__": "inf"}), "not finite"),
    (lambda rows: rows["J"].update(lower={"__float__": "nan"}), "missing without a flag"),
    (lambda rows: rows["J"].update(lower=[0.0, 0.0]), "shape"),
    (lambda rows: rows.update(nonsense={"lower": 0.0, "upper": 1.0, "flag": ""}), "has not"),
    (lambda rows: rows["J"].update(flag=3), "flag"),
])
def test_hostile_intervals_are_refused_in_one_line(tmp_path, change, message):
    with pytest.raises(ModelFileError) as error:
        load_model(_tampered(tmp_path, change))
    assert message in str(error.value) and "\n" not in str(error.value)


def test_a_model_file_without_intervals_loads_and_prints_without_them(tmp_path):
    run = _coulomb_run(0, 2_000)
    loaded = load_model(save_model(CoulombModel().fit(run), tmp_path / "old.gbm"))
    assert all(row.lower is None and row.flag == "" for row in loaded.parameter_table())


# ------------------------------------------------------------------ command line
@pytest.fixture
def commands(monkeypatch):
    for name in ("train", "info"):
        if name not in cli.COMMANDS:
            monkeypatch.setattr(cli, "COMMANDS", tuple(cli.COMMANDS) + (name,))


def test_train_and_info_print_and_store_the_intervals(tmp_path, capsys, commands):
    log = tmp_path / "run.csv"
    write_log(_coulomb_run(0, 5_000), log)
    out = tmp_path / "model.gbm"
    assert cli.main(["train", "--model", "coulomb", "--no-offset", "--train", str(log), "--out", str(out),
                     "--quiet"]) == 0
    trained = capsys.readouterr().out
    assert re.search(r"95 % intervals by sandwich over \d+ time blocks", trained)
    assert [line for line in trained.splitlines() if line.strip().startswith("J ")][0].count("95 %:") == 1
    assert cli.main(["info", str(out)]) == 0
    assert "95 %:" in capsys.readouterr().out
    assert cli.main(["info", str(out), "--json"]) == 0
    parameters = json.loads(capsys.readouterr().out)["parameters"]
    assert parameters["J"]["lower_95"] <= parameters["J"]["value"] <= parameters["J"]["upper_95"]
    assert parameters["offset"]["lower_95"] is None and parameters["offset"]["flag"]


def test_train_without_intervals(tmp_path, capsys, commands):
    log = tmp_path / "run.csv"
    write_log(_coulomb_run(0, 2_000), log)
    out = tmp_path / "model.gbm"
    assert cli.main(["train", "--model", "coulomb", "--train", str(log), "--out", str(out), "--quiet",
                     "--intervals", "none"]) == 0
    assert "95 %" not in capsys.readouterr().out
    assert load_model(out).parameter_table()[0].lower is None


def test_train_by_bootstrap_and_a_bootstrap_count_without_it(tmp_path, capsys, commands):
    log = tmp_path / "run.csv"
    write_log(_coulomb_run(0, 2_000), log)
    out = tmp_path / "model.gbm"
    assert cli.main(["train", "--model", "coulomb", "--train", str(log), "--out", str(out), "--quiet",
                     "--intervals", "bootstrap", "--bootstrap", "20"]) == 0
    assert "95 % intervals by bootstrap" in capsys.readouterr().out
    assert load_model(out).parameter_intervals_["method"] == "bootstrap"
    assert cli.main(["train", "--model", "coulomb", "--train", str(log), "--out", str(tmp_path / "other.gbm"),
                     "--bootstrap", "20"]) == 2
    error = capsys.readouterr().err
    assert "--bootstrap N applies with --intervals bootstrap" in error and error.count("\n") == 1
    assert cli.main(["train", "--model", "coulomb", "--train", str(log), "--out", str(tmp_path / "other.gbm"),
                     "--intervals", "bootstrap", "--bootstrap", "1"]) == 2
    assert "--bootstrap 1: a bootstrap needs at least 2 replicates" in capsys.readouterr().err


def test_a_fleets_models_carry_intervals(tmp_path):
    from greybox.fleet.train import train_jobs, train_model

    log = tmp_path / "logs" / "machine_1" / "run.csv"
    log.parent.mkdir(parents=True)
    write_log(_coulomb_run(0, 3_000), log)
    (job,) = train_jobs([log], CoulombModel(), str(tmp_path / "models"))
    result = train_model(job)
    assert result["status"] == "ok", result
    rows = {row.name: row for row in load_model(tmp_path / "models" / result["output"]).parameter_table()}
    assert rows["J"].lower < rows["J"].value < rows["J"].upper
