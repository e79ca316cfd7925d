"""The one entry point of prediction, :func:`greybox.predict.predict_logs`: it chooses how to read, what to
write and whether to fan out, from what it is given."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pandas as pd
import pytest

from greybox.data.io import FORMATS, LOG_SUFFIXES, read_log, write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError, Setting
from greybox.fleet import expand_logs
from greybox.fleet.predict import predict_fleet
from greybox.models.files import save_model
from greybox.models.friction import CoulombModel
from greybox.models.machine import MachineModel, save_machine
from greybox.models.plant import MANIFEST, MODELS_FORMAT, machine_of
from greybox.predict import ChunkProgress, Prediction, predict_logs
from greybox.predict.output import write_process
from greybox.predict.process import predict_process
from greybox.predict.run import is_fleet
from greybox.predict.sources import MachineDirectory, ModelFile, ModelsDirectory, open_model
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A Coulomb model file (fast to fit), a machine model of it, and one cutting log as CSV and as Parquet."""
    root = tmp_path_factory.mktemp("entry")
    model = CoulombModel().fit(prepare([make_dataset("X", "A", seed=3, duration_s=6)])[0])
    save_model(model, root / "x.gbm")
    save_machine(MachineModel({"X": model, "Y": model}, name="mill"), root / "machine")
    cut = make_dataset("X", "C", seed=4, duration_s=5, cutting=True)
    for suffix in (".csv", ".parquet"):
        write_log(cut, root / f"cut{suffix}")
    other = make_dataset("Y", "C", seed=5, duration_s=5, cutting=True)
    shortest = min(len(cut), len(other))
    write_log([log.select(slice(0, shortest)) for log in (cut, other)], root / "xy.csv")
    return {"root": root, "model": model, "model_path": root / "x.gbm", "machine": root / "machine",
            "csv": root / "cut.csv", "parquet": root / "cut.parquet", "xy": root / "xy.csv"}


def _table(path) -> pd.DataFrame:
    return pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)


def test_a_csv_log_is_read_whole_and_gives_the_table_of_the_library_calls(files, tmp_path):
    steps: list[ChunkProgress] = []
    done = predict_logs(files["model_path"], files["csv"], out=tmp_path / "p.csv", chunk_s=1.5,
                        progress=steps.append)
    assert isinstance(done, Prediction) and done.result is not None and done.status == 0
    assert done.written == [str(tmp_path / "p.csv"), str(tmp_path / "p.csv.json")]
    assert "block by block" not in done.summary[0] and "coulomb model x.gbm" in done.summary[0]
    runs = prepare([read_log(files["csv"])])
    expected = predict_process(files["model"], runs, chunk_s=1.5)
    write_process(expected, tmp_path / "expected.csv")
    pd.testing.assert_frame_equal(_table(tmp_path / "p.csv"), _table(tmp_path / "expected.csv"))
    # one progress report per chunk, counting up to the last, ending at the log's last sample
    assert [step.done for step in steps] == list(range(1, len(steps) + 1)) and len(steps) > 1
    assert {step.chunks for step in steps} == {len(steps)} and steps[-1].time_s == steps[-1].end_s == runs[-1].time[-1]
    (heading, figures), = done.axes
    assert heading is None and figures.tally.n_samples == len(expected.time)
    assert figures.tally.rms("process") == pytest.approx(float(np.sqrt(np.mean(expected.process ** 2))))


def test_a_parquet_log_streams_unless_a_picture_is_asked_and_both_give_one_table(files, tmp_path):
    streamed = predict_logs(files["model_path"], files["parquet"], out=tmp_path / "s.parquet")
    assert streamed.result is None and streamed.summary[0].endswith("read and written block by block")
    drawn = predict_logs(files["model_path"], files["parquet"], out=tmp_path / "w.parquet",
                         plot=str(tmp_path / "w.png"))
    assert drawn.result is not None and "block by block" not in drawn.summary[0]
    assert drawn.written == [str(tmp_path / "w.parquet"), str(tmp_path / "w.png")] and (tmp_path / "w.png").is_file()
    pd.testing.assert_frame_equal(_table(tmp_path / "s.parquet"), _table(tmp_path / "w.parquet"))
    assert streamed.axes[0][1].tally.n_samples == drawn.axes[0][1].tally.n_samples


def test_the_model_source_is_chosen_by_what_the_path_is(files, tmp_path):
    (tmp_path / "models").mkdir()
    assert type(open_model(files["model_path"])) is ModelFile
    assert type(open_model(files["machine"])) is MachineDirectory
    assert type(open_model(tmp_path / "models")) is ModelsDirectory


