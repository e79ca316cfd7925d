"""Time as it comes: irregular time stamps resampled, gaps split into runs, tolerance honoured everywhere."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare, split_at_gaps
from greybox.errors import LogError
from greybox.twin import make_dataset

STEP = 0.002


@pytest.fixture(scope="module")
def uniform():
    """A twin air cut (steps and sines in the window) at 2 ms, 20 s; its prepared form is the reference."""
    log = make_dataset("X", "C", seed=41, duration_s=20)
    return log.replace(velocity=None, extras={}), prepare([log.replace(velocity=None, extras={})])[0]


def _irregular(log: AxisLog, low_steps: float, high_steps: float, seed: int) -> AxisLog:
    """The same motion sampled at irregular times: steps drawn uniformly from [low, high] x 2 ms."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(low_steps, high_steps, size=len(log)) * STEP
    time = np.concatenate(([0.0], np.cumsum(steps)))
    time = time[time <= log.time[-1]]
    return AxisLog(time=time, position=np.interp(time, log.time, log.position),
                   effort=np.interp(time, log.time, log.effort), axis="X", source="irregular.csv")


@pytest.mark.parametrize("low, high", [(0.5, 1.5), (0.5, 6.0), (1.0, 6.0)])
def test_resampled_irregular_log_gives_the_velocity_within_what_the_jitter_allows(uniform, low, high):
    raw, reference = uniform
    irregular = _irregular(raw, low, high, seed=int(10 * high))
    with pytest.raises(LogError, match="--resample S"):
        prepare([irregular])
    (run,) = prepare([irregular], sample_time=STEP)
    assert run.sample_time == pytest.approx(STEP)
    common = slice(50, len(run) - 50)  # away from the ends, where the filter starts
    truth = np.interp(run.time, reference.time, reference.velocity)
    error = run.velocity[common] - truth[common]
    # A straight line between samples dt apart misses the slope by up to |a| dt / 2; the longest step
    # bounds dt, and the filter averages the error over many steps, so its RMS stays below that bound.
    bound = np.sqrt(np.mean(reference.acceleration**2)) * high * STEP / 2
    assert np.sqrt(np.mean(error**2)) < bound
    assert np.sqrt(np.mean(error**2)) < 0.1 * np.sqrt(np.mean(truth**2))


def test_dropped_samples_are_interpolated_and_a_long_dropout_splits_the_log(uniform):
    raw, _ = uniform
    rng = np.random.default_rng(5)
    keep = rng.random(len(raw)) > 0.02  # single dropped samples: steps of 2-3 nominal steps
    keep[4000:4020] = False  # a dropout of 20 steps
    dropped = AxisLog(time=raw.time[keep], position=raw.position[keep], effort=raw.effort[keep], axis="X")
    runs = split_at_gaps(dropped, 5.0)
    assert len(runs) == 2 and runs[1].attrs["split"]["start_s"] == pytest.approx(raw.time[4020])
    prepared = prepare([dropped], sample_time=STEP)
    assert len(prepared) == 2 and all(run.is_prepared for run in prepared)
    assert prepared[0].time[-1] < raw.time[4000] and prepared[1].time[0] == pytest.approx(raw.time[4020])
    assert len(prepare([dropped], sample_time=STEP, max_gap_steps=30.0)) == 1


