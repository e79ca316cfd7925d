"""Calibrated intervals of the process current and force: split conformal per regime."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.axis_config import read_axis_config
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.evaluate.regimes import RegimeThresholds, regime_masks
from greybox.models.files import save_model
from greybox.models.friction import LuGreModel
from greybox.predict.interval import INTERVAL_CLASSES, _conformal_half_width, calibrate_interval, interval_classes
from greybox.predict.process import predict_process
from greybox.twin import make_dataset
from greybox.twin.cutting import CuttingSpec

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"


def _read_table(path: Path) -> pd.DataFrame:
    if path.suffix == ".csv":
        return pd.read_csv(path)
    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    return pd.DataFrame(read_log(path, columns={"current_A": "current_measured_A"}).extras)



def test_conformal_rank_is_ceil_of_n_plus_one_times_the_coverage():
    errors = -np.arange(1.0, 20.0)  # |e| = 1 ... 19
    assert _conformal_half_width(errors, 0.95) == 19.0  # ceil(20 * 0.95) = 19
    assert _conformal_half_width(errors, 0.5) == 10.0  # ceil(10) = 10
    assert _conformal_half_width(errors[:10], 0.95) == 10.0  # rank 11 > n: the largest


@pytest.fixture(scope="module")
def fitted():
    """LuGre on a twin air cut; two other draws of the same kind of motion to calibrate and to check."""
    train, calibration, check = prepare([make_dataset("X", "C", seed=s, duration_s=40) for s in (21, 22, 23)])
    return LuGreModel(n_starts=1, max_iter=150).fit(train), calibration, check


def test_every_sample_falls_in_one_class_and_reversals_win(fitted):
    _, log, _ = fitted
    thresholds = RegimeThresholds.from_logs(log)
    classes = interval_classes(log, thresholds)
    assert classes.min() >= 0 and classes.max() < len(INTERVAL_CLASSES)
    masks = regime_masks(log, thresholds)
    assert np.all(classes[masks["reversal"]] == INTERVAL_CLASSES.index("reversal"))
    assert set(np.unique(classes)) == set(range(len(INTERVAL_CLASSES)))


def test_the_interval_covers_new_air_cut_errors_at_about_its_nominal_rate(fitted):
    model, calibration, check = fitted
    for coverage in (0.8, 0.95):
        interval = calibrate_interval(model, calibration, coverage=coverage)
        covered = np.abs(check.effort - model.predict(check)) <= interval.half_widths(check)
        assert abs(covered.mean() - coverage) < 0.03, coverage
    # Reversals are harder than constant feed: a wider half-width.
    assert interval.half_width_A["reversal"] > interval.half_width_A["constant_feed"]
    with pytest.raises(GreyboxError, match="coverage must be a fraction"):
        calibrate_interval(model, calibration, coverage=1.0)


def test_bounds_of_force_follow_the_conversion_and_hold_the_estimate(fitted):
    model, calibration, _ = fitted
    cut = prepare([make_dataset("X", "C", seed=24, duration_s=20, cutting=CuttingSpec(return_pass=-0.5))])[0]
    config = read_axis_config(EXAMPLE)
    interval = calibrate_interval(model, calibration)
    result = predict_process(model, cut, axis_config=config, interval=interval)
    lower, upper = result.process_bounds
    np.testing.assert_allclose(upper - lower, 2 * interval.half_widths(cut))
    force_low, force_high = result.load_bounds
    assert np.all(force_low <= result.load) and np.all(result.load <= force_high)
    np.testing.assert_array_equal(force_low, config.process_load(lower, cut.velocity))
    truth = cut.extras["truth_process_force_N"]
    covered = np.mean((force_low <= truth) & (truth <= force_high))
    assert 0.9 < covered <= 1.0
    assert result.attrs["interval"]["coverage"] == 0.95
    columns = result.columns()
    assert list(columns)[3:9] == ["current_process_A", "current_process_lower_A", "current_process_upper_A",
                                  "force_process_N", "force_process_lower_N", "force_process_upper_N"]

    matplotlib.use("Agg")
    from greybox.predict.plot import plot_process

    figure = plot_process(result)
    labels = [collection.get_label() for collection in figure.axes[2].collections]
    assert "95 % interval" in labels
    assert [label for label in labels if label != "95 % interval"] == (
        [next(label for label in labels if label.startswith("outside"))] if result.outside.any() else [])
    matplotlib.pyplot.close(figure)


@pytest.fixture(scope="module")
def cli_files(tmp_path_factory, fitted):
    root = tmp_path_factory.mktemp("interval")
    model, calibration, _ = fitted
    save_model(model, root / "m.gbm")
    write_log(make_dataset("X", "C", seed=22, duration_s=40), root / "air.mcap")
    write_log(make_dataset("X", "C", seed=25, duration_s=10, cutting=True), root / "cut.mcap")
    return root


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_predict_writes_bounds_in_every_format(cli_files, capsys, suffix):
    out = cli_files / f"p{suffix}"
    status = cli.main(["predict", str(cli_files / "m.gbm"), str(cli_files / "cut.mcap"), "--out", str(out),
                       "--axis-config", str(EXAMPLE), "--calibration", str(cli_files / "air.mcap"),
                       "--interval", "0.9", "--quiet"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "interval 90 % (split conformal per regime on" in captured.out
    table = _read_table(out)
    assert np.all(table["current_process_lower_A"] <= table["current_process_upper_A"])
    assert np.all(table["force_process_lower_N"] <= table["force_process_N"])
    assert np.all(table["force_process_N"] <= table["force_process_upper_N"])


def test_interval_without_calibration_is_refused(cli_files, capsys):
    status = cli.main(["predict", str(cli_files / "m.gbm"), str(cli_files / "cut.mcap"), "--out",
                       str(cli_files / "x.csv"), "--interval", "0.9"])
    assert status == 2 and "--interval needs --calibration" in capsys.readouterr().err


def test_the_cutting_log_is_no_calibration_and_pooled_classes_are_said(cli_files, capsys):
    model, log = cli_files / "m.gbm", cli_files / "cut.mcap"
    status = cli.main(["predict", str(model), str(log), "--out", str(cli_files / "y.csv"), "--calibration", str(log)])
    err = capsys.readouterr().err
    assert status == 2 and "is the cutting log itself" in err
    status = cli.main(["predict", str(model), str(log), "--out", str(cli_files / "z.csv"), "--calibration",
                       str(cli_files / "air.mcap"), "--quiet"])
    out = capsys.readouterr().out
    assert status == 0
    line = next(text for text in out.splitlines() if text.startswith("  interval"))
    assert ("pooled" in line) == any(n < 200 for n in _samples(cli_files / "z.csv.json").values())


def _samples(sidecar):
    import json

    return json.loads(Path(sidecar).read_text())["attrs"]["interval"]["calibration_samples"]