def test_a_machine_model_predicts_every_axis_and_refuses_a_fleet(files, tmp_path):
    done = predict_logs(files["machine"], [files["xy"]], out=tmp_path / "m.csv")
    assert [heading for heading, _ in done.axes] == ["axis X:", "axis Y:"]
    assert "with the machine model machine (X: coulomb, Y: coulomb)" in done.summary[0]
    assert {"X_current_process_A", "Y_current_process_A"} <= set(_table(tmp_path / "m.csv").columns)
    with pytest.raises(GreyboxError, match="a fleet run takes one model file"):
        predict_fleet(files["machine"], [files["csv"], files["parquet"]], out=tmp_path / "fleet")
    with pytest.raises(GreyboxError, match="^axis does not apply to a machine model"):
        predict_logs(files["machine"], files["csv"], out=tmp_path / "m2.csv", read={"axis": "X"})
    assert not (tmp_path / "fleet").exists() and not (tmp_path / "m2.csv").exists()


@pytest.mark.parametrize("options, message", [
    ({"plot": "p.png"}, "^plot applies to one log"),
    ({"calibration": ["air.csv"]}, "^calibration applies to one log"),
    ({"machine": "m.toml"}, "^machine applies to one log"),
])
def test_options_of_one_log_are_refused_for_a_fleet_before_any_work(files, tmp_path, options, message):
    with pytest.raises(GreyboxError, match=message):
        predict_fleet(files["model_path"], [files["csv"], files["parquet"]], out=tmp_path / "fleet", **options)
    assert not (tmp_path / "fleet").exists()


def test_several_logs_are_refused_with_the_fleet_run_named(files, tmp_path):
    with pytest.raises(GreyboxError, match="make a fleet run; greybox.fleet.predict.predict_fleet runs it"):
        predict_logs(files["model_path"], [files["csv"], files["parquet"]], out=tmp_path / "fleet")
    assert not (tmp_path / "fleet").exists()


def test_cluster_options_are_refused_for_one_log_and_outputs_checked_before_work(files, tmp_path):
    with pytest.raises(GreyboxError, match="^scheduler and workers apply to fleet runs"):
        predict_logs(files["model_path"], files["csv"], out=tmp_path / "p.csv", workers=2)
    with pytest.raises(GreyboxError, match="^coverage needs calibration= ") as refused:
        predict_logs(files["model_path"], files["csv"], out=tmp_path / "p.csv", coverage=0.9)
    # the message names the settings (the command line spells them as --interval and --calibration)
    assert [part.name for part in refused.value.parts if isinstance(part, Setting)] == ["coverage", "calibration"]
    with pytest.raises(GreyboxError, match="is an input of this command"):
        predict_logs(files["model_path"], files["csv"], out=files["csv"], force=True)
    assert not (tmp_path / "p.csv").exists()


def test_several_logs_a_directory_or_a_pattern_make_a_fleet(files):
    assert not is_fleet([files["csv"]])
    assert is_fleet([files["csv"], files["parquet"]]) and is_fleet([files["root"]])
    assert is_fleet([str(files["root"] / "*.csv")])


def test_a_directory_of_per_machine_models_predicts_a_log_with_its_machines_model(files, tmp_path):
    with pytest.raises(GreyboxError, match="without the _manifest.json of 'greybox train --per-machine'"):
        predict_logs(tmp_path, files["csv"], out=tmp_path / "p.csv")
    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(files["model_path"], models / "x.gbm")
    machine = machine_of(files["csv"])  # the name of the log's folder
    (models / MANIFEST).write_text(json.dumps({"format": MODELS_FORMAT, "models": [
        {"status": "ok", "machine": machine, "axis": "X", "output": "x.gbm"}]}))
    done = predict_logs(models, files["csv"], out=tmp_path / "p.csv")
    assert done.summary[0] == f"model of machine {machine}: {models / 'x.gbm'}"
    predict_logs(files["model_path"], files["csv"], out=tmp_path / "q.csv")
    pd.testing.assert_frame_equal(_table(tmp_path / "p.csv"), _table(tmp_path / "q.csv"))


def test_a_directory_of_logs_is_searched_for_every_registered_log_extension(tmp_path):
    assert set(LOG_SUFFIXES) == {suffix for suffixes in FORMATS.values() for suffix in suffixes}
    for suffix in LOG_SUFFIXES:
        (tmp_path / f"log{suffix}").write_bytes(b"")
    (tmp_path / "log.csv.json").write_text("{}")  # a CSV log's metadata sidecar is no log
    found = {path.name for path in expand_logs([str(tmp_path)])}
    assert found == {f"log{suffix}" for suffix in LOG_SUFFIXES}
