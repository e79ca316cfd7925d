"""Where the model extrapolates: samples outside the region its training runs covered."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest

import greybox.cli as cli
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.models.files import load_model, save_model
from greybox.models.friction import GMSModel, StribeckModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.predict.process import EXTRAPOLATION_WARNING_SHARE, predict_process
from greybox.twin import make_dataset

SMALL_SVR = dict(n_subset=200, n_calls=3, cv_folds=2, cv_blocks=4)


@pytest.fixture(scope="module")
def logs():
    """Air cut A in the 50 mm window (training), C in the same window, D over the whole travel."""
    return dict(zip("ACD", prepare([make_dataset("X", "A", seed=31, duration_s=20),
                                    make_dataset("X", "C", seed=32, duration_s=20),
                                    make_dataset("X", "D", seed=33)])))


def test_the_region_is_the_range_of_the_training_runs_and_the_flags_follow_it(logs):
    model = StribeckModel().fit(logs["A"])
    assert model.position_range_mm_ == [logs["A"].position.min(), logs["A"].position.max()]
    assert model.velocity_range_mm_s_ == [logs["A"].velocity.min(), logs["A"].velocity.max()]
    inside = model.outside_training(logs["A"])
    # a memoryless model flags standstill too; every model a prediction beyond the trained efforts
    assert set(inside) == {"position", "velocity", "standstill", "effort"}
    assert not inside["position"].any() and not inside["velocity"].any()
    far = model.outside_training(logs["D"])
    low, high = model.position_range_mm_
    np.testing.assert_array_equal(far["position"], (logs["D"].position < low) | (logs["D"].position > high))
    assert far["position"].mean() > 0.8


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_gms_svr_adds_its_input_space_and_covers_both_stages(logs):
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=60), **SMALL_SVR).fit_staged(logs["A"], logs["C"])
    both = np.concatenate([logs["A"].position, logs["C"].position])
    assert model.position_range_mm_ == [both.min(), both.max()]
    assert model.input_range_.shape == (2, 2 + len(model.gms_.alpha_))
    flags = model.outside_training(logs["D"])
    assert set(flags) == {"position", "velocity", "inputs", "effort"}
    assert np.all(flags["inputs"][flags["position"]])  # position is one of the inputs
    again = model.outside_training(logs["C"])
    assert not again["position"].any() and not again["inputs"].any()


def test_predict_reports_records_and_marks_the_samples_outside(logs, tmp_path, capsys):
    model = StribeckModel().fit(logs["A"])
    save_model(model, tmp_path / "m.gbm")
    write_log(make_dataset("X", "D", seed=34, duration_s=None, cutting=True), tmp_path / "cut.mcap")
    out = tmp_path / "p.csv"
    status = cli.main(["predict", str(tmp_path / "m.gbm"), str(tmp_path / "cut.mcap"), "--out", str(out),
                       "--plot", str(tmp_path / "p.png"), "--quiet"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    meta = json.loads(Path(str(out) + ".json").read_text())["attrs"]["extrapolation"]
    assert meta["share"] > EXTRAPOLATION_WARNING_SHARE
    assert set(meta["by"]) == {"position", "velocity", "standstill", "effort"}
    assert f"outside the training region: {100 * meta['share']:.1f} % of the samples" in captured.out
    note = [line for line in captured.err.splitlines()
            if line.startswith("note: cut.mcap:") and "standstill" not in line]
    assert len(note) == 1 and "the model extrapolates there (column outside_training)" in note[0]
    import pandas as pd

    table = pd.read_csv(out)
    assert table["outside_training"].mean() == pytest.approx(meta["share"])

    matplotlib.use("Agg")
    from greybox.predict.plot import plot_process

    result = predict_process(model, prepare([make_dataset("X", "D", seed=34)])[0])
    figure = plot_process(result)
    labels = [text.get_text() for text in figure.axes[2].get_legend().get_texts()]
    assert any(label.startswith("outside the training region") for label in labels)
    matplotlib.pyplot.close(figure)


@pytest.mark.parametrize("suffix", [".parquet", ".mcap"])
def test_inside_the_window_there_is_no_note_and_every_format_carries_the_column(logs, tmp_path, capsys, suffix):
    model = StribeckModel().fit([logs["A"], logs["C"]])
    save_model(model, tmp_path / "m.gbm")
    write_log(make_dataset("X", "C", seed=32, duration_s=20, cutting=True), tmp_path / "cut.mcap")
    out = tmp_path / f"p{suffix}"
    status = cli.main(["predict", str(tmp_path / "m.gbm"), str(tmp_path / "cut.mcap"), "--out", str(out), "--quiet"])
    captured = capsys.readouterr()
    assert status == 0 and "extrapolates" not in captured.err
    assert "(position 0.0 %, velocity 0.0 %, standstill" in captured.out
    flags = read_log(out, columns={"current_A": "current_measured_A"}).extras["outside_training"]
    columns = read_log(out, columns={"current_A": "current_measured_A"}).extras
    standstill = model.outside_training(prepare([read_log(tmp_path / "cut.mcap")])[0])["standstill"]
    assert standstill.any() and np.array_equal(columns["standstill"] == 1.0, standstill)  # a column of its own
    assert flags.size > 1000 and not flags.any()  # and not outside the training region (issue 40)


def test_a_model_file_without_a_region_still_predicts_and_says_so(logs, tmp_path, capsys):
    model = StribeckModel().fit(logs["A"])
    del model.position_range_mm_, model.velocity_range_mm_s_, model.effort_range_  # as a file written before
    save_model(model, tmp_path / "old.gbm")
    loaded = load_model(tmp_path / "old.gbm")
    assert loaded.outside_training(logs["D"]) == {}
    result = predict_process(loaded, logs["D"])
    assert result.outside is None and result.attrs["extrapolation"]["share"] is None
    assert "outside_training" not in result.columns()


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_gms_svr_flags_its_inputs_in_chunks_equal_to_the_whole_run(logs):
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=60), **SMALL_SVR).fit(logs["A"])
    long_log = prepare([make_dataset("X", "C", seed=35, duration_s=130)])[0]
    whole = model._inputs(long_log, model.initial_state(), long_log.sample_time)[0]
    expected = np.any((whole < model.input_range_[0]) | (whole > model.input_range_[1]), axis=1)
    assert 0 < np.count_nonzero(expected) < len(expected)  # a test that can tell
    np.testing.assert_array_equal(model.outside_training(long_log)["inputs"], expected)  # 60 s chunks inside
    state, parts = model.region_state(), []
    for samples in (slice(0, 1234), slice(1234, 40_000), slice(40_000, None)):  # the GMS state carried across
        flags, state = model.outside_training_chunk(long_log.select(samples), state,
                                                    sample_time=long_log.sample_time)
        parts.append(flags["inputs"])
    np.testing.assert_array_equal(np.concatenate(parts), expected)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_gms_svr_predicts_and_flags_a_chunk_with_one_gms_pass_as_it_does_apart(logs):
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=60), **SMALL_SVR).fit(logs["A"])
    run = prepare([make_dataset("X", "C", seed=36, duration_s=20)])[0]
    first, rest = run.select(slice(0, 3000)), run.select(slice(3000, None))
    state = region = model.initial_state()
    for chunk in (first, rest):  # the second chunk starts from the states the first ended in
        current, state_together, flags, region_together = model.predict_flag_chunk(
            chunk, state, region, sample_time=run.sample_time)
        expected, state = model.predict_chunk(chunk, state, sample_time=run.sample_time)
        expected_flags, region = model.outside_training_chunk(chunk, region, sample_time=run.sample_time)
        expected_flags.update(model.effort_flags(expected))  # the flag of the prediction, beside those of the inputs
        np.testing.assert_array_equal(current, expected)
        assert flags.keys() == expected_flags.keys() and "inputs" in flags and "effort" in flags
        for name in flags:
            np.testing.assert_array_equal(flags[name], expected_flags[name])
        for ours, theirs in ((state_together, state), (region_together, region)):
            for a, b in zip(ours, theirs):
                np.testing.assert_array_equal(a, b)
