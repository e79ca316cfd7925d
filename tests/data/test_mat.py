"""MATLAB .mat logs: version 5 through SciPy, version 7.3 (HDF5) through h5py, variables mapped like columns."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import savemat

import greybox.cli as cli
from greybox.data.io import read_log
from greybox.errors import LogError
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def log():
    return make_dataset("X", "A", seed=51, duration_s=4)


def _write_v73(path, variables):
    """A MATLAB 7.3 file as MATLAB writes one: a 512-byte header, then HDF5 with column-major arrays."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as store:
        for name, value in variables.items():
            store.create_dataset(name, data=np.atleast_2d(value))  # a row vector, shown as (1, n)
    with open(path, "r+b") as stream:
        stream.write(b"MATLAB 7.3 MAT-file, written by a greybox test".ljust(128, b" "))


@pytest.mark.parametrize("version", ["5", "7.3"])
def test_a_mat_file_reads_with_a_variable_mapping_in_any_unit(tmp_path, log, version):
    variables = {"t": log.time, "x_m": log.position / 1000.0, "iq": log.effort, "other": np.arange(3.0)}
    path = tmp_path / f"v{version}.mat"
    if version == "5":
        savemat(path, {name: value.reshape(-1, 1) for name, value in variables.items()})  # column vectors
    else:
        _write_v73(path, variables)
    read = read_log(path, columns={"time_s": "t", "position_m": "x_m", "current_A": "iq"})
    np.testing.assert_allclose(read.time, log.time)
    np.testing.assert_allclose(read.position, log.position, rtol=1e-12)
    np.testing.assert_array_equal(read.effort, log.effort)
    assert read.dataset == f"v{version}"


def test_conventional_names_need_no_mapping_and_bad_files_are_one_line(tmp_path, log, capsys):
    path = tmp_path / "plain.mat"
    savemat(path, {"time_s": log.time, "position_mm": log.position, "current_A": log.effort})
    assert len(read_log(path)) == len(log)
    with pytest.raises(LogError, match="column 'iq' \\(mapped to current_A\\) not found"):
        read_log(path, columns={"current_A": "iq"})
    savemat(tmp_path / "matrix.mat", {"time_s": log.time, "position_mm": log.position,
                                      "current_A": np.ones((3, 4))})
    with pytest.raises(LogError, match="'current_A' has shape \\(3, 4\\); a channel must be a vector"):
        read_log(tmp_path / "matrix.mat", columns={"current_A": "current_A"})
    bad = tmp_path / "bad.mat"
    bad.write_bytes(b"MATLAB 5.0 MAT-file" + bytes(200))
    assert cli.main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "bad.mat" in err


def test_emps_variables_without_a_mapping_read_as_the_benchmark(tmp_path, log):
    path = tmp_path / "emps_like.mat"
    n = len(log)
    savemat(path, {"t": log.time.reshape(-1, 1), "qm": (log.position / 1000).reshape(-1, 1),
                   "vir": np.full((n, 1), 0.5), "gtau": np.array([[30.0]])})
    read = read_log(path)
    assert read.effort_unit == "N" and np.allclose(read.effort, 15.0) and read.attrs["gtau"] == 30.0


@pytest.mark.parametrize("size", [1, 20, 100])
def test_a_mat_file_cut_inside_its_header_is_one_clear_error(tmp_path, log, size):
    whole = tmp_path / "whole.mat"
    savemat(whole, {"time_s": log.time, "position_mm": log.position, "current_A": log.effort})
    cut = tmp_path / "cut.mat"
    cut.write_bytes(whole.read_bytes()[:size])
    with pytest.raises(LogError, match="cut.mat: not a readable MATLAB .mat file"):
        read_log(cut)
