"""Parquet axis logs: round trip with metadata, files from other tools."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from greybox.data.io import read_log, write_log
from greybox.errors import LogError


def test_round_trip_is_exact_and_keeps_metadata(tmp_path, make_log):
    rng = np.random.default_rng(9)
    log = make_log(
        effort_unit="N",
        velocity=rng.normal(size=2000),
        acceleration=rng.normal(size=2000),
        extras={"truth_friction_N": rng.normal(size=2000)},
        attrs={"seed": 9, "hidden": ["thermal"]},
    )
    path = tmp_path / "axis.parquet"
    write_log(log, path)
    back = read_log(path)
    for name in ("time", "position", "effort", "velocity", "acceleration"):
        assert np.array_equal(getattr(back, name), getattr(log, name)), name
    assert np.array_equal(back.extras["truth_friction_N"], log.extras["truth_friction_N"])
    assert (back.axis, back.dataset, back.effort_unit, back.attrs) == ("X", "T", "N", log.attrs)
    stored = json.loads(pq.read_schema(path).metadata[b"greybox"])
    assert stored["effort_unit"] == "N"


def test_file_from_another_tool_with_units_and_pq_extension(tmp_path):
    path = tmp_path / "export.pq"
    pq.write_table(
        pa.table(
            {
                "time_ms": pa.array([0, 2, 4], pa.int64()),
                "position_m": [0.1, 0.2, 0.3],
                "current_mA": pa.array([100, 200, 300], pa.int32()),
                "label": ["a", "b", "c"],
            }
        ),
        path,
    )
    log = read_log(path)
    np.testing.assert_allclose(log.time, [0.0, 0.002, 0.004])
    np.testing.assert_allclose(log.position, [100.0, 200.0, 300.0])
    np.testing.assert_allclose(log.current, [0.1, 0.2, 0.3])
    assert log.extras == {} and log.axis == ""


def test_not_a_parquet_file(tmp_path):
    path = tmp_path / "fake.parquet"
    path.write_bytes(b"PAR1 this is not a parquet file at all")
    with pytest.raises(LogError, match="not a readable Parquet file") as error:
        read_log(path)
    assert str(path) in str(error.value)
