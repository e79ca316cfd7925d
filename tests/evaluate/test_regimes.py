"""The rows of :func:`greybox.evaluate.regimes.metrics_by_regime` that split the samples by a model's training
region (issue 30); the operating regimes themselves are tested in tests/test_metrics.py."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.evaluate.regimes import REGIME_NAMES, TRAINING_REGION_NAMES, metrics_by_regime
from greybox.metrics import rmse


def _runs():
    runs = []
    for seed, n in ((0, 400), (1, 300)):
        time = np.arange(n) * 0.002
        position = 10.0 * np.sin(2.0 * np.pi * time)
        runs.append(AxisLog(time=time, position=position, effort=np.random.default_rng(seed).normal(0, 0.1, n)))
    return prepare(runs)


def test_the_training_region_rows_come_only_with_the_flags_and_split_every_sample_once():
    runs = _runs()
    predicted = [np.zeros(len(run)) for run in runs]
    assert set(metrics_by_regime(runs, predicted)) == set(REGIME_NAMES)
    flags = [run.position > 5.0 for run in runs]
    result = metrics_by_regime(runs, predicted, outside=flags)
    assert set(result) == set(REGIME_NAMES) | set(TRAINING_REGION_NAMES)
    inside, outside = (result[name] for name in TRAINING_REGION_NAMES)
    beyond = np.concatenate(flags)
    measured = np.concatenate([run.effort for run in runs])
    assert outside["n"] == beyond.sum() and inside["n"] + outside["n"] == result["all"]["n"]
    assert outside["rmse"] == pytest.approx(rmse(measured[beyond], 0.0 * measured[beyond]))
    assert inside["rmse"] == pytest.approx(rmse(measured[~beyond], 0.0 * measured[~beyond]))
    assert metrics_by_regime(runs, predicted, outside=[f & False for f in flags])["outside_training"]["n"] == 0


def test_flags_of_another_length_are_refused():
    runs = _runs()
    with pytest.raises(ValueError, match="training-region flags"):
        metrics_by_regime(runs, [np.zeros(len(run)) for run in runs], outside=[np.zeros(3, bool), np.zeros(3, bool)])