def test_the_command_line_resamples_splits_with_a_note_and_names_resample_otherwise(uniform, tmp_path, capsys):
    raw, _ = uniform
    keep = np.ones(len(raw), dtype=bool)
    keep[3000:3030] = False
    gappy = AxisLog(time=raw.time[keep], position=raw.position[keep], effort=raw.effort[keep], axis="X",
                    dataset="C")
    path = tmp_path / "gappy.csv"
    write_log(gappy, path)
    status = cli.main(["info", str(path)])
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1 and "--resample S splits the log" in err
    status = cli.main(["info", str(path), "--resample", "0.002"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "note: gappy.csv: split into 2 runs at gaps longer than 5 steps (--max-gap)" in captured.err
    assert "gappy.csv run 1 of 2" in captured.out and "gappy.csv run 2 of 2" in captured.out
    status = cli.main(["info", str(path), "--resample", "0.002", "--max-gap", "40"])
    assert status == 0 and "split" not in capsys.readouterr().err
    assert cli.main(["plot", str(path), "--resample", "0.002", "--out", str(tmp_path / "p.png")]) == 2
    assert "plot draws one: give --window" in capsys.readouterr().err
    assert cli.main(["plot", str(path), "--resample", "0.002", "--window", "7", "9",
                     "--out", str(tmp_path / "p.png")]) == 0
    capsys.readouterr()


def test_predict_writes_the_runs_of_a_split_log_one_after_the_other(uniform, tmp_path, capsys):
    import json

    from greybox.models.files import save_model
    from greybox.models.friction import StribeckModel

    raw, reference = uniform
    save_model(StribeckModel().fit(reference), tmp_path / "m.gbm")
    keep = np.ones(len(raw), dtype=bool)
    keep[2000:2040] = False
    write_log(AxisLog(time=raw.time[keep], position=raw.position[keep], effort=raw.effort[keep], axis="X"),
              tmp_path / "gappy.csv")
    out = tmp_path / "p.csv"
    status = cli.main(["predict", str(tmp_path / "m.gbm"), str(tmp_path / "gappy.csv"), "--out", str(out),
                       "--resample", "0.002", "--quiet"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "in 2 runs" in captured.out
    runs = json.loads(Path(str(out) + ".json").read_text())["attrs"]["runs"]
    assert [run["start_s"] for run in runs] == pytest.approx([0.0, raw.time[2040]])
    import pandas as pd

    table = pd.read_csv(out)
    assert len(table) == sum(run["samples"] for run in runs) and np.all(np.diff(table["time_s"]) > 0)


def test_time_tolerance_reaches_the_preparation(uniform, tmp_path, capsys):
    raw, _ = uniform
    time = raw.time.copy()
    time[1::2] += 0.3 * STEP  # every other step 30 % long, the next 30 % short
    path = tmp_path / "jitter.csv"
    write_log(raw.replace(time=time), path)
    assert cli.main(["info", str(path)]) == 2
    assert "tolerance 25%" in capsys.readouterr().err
    assert cli.main(["info", str(path), "--time-tolerance", "0.4"]) == 0


@pytest.mark.parametrize("scale, column, message", [
    ({"position": 1e-3}, "position", "position is probably in m under a mm name"),
    ({"velocity": 60.0}, "velocity", "velocity is probably in mm/min under a mm/s name"),
    ({"velocity": 1 / 60.0}, "velocity", "velocity is probably in mm/s under a mm/min name"),
    ({"velocity": -1.0}, "velocity", "opposite sign"),
])
def test_a_unit_slip_between_velocity_and_position_is_named(scale, column, message, tmp_path, capsys):
    log = make_dataset("X", "C", seed=42, duration_s=10)
    assert prepare([log])[0].is_prepared  # as logged: consistent
    slipped = log.replace(**{name: getattr(log, name) * factor for name, factor in scale.items()})
    with pytest.raises(LogError, match=message):
        prepare([slipped])
    path = tmp_path / "slipped.csv"
    write_log(slipped, path)
    assert cli.main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and message in err and "--columns" in err or "opposite" in err


def test_resampling_a_log_already_on_the_grid_changes_nothing(uniform):
    raw, reference = uniform
    logged = make_dataset("X", "C", seed=41, duration_s=20)  # with its logged velocity, ending at rest
    (again,) = prepare([logged], sample_time=STEP)
    (plain,) = prepare([logged])
    np.testing.assert_array_equal(again.velocity, plain.velocity)
    np.testing.assert_array_equal(again.time, plain.time)
