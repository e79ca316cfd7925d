"""The ARTS friction-device reader and benchmark on the real data (and the reader's refusals on bad files).

The reported errors are checked against a recomputation typed in here: a
model fitted on the same prepared training file outside the study, its
prediction, and RE = 100 RMSE / mean|F| written out.
"""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from greybox.errors import GreyboxError, LogError
from greybox.models.friction import CoulombModel, GMSModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.train.candidates import choose_model
from studies import arts as bench
from studies import auto
from studies.arts_data import read_arts

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "arts_benchmark.py"

#: Samples per file and displacement amplitude [mm] per file (the data's README; test12 is velocity-limited).
SAMPLES = {0: 71681, 1: 28673, 2: 14337, 3: 7169, 4: 3585, 5: 71681, 6: 28673, 7: 14337, 8: 7169,
           9: 71681, 10: 28673, 11: 14337, 12: 7169}
AMPLITUDE_MM = {**{k: 19.2 for k in range(5)}, **{k: 38.7 for k in range(5, 9)}, **{k: 58.9 for k in range(9, 12)},
                12: 56.3}


@pytest.fixture(scope="module")
def arts(real_data):
    """The folder of the ARTS friction-device files (skips without it)."""
    return real_data("ARTS_friction_damper")


# ---------------------------------------------------------------- reader
def test_reader_gives_mm_mm_per_s_and_newton_at_1024_hz(arts):
    path = arts / "test1.npy"
    log = read_arts(path)
    t, force, x, v = np.load(path).T
    assert log.effort_unit == "N" and log.dataset == "test1" and log.source == str(path)
    assert log.sample_time == pytest.approx(1 / 1024, rel=1e-9)
    np.testing.assert_array_equal(log.time, t)
    np.testing.assert_array_equal(log.position, 1e3 * x)
    np.testing.assert_array_equal(log.velocity, 1e3 * v)
    np.testing.assert_array_equal(log.effort, force)
    assert log.acceleration is None
    assert 19.0 < log.position.max() < 19.5 and -19.5 < log.position.min() < -19.0
    assert -23e3 < log.effort.min() < -20e3 and 13e3 < log.effort.max() < 16e3


@pytest.mark.parametrize("k", range(13))
def test_every_file_has_its_length_amplitude_and_a_velocity_that_is_the_derivative_of_position(arts, k):
    log = read_arts(arts / f"test{k}.npy")
    assert len(log) == SAMPLES[k] and log.sample_time == pytest.approx(1 / 1024, rel=1e-9)
    assert np.ptp(log.position) / 2 == pytest.approx(AMPLITUDE_MM[k], abs=0.3)
    # the same low-pass on both sides: the recorded velocity is d(x)/dt within 1 % RMS, no gain error, no lag
    sos = butter(4, 20.0, fs=1024, output="sos")
    recorded = sosfiltfilt(sos, log.velocity)
    derived = np.gradient(sosfiltfilt(sos, log.position), log.time)
    assert np.sqrt(np.mean((recorded - derived) ** 2)) < 0.01 * np.sqrt(np.mean(derived**2))


def _save(path: Path, array) -> Path:
    np.save(path, array)
    return path


def _good(n: int = 100) -> np.ndarray:
    t = np.arange(n) / 1024
    return np.column_stack([t, 1e3 * np.sin(t), 1e-3 * np.sin(t), 1e-3 * np.cos(t)])


def test_a_small_good_file_is_read(tmp_path):
    log = read_arts(_save(tmp_path / "run.npy", _good()))
    assert len(log) == 100 and log.dataset == "run" and log.position[5] == pytest.approx(np.sin(5 / 1024))


@pytest.mark.parametrize("name, make, fragment", [
    ("test.csv", lambda p: p.write_text("t,F,x,v\n"), "not a .npy file"),
    ("missing.npy", lambda p: None, "no such file"),
    ("text.npy", lambda p: p.write_text("t F x v\n0 1 2 3\n"), "not a readable NumPy .npy array"),
    ("objects.npy", lambda p: np.save(p, np.array([{"t": 0}], dtype=object)), "not a readable NumPy .npy array"),
    ("archive.npy", lambda p: np.savez(p.open("wb"), data=_good()), "an .npz archive"),
    ("folder.npy", lambda p: p.mkdir(), "is a directory"),
    ("three.npy", lambda p: np.save(p, _good()[:, :3]), "shape (100, 3); expected (N, 4)"),
    ("flat.npy", lambda p: np.save(p, _good()[:, 0]), "shape (100,); expected (N, 4)"),
    ("complex.npy", lambda p: np.save(p, _good().astype(complex)), "complex128 values"),
    ("nan.npy", lambda p: np.save(p, np.where(np.arange(4) == 1, np.nan, _good())), "channel 'force_N' holds nan"),
    ("inf_x.npy", lambda p: np.save(p, np.where(np.arange(4) == 2, np.inf, _good())), "channel 'position_mm'"),
    ("backwards.npy", lambda p: np.save(p, _good()[::-1]), "time goes backwards"),
])
def test_bad_files_raise_a_log_error_naming_the_file(tmp_path, name, make, fragment):
    path = tmp_path / name
    make(path)
    with pytest.raises(LogError) as error:
        read_arts(path)
    message = str(error.value)
    assert message.startswith(f"{path}: ") and fragment in message, message


