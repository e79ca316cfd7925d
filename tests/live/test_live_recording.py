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
from greybox.models.files import load_model


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


def test_part_files_hold_what_a_kill_would_leave_and_go_once_the_file_is_whole(tmp_path, model_file, cut_raw):
    import pandas as pd

    model = load_model(model_file("gms"))
    results = _results(model, cut_raw)
    folder = tmp_path / "rec"
    recorder = Recorder(folder, model=model, chunk_s=60.0, every_s=60.0, flush_s=0.2)
    added = []
    for result in results:
        recorder.add(result)
        added.append(result)
        recorder._collect(wait=False)
        recorder._writer is None or recorder._writer.submit(lambda: None).result()  # the writer done with the parts
        parts = sorted(folder.glob("live-*.part-*.parquet"))
        on_disk = pd.concat([pd.read_parquet(part) for part in parts]) if parts else pd.DataFrame({"time_s": []})
        everything = np.concatenate([part.time for part in added])
        # what is on disk is the estimates in order, all but less than flush_s of log time at the end
        np.testing.assert_array_equal(on_disk["time_s"].to_numpy(), everything[:len(on_disk)])
        assert everything[-1] - (on_disk["time_s"].iloc[-1] if len(on_disk) else everything[0] - 0.002) < 0.2 + 0.03
    assert len(list(folder.glob("live-*.part-*.parquet"))) >= 5
    recorder.close()
    assert [path.name for path in sorted(folder.iterdir())] == [path.name for path in recorder.written]
    whole = pd.read_parquet(recorder.written[0])
    np.testing.assert_array_equal(whole["time_s"].to_numpy(), np.concatenate([part.time for part in results]))
