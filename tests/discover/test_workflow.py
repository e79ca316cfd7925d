"""The discovery workflow's model keeps the training record every trained model carries (issue 43, item 3)."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.discover.workflow import discover
from greybox.models.friction import CoulombModel
from studies.discovery import StudyCase, case_logs


@pytest.mark.slow  # a discovery run, > 5 s
def test_the_discovered_model_records_its_training_logs_and_fit(tmp_path):
    train, _, _ = case_logs(StudyCase("position_periodic_friction", 1.5, 3, "coulomb", 15.0))
    path = tmp_path / "train.csv"
    write_log(train.replace(acceleration=None, extras={}, attrs={}), path)
    runs = prepare([read_log(path)], cutoff_hz=40.0)
    result = discover(CoulombModel(), runs, max_effects=1, n_null=19, read={"cutoff_hz": 40.0})
    record = result.model.training_record_
    assert [entry["name"] for entry in record["files"]] == ["train.csv"]
    assert record["preparation"]["cutoff_hz"] == 40.0
    residual = runs[0].effort - result.model.predict(runs[0])
    assert record["training_error"]["rmse"] == pytest.approx(np.sqrt(np.mean(residual ** 2)), rel=1e-12)
