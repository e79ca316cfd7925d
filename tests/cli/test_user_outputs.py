"""Outputs and options of the commands as a new user meets them (issue 12, section 4).

Each test runs the command line as a user would and fails without its fix: refusal of existing outputs
by ``plot`` and ``synth``, the defaults stated in the help, the effort unit of force logs in the
``evaluate`` report, per-log rows, distinguishable ``info`` rows, the dataset id and progress of
``predict``, the duration of ``synth`` and long-log pictures.
"""

from __future__ import annotations

import re

import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.twin import make_dataset


def _run(capsys, *args):
    status = cli.main([str(a) for a in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture(scope="module")
def short_log(tmp_path_factory):
    """A 3 s synthetic air-cut log (MCAP)."""
    path = tmp_path_factory.mktemp("logs") / "X_A.mcap"
    write_log(make_dataset("X", "A", seed=1, duration_s=3.0), path)
    return path


# ---------------------------------------------------------------- existing outputs need --force
def test_plot_keeps_an_existing_picture_unless_force(short_log, tmp_path, capsys):
    picture = tmp_path / "log.png"
    picture.write_bytes(b"the user's picture")
    status, _, err = _run(capsys, "plot", short_log, "--out", picture)
    assert status == 2 and err.count("\n") == 1
    assert f"{picture}: file exists; use --force" in err
    assert picture.read_bytes() == b"the user's picture"
    status, out, err = _run(capsys, "plot", short_log, "--out", picture, "--force")
    assert status == 0, err
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f"wrote {picture}" in out
    assert [p.name for p in tmp_path.iterdir()] == ["log.png"]  # no temporary file left


def test_plot_never_draws_over_its_log_nor_an_unknown_format(short_log, tmp_path, capsys):
    before = short_log.read_bytes()
    status, _, err = _run(capsys, "plot", short_log, "--out", short_log, "--force")
    assert status == 2 and "unknown picture extension '.mcap'" in err
    assert short_log.read_bytes() == before
    status, _, err = _run(capsys, "plot", short_log, "--out", tmp_path / "log.txt")
    assert status == 2 and "unknown picture extension '.txt'" in err and "Traceback" not in err


def test_synth_refuses_a_non_empty_directory_unless_force(tmp_path, capsys):
    out = tmp_path / "twin"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    args = ["synth", "--axis", "X", "--datasets", "A", "--duration", "3", "--seed", "1", "--out", out]
    status, _, err = _run(capsys, *args)
    assert status == 2 and err.count("\n") == 1
    assert f"{out}: directory is not empty (notes.txt exists)" in err and "--force" in err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    status, _, err = _run(capsys, *args, "--force")
    assert status == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["X_A.mcap", "notes.txt"]
    assert (out / "notes.txt").read_text() == "mine"


# ---------------------------------------------------------------- help states the defaults
@pytest.mark.parametrize("command", ["info", "plot", "train", "evaluate", "predict", "discover"])
def test_cutoff_help_states_the_default(command, capsys):
    with pytest.raises(SystemExit):
        cli.main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "see README" not in text
    assert "default min(50 Hz, 0.4 x Nyquist)" in text


# ---------------------------------------------------------------- synth --duration
@pytest.mark.parametrize("datasets, duration, minimum", [(("A", "P"), "5", "10"), (("C",), "1", "2")])
def test_synth_refuses_a_duration_below_the_minimum(tmp_path, capsys, datasets, duration, minimum):
    out = tmp_path / "twin"
    status, _, err = _run(capsys, "synth", "--axis", "X", "--datasets", *datasets, "--duration", duration,
                          "--seed", "5", "--out", out)
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert f"--duration {duration}: dataset" in err and f"needs at least {minimum} s" in err
    assert not out.exists()


def test_synth_says_when_a_log_is_not_as_long_as_asked(tmp_path, capsys):
    from greybox.data.io import read_log

    out = tmp_path / "twin"
    status, printed, err = _run(capsys, "synth", "--axis", "X", "--datasets", "A", "P", "D", "--duration", "15",
                                "--seed", "5", "--out", out, "--truth", "essential")
    assert status == 0, err
    note = err.splitlines()[0]
    length = read_log(out / "X_P.mcap").duration
    assert length == pytest.approx(20.0)
    assert note.startswith("note: --duration 15 s gives ") and "X_P 20.0 s" in note and "10 s envelope" in note
    assert "note: --duration does not apply to D" in err
    for key in "AP":  # the printed length is the written one
        written = read_log(out / f"X_{key}.mcap").duration
        assert (f"X_{key} {written:.1f} s" in note) == (abs(written - 15.0) > 0.5)


# ---------------------------------------------------------------- evaluate: force logs, one row per test log
def _force_log(dataset: str, seed: int, duration_s: float):
    """A synthetic log turned into a force log [N] (as EMPS logs force), without truth channels."""
    log = make_dataset("X", dataset, seed=seed, duration_s=duration_s)
    return log.replace(effort=700.0 * log.effort, effort_unit="N", extras={})


@pytest.fixture(scope="module")
def force_files(tmp_path_factory):
    """A Stribeck model fitted on a force log, two force test logs and one current log (MCAP)."""
    from greybox.data.prepare import prepare
    from greybox.models.files import save_model
    from greybox.models.friction import StribeckModel

    root = tmp_path_factory.mktemp("force")
    model = save_model(StribeckModel().fit(prepare([_force_log("A", 1, 4.0)])), root / "stribeck.gbm")
    paths = {"model": model}
    for name, dataset, seed in (("first", "C", 2), ("second", "A", 3)):
        paths[name] = root / f"{name}.mcap"
        write_log(_force_log(dataset, seed, 3.0), paths[name])
    paths["current"] = root / "current.mcap"
    write_log(make_dataset("X", "C", seed=2, duration_s=3.0), paths["current"])
    return paths


def test_evaluate_report_of_force_logs_is_in_newtons(force_files, tmp_path, capsys):
    import json

    out = tmp_path / "report"
    status, printed, err = _run(capsys, "evaluate", force_files["model"], "--test", force_files["first"],
                                force_files["second"], "--out", out)
    assert status == 0, err
    assert "effort in N" in printed and "RMSE N" in printed
    tables = (out / "tables.md").read_text()
    assert "RMSE [N]" in tables and "max error [N]" in tables and "[A]" not in tables
    assert "force in N" in tables
    html = (out / "index.html").read_text()
    assert "RMSE [N]" in html and "[A]" not in html
    records = json.loads((out / "metrics.json").read_text())
    assert {r["effort_unit"] for r in records} == {"N"}


def test_report_figures_label_the_effort_unit(force_files, tmp_path):
    from greybox.data.io import read_log
    from greybox.data.prepare import prepare
    from greybox.evaluate.figures import error_boxplot, residual_vs_position, time_comparison

    runs = prepare([read_log(force_files["first"])])
    predictions = {"stribeck": runs[0].effort * 0.9}
    texts = {}
    for name, draw in (("box", lambda p: error_boxplot([("test", runs, predictions)], p)),
                       ("time", lambda p: time_comparison(runs, predictions, p)),
                       ("residual", lambda p: residual_vs_position(runs, predictions, p))):
        texts[name] = draw(tmp_path / f"{name}.svg").read_text()
        assert "[A]" not in texts[name]
    assert "absolute error [N]" in texts["box"] and "modelled force" in texts["box"]
    assert "force [N]" in texts["time"] and "Measured and modelled force" in texts["time"]
    assert "measured - model [N]" in texts["residual"]


def test_evaluate_prints_a_row_per_test_log_before_the_pooled_rows(force_files, tmp_path, capsys):
    import json

    from greybox.data.io import read_log
    from greybox.data.prepare import prepare
    from greybox.metrics import rmse
    from greybox.models.files import load_model

    records_file = tmp_path / "m.json"
    out = tmp_path / "report"
    status, printed, err = _run(capsys, "evaluate", force_files["model"], "--test", force_files["first"],
                                force_files["second"], "--json", records_file, "--out", out)
    assert status == 0, err
    lines = printed.splitlines()
    first = next(i for i, line in enumerate(lines) if "log first" in line)
    assert "log second" in lines[first + 1] and "all (pooled)" in lines[first + 2]
    model = load_model(force_files["model"])
    (record,) = json.loads(records_file.read_text())
    for offset, name in enumerate(("first", "second")):
        run = prepare([read_log(force_files[name])])[0]
        fields = lines[first + offset].split()
        assert fields[-5:-3] == [f"{name}", str(len(run))]
        assert float(fields[-3]) == pytest.approx(rmse(run.effort, model.predict(run)), rel=1e-3)
        assert float(fields[-2]) == pytest.approx(record["per_log"][name]["re"], abs=0.006)
    assert "Test errors per log" in (out / "tables.md").read_text()


def test_evaluate_refuses_logs_of_different_effort_units(force_files, capsys):
    status, _, err = _run(capsys, "evaluate", force_files["model"], "--test", force_files["first"],
                          force_files["current"])
    assert status == 2 and err.count("\n") == 1
    assert "--test: the logs carry effort in different units (first in N, current in A)" in err


# ---------------------------------------------------------------- info: files of the same name
def test_info_tells_files_of_the_same_name_apart(tmp_path, capsys):
    paths = []
    for run, seed in (("monday", 1), ("tuesday", 2)):
        (tmp_path / run / "axis").mkdir(parents=True)
        paths.append(tmp_path / run / "axis" / "X_A.mcap")
        write_log(make_dataset("X", "A", seed=seed, duration_s=3.0), paths[-1])
    status, printed, err = _run(capsys, "info", *paths)
    assert status == 0, err
    rows = printed.splitlines()[1:]
    assert len(rows) == 2 and rows[0] != rows[1]
    assert rows[0].startswith("monday/axis/X_A.mcap ") and rows[1].startswith("tuesday/axis/X_A.mcap ")


def test_display_names_use_as_few_folders_as_needed():
    from greybox.cli.info import display_names

    assert display_names(["a/b/X.mcap", "c/b/X.mcap", "d/Y.mcap"]) == ["a/b/X.mcap", "c/b/X.mcap", "Y.mcap"]
    assert display_names(["a/X.mcap", "X.mcap"]) == ["a/X.mcap", "X.mcap"]
    assert display_names(["a/X.mcap", "a/X.mcap"]) == ["a/X.mcap", "a/X.mcap"]


# ---------------------------------------------------------------- long logs: envelope and time window
def _long_log(n: int = 200_000):
    """A log of n samples at 2 ms with one single-sample spike of 5 A at sample 123 457."""
    import numpy as np

    from greybox.data.log import AxisLog

    time = np.arange(n) * 0.002
    effort = 0.5 * np.sin(2 * np.pi * 0.3 * time)
    effort[123_457] = 5.0
    return AxisLog(time=time, position=np.sin(0.1 * time), effort=effort, velocity=0.1 * np.cos(0.1 * time),
                   axis="X", dataset="H")


def test_envelope_keeps_the_range_of_every_bin_in_time_order():
    import numpy as np

    from greybox.evaluate.plots import envelope

    time = np.arange(10_001) * 0.002
    values = np.sin(time) + np.where(np.arange(time.size) == 4321, 3.0, 0.0)
    t, v = envelope(time, values, max_points=100)
    assert v.size <= 100 and v.max() == values.max() and v.min() == values.min()
    assert np.all(np.diff(t) >= 0)  # the line follows the signal in time
    assert np.isin(t, time).all() and np.array_equal(np.interp(t, time, values), v)  # samples, not invented
    short_t, short_v = envelope(time[:50], values[:50], max_points=100)
    assert np.array_equal(short_v, values[:50])


def test_plot_of_a_long_log_is_an_envelope_and_a_window_shows_the_samples():
    import matplotlib
    import matplotlib.pyplot

    matplotlib.use("Agg")
    from greybox.evaluate.plots import ENVELOPE_POINTS, plot_log

    log = _long_log()
    figure = plot_log(log)
    current = figure.axes[2].lines[0]
    assert current.get_ydata().size <= ENVELOPE_POINTS and current.get_ydata().max() == 5.0
    matplotlib.pyplot.close(figure)
    figure = plot_log(log, window=(200.0, 205.0))
    t = figure.axes[2].lines[0].get_xdata()
    assert t.size == 2501 and t[0] == pytest.approx(200.0) and t[-1] == pytest.approx(205.0)
    assert "200 to 205 s" in figure._suptitle.get_text()
    matplotlib.pyplot.close(figure)


def test_plot_window_option(short_log, tmp_path, capsys):
    picture = tmp_path / "window.png"
    status, out, err = _run(capsys, "plot", short_log, "--out", picture, "--window", "1", "2")
    assert status == 0, err
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for window, message in ((("2", "1"), "--window 2 1: give START < END"),
                            (("100", "200"), "--window 100 200: no sample in the window; X_A.mcap runs from 0 to")):
        status, _, err = _run(capsys, "plot", short_log, "--out", tmp_path / "other.png", "--window", *window)
        assert status == 2 and err.count("\n") == 1 and message in err
    assert not (tmp_path / "other.png").exists()


# ---------------------------------------------------------------- predict: dataset id, progress, wall time
@pytest.fixture(scope="module")
def predict_files(tmp_path_factory):
    """A Stribeck model file and a 6 s cutting log of dataset C (MCAP)."""
    from greybox.data.prepare import prepare
    from greybox.models.files import save_model
    from greybox.models.friction import StribeckModel

    root = tmp_path_factory.mktemp("predict")
    model = save_model(StribeckModel().fit(prepare([make_dataset("X", "A", seed=1, duration_s=4.0)])),
                       root / "stribeck.gbm")
    log = root / "cut.mcap"
    write_log(make_dataset("X", "C", seed=2, duration_s=6.0, cutting=True), log)
    return {"model": model, "log": log}


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_predict_keeps_the_dataset_id(predict_files, tmp_path, capsys, suffix):
    import json

    from greybox.data.io import read_log

    out = tmp_path / f"process{suffix}"
    status, _, err = _run(capsys, "predict", predict_files["model"], predict_files["log"], "--out", out)
    assert status == 0, err
    if suffix == ".csv":
        assert json.loads((tmp_path / "process.csv.json").read_text())["dataset"] == "C"
    elif suffix == ".parquet":
        import pyarrow.parquet as pq

        assert json.loads(pq.read_schema(out).metadata[b"greybox"])["dataset"] == "C"
    else:
        assert read_log(out, columns={"current_A": "current_measured_A"}).dataset == "C"


def test_process_picture_title_names_the_dataset(predict_files):
    import matplotlib
    import matplotlib.pyplot
    import numpy as np

    matplotlib.use("Agg")
    from greybox.data.io import read_log
    from greybox.data.prepare import prepare
    from greybox.models.files import load_model
    from greybox.predict.plot import plot_process
    from greybox.predict.process import predict_process

    log = prepare([read_log(predict_files["log"])])[0]
    steps = []
    result = predict_process(load_model(predict_files["model"]), log, chunk_s=2.5,
                             progress=lambda *step: steps.append(step))
    assert result.dataset == "C"
    n = int(np.ceil(log.duration / 2.5 - 1e-9))
    assert n > 1 and [step[:2] for step in steps] == [(k, n) for k in range(1, n + 1)]
    assert steps[-1][2] == log.time[-1] and steps[0][2] == pytest.approx(2.5 - log.sample_time)
    figure = plot_process(result)
    assert figure._suptitle.get_text().startswith("axis X / dataset C")
    matplotlib.pyplot.close(figure)
    figure = plot_process(result, window=(1.0, 2.0))
    assert "1 to 2 s" in figure._suptitle.get_text()
    assert figure.axes[1].lines[0].get_xdata().min() >= 1.0 and figure.axes[1].lines[0].get_xdata().max() <= 2.0
    matplotlib.pyplot.close(figure)


def test_predict_shows_progress_per_chunk_and_the_total_wall_time(predict_files, tmp_path, capsys):
    out = tmp_path / "process.parquet"
    status, printed, err = _run(capsys, "predict", predict_files["model"], predict_files["log"], "--out", out,
                                "--chunk-s", "2.5")
    assert status == 0, err
    progress = [line for line in err.splitlines() if not line.startswith("note: ")]  # notes may follow
    chunks = len(progress)
    assert chunks > 1 and all(line.startswith(f"predicting: chunk {k}/{chunks}, ")
                              for k, line in enumerate(progress, start=1))
    assert f"{chunks} chunk(s) of 2.5 s, dataset C" in printed
    last = printed.strip().splitlines()[-1]
    assert re.fullmatch(r"done in \d+\.\d\d s wall \(model \d+\.\d\d s\)", last)
    status, printed, err = _run(capsys, "predict", predict_files["model"], predict_files["log"], "--out", out,
                                "--force", "--quiet")
    assert status == 0 and "predicting" not in err and printed.strip().splitlines()[-1].startswith("done in ")
    assert all(line.startswith("note: ") for line in err.splitlines())


def test_predict_plot_window(predict_files, tmp_path, capsys):
    out, picture = tmp_path / "process.parquet", tmp_path / "process.png"
    status, printed, err = _run(capsys, "predict", predict_files["model"], predict_files["log"], "--out", out,
                                "--plot", picture, "--plot-window", "1", "3", "--quiet")
    assert status == 0, err
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for args, message in ((["--plot", tmp_path / "p.png", "--plot-window", "3", "1"], "--plot-window 3 1: give"),
                          (["--plot-window", "1", "3"], "--plot-window needs --plot PNG")):
        status, _, err = _run(capsys, "predict", predict_files["model"], predict_files["log"], "--out",
                              tmp_path / "other.parquet", *args)
        assert status == 2 and err.count("\n") == 1 and message in err
    assert not (tmp_path / "other.parquet").exists() and not (tmp_path / "p.png").exists()
