"""The rolling recording: files written by a thread of their own, one row group each, all there after close."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from greybox.errors import GreyboxError
from greybox.live.estimator import LiveEstimator
from greybox.live.recording import Recorder
from greybox.persistence import load_model


def _results(model, log, size=10):
    estimator = LiveEstimator(model)
    out = []
    for k in range(0, len(log), size):
        out += estimator.step(log.select(slice(k, k + size))).results
    return out + estimator.finish().results


def test_files_hold_the_estimates_in_one_row_group_each(tmp_path, model_file, cut_raw):
    model = load_model(model_file("gms"))
    results = _results(model, cut_raw)
    recorder = Recorder(tmp_path / "rec", model=model, chunk_s=60.0, every_s=0.5)
    for result in results:
        recorder.add(result)
    recorder.close()
    assert len(recorder.written) >= 3 and all(path.exists() for path in recorder.written)
    files = [pq.ParquetFile(path) for path in recorder.written]
    assert [file.num_row_groups for file in files] == [1] * len(files)
    places = [json.loads(file.schema_arrow.metadata[b"greybox"])["attrs"]["live"]["file"] for file in files]
    assert places == list(range(len(files)))
    recorded = np.concatenate([file.read(columns=["current_model_A"]).column(0).to_numpy() for file in files])
    np.testing.assert_array_equal(recorded, np.concatenate([result.model for result in results]))


def test_a_file_that_cannot_be_written_is_reported_at_close(tmp_path, model_file, cut_raw):
    model = load_model(model_file("gms"))
    result = _results(model, cut_raw)[0]
    recorder = Recorder(tmp_path / "rec", model=model, chunk_s=60.0, every_s=60.0)
    recorder.add(dataclasses.replace(result, model=np.full(len(result.time), np.inf)))
    with pytest.raises(GreyboxError, match="not finite"):
        recorder.close()
    assert recorder.written == [] and not list((tmp_path / "rec").iterdir())