# ---------------------------------------------------------------- study
def test_the_model_table_has_every_kind_symmetric_with_offset_and_asymmetric_without():
    kinds = ("coulomb", "stribeck", "lugre", "gms")
    assert bench.MODEL_NAMES == tuple(name for kind in kinds for name in (kind, f"{kind}_asym")) + (
        "gms_backlash", "gms_asym_backlash", "auto")
    for name, (factory, _) in bench.MODELS.items():
        if name == "auto":  # not a model: the choice among the candidates of --model auto
            continue
        model = factory(3)  # a constructor without the option raises TypeError here: nothing is skipped
        if name.endswith("_backlash"):
            assert model.width is None  # identified
            model = model.base
        asymmetric = "_asym" in name
        assert model.fit_offset is not asymmetric and getattr(model, "asymmetric", False) is asymmetric, name
        if hasattr(model, "random_state"):
            assert model.random_state == 3


def test_a_model_that_cannot_be_built_stops_the_run_before_any_fit(tmp_path, arts, monkeypatch):
    def unbuildable(seed):
        raise TypeError("__init__() got an unexpected keyword argument 'asymmetric'")

    monkeypatch.setitem(bench.MODELS, "lugre_asym", (unbuildable, "stand-in"))
    fitted = []
    monkeypatch.setattr(CoulombModel, "fit", lambda self, *a, **k: fitted.append(self))
    with pytest.raises(TypeError, match="asymmetric"):
        bench.arts_benchmark(arts, tmp_path / "arts.json", names=["coulomb", "lugre_asym"])
    assert not fitted and not list(tmp_path.iterdir())


def _re(y, y_hat):
    return 100 * np.sqrt(np.mean((y - y_hat) ** 2)) / np.mean(np.abs(y))


def test_subset_study_writes_its_files_and_reports_the_re_of_its_predictions(tmp_path, arts):
    out, md, png = tmp_path / "arts.json", tmp_path / "arts.md", tmp_path / "arts.png"
    table = bench.arts_benchmark(arts, out, markdown_path=md, plot_path=png, names=["coulomb", "stribeck"],
                                 train=["test1.npy"], test=["test4.npy"])
    results = json.loads(out.read_text())
    assert list(results["models"]) == ["coulomb", "stribeck"]
    assert results["protocol"]["train"] == ["test1.npy"] and results["protocol"]["test"] == ["test4.npy"]
    assert results["files"]["test4.npy"]["role"] == "test" and results["provenance"]["greybox"]
    # the same fit outside the study: the recorded motion, no acceleration (no inertia is fitted)
    train, test = (read_arts(arts / name) for name in ("test1.npy", "test4.npy"))
    train, test = (log.replace(acceleration=np.zeros(len(log))) for log in (train, test))
    for name, model in (("coulomb", CoulombModel(fit_offset=True)), ("stribeck", StribeckModel(fit_offset=True))):
        model.fit(train)
        entry = results["models"][name]
        assert entry["fit_offset"] is True and set(entry["units"]) == set(entry["params"])
        for role, log in (("train", train), ("test", test)):
            prediction = model.predict(log)
            assert entry[role]["re"] == pytest.approx(_re(log.effort, prediction), rel=1e-9), (name, role)
            relerr = 100 * np.linalg.norm(log.effort - prediction) / np.linalg.norm(log.effort)
            assert entry[role]["relerr"] == pytest.approx(relerr, rel=1e-9)
            assert entry["files"][f"{log.dataset}.npy"]["re"] == entry[role]["re"]  # one file per role
    assert f"| `stribeck` | Stribeck + viscous + offset | 6 | {results['models']['stribeck']['train']['re']:.2f} |" \
        in table
    coulomb = results["models"]["coulomb"]
    assert coulomb["test"]["bands"] == coulomb["files"]["test4.npy"]["bands"]  # one file per role
    refit = CoulombModel(fit_offset=True).fit(train)
    assert coulomb["test"]["bands"] == bench.band_split([test], [refit.predict(test)])
    floors = (coulomb["train"]["bands"]["floor"], coulomb["test"]["bands"]["floor"], coulomb["fast"]["bands"]["floor"])
    assert "| floor: the measured force above the band | " + " | ".join(f"{f:.2f}" for f in floors) + " |" in table
    assert md.read_text().startswith(table) and "Measured with greybox" in md.read_text()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files left


def test_a_model_behind_a_backlash_reports_its_width_and_offset(tmp_path, arts, monkeypatch):
    quick = BacklashModel(base=GMSModel(fit_offset=True, n_starts=1, max_iter=30), width=3.0)
    monkeypatch.setitem(bench.MODELS, "gms_backlash", (lambda seed: quick, "stand-in"))
    out = tmp_path / "arts.json"
    bench.arts_benchmark(arts, out, names=["gms_backlash"], train=["test1.npy"], test=["test4.npy"])
    entry = json.loads(out.read_text())["models"]["gms_backlash"]
    assert entry["fit_offset"] is True and entry["params"]["width"] == 3.0
    assert entry["n_params"] == quick.base_.n_params  # a given width is not a fitted parameter


def test_auto_reports_the_model_it_chose_and_the_fast_tests(tmp_path, arts, monkeypatch):
    candidates = ["coulomb:offset", "stribeck:offset"]
    monkeypatch.setattr(auto, "choose_model", functools.partial(choose_model, candidates=candidates))
    out = tmp_path / "arts.json"
    table = bench.arts_benchmark(arts, out, names=["auto", "coulomb"], train=["test1.npy", "test6.npy"],
                                 test=["test2.npy", "test4.npy"])
    results = json.loads(out.read_text())
    entry = results["models"]["auto"]
    assert entry["selection"]["chosen"] in candidates
    assert entry["selection"]["folds"] == [str(arts / "test1.npy"), str(arts / "test6.npy")]
    assert results["protocol"]["fast"] == ["test4.npy"]
    for other in results["models"].values():
        assert other["fast"] == other["files"]["test4.npy"]  # the one 1-2 Hz file of this split
    assert f"| {entry['fast']['re']:.2f} |" in table and f": {entry['selection']['chosen']} |" in table


def test_the_run_checks_names_split_and_files_before_reading(tmp_path, arts):
    with pytest.raises(GreyboxError, match="unknown model"):
        bench.run_benchmark(arts, ["coulomb", "dahl"])
    with pytest.raises(GreyboxError, match="test1.npy: both a training and a test file"):
        bench.run_benchmark(arts, ["coulomb"], train=["test1.npy"], test=["test1.npy", "test2.npy"])
    with pytest.raises(GreyboxError, match="at least one training file and one test file"):
        bench.run_benchmark(arts, ["coulomb"], test=[])
    with pytest.raises(GreyboxError, match="test99.npy: ARTS data file not found"):
        bench.run_benchmark(arts, ["coulomb"], train=["test99.npy"])


# ---------------------------------------------------------------- script
def _script(*args, env=None):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=env)


def test_script_refuses_to_overwrite_without_force(tmp_path):
    existing = tmp_path / "arts.json"
    existing.write_text("{}")
    result = _script("--json", existing, "--data", tmp_path)  # refused before the data are looked at
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == f"arts_benchmark: error: {existing}: file exists; use --force to overwrite it\n"
    assert existing.read_text() == "{}"


def test_outputs_never_replace_the_data(tmp_path):
    data = tmp_path / "ARTS"
    data.mkdir()
    (data / "test1.npy").write_bytes(b"not the real data")  # never read: the refusal comes first
    with pytest.raises(GreyboxError, match="ARTS data files"):
        bench.arts_benchmark(data, data / "test1.npy", force=True)
    assert (data / "test1.npy").read_bytes() == b"not the real data"


def test_script_reports_a_missing_data_folder_in_one_line(tmp_path):
    result = _script("--json", tmp_path / "x.json", "--data", tmp_path / "nowhere", "--models", "coulomb")
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1
    assert str(tmp_path / "nowhere" / "test1.npy") in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "x.json").exists()


def test_the_script_finds_the_data_through_greybox_real_data(tmp_path):
    env = {**os.environ, "GREYBOX_REAL_DATA": str(tmp_path / "elsewhere")}
    result = _script("--json", tmp_path / "x.json", "--models", "coulomb", env=env)
    assert result.returncode == 2 and str(tmp_path / "elsewhere" / "ARTS_friction_damper") in result.stderr


def test_record_prints_the_results_as_json_last_and_writes_nothing(tmp_path, arts):
    result = subprocess.run([sys.executable, str(SCRIPT), "--record", "--quiet", "--data", str(arts), "--models",
                             "coulomb"], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    printed = json.loads(result.stdout)  # the whole output is one JSON object: the record's figures
    assert list(printed["models"]) == ["coulomb"] and printed["protocol"]["train"] == list(bench.TRAIN_FILES)
    written, _ = bench.run_benchmark(arts, ["coulomb"])
    assert printed["models"]["coulomb"]["test"]["re"] == pytest.approx(written["models"]["coulomb"]["test"]["re"])
    assert list(tmp_path.iterdir()) == []


def test_record_refuses_the_file_options(tmp_path):
    result = _script("--record", "--plot", tmp_path / "arts.png", "--data", tmp_path)
    assert result.returncode == 2 and "--record writes no file" in result.stderr
    assert result.stdout == "" and not (tmp_path / "arts.png").exists()
