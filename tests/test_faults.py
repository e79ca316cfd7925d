"""Fault suite of issue 41 (and the two small items of issue 40): each fault, reproduced, gives its documented outcome.

Fast cases run by default; the fleet, concurrency and history cases are beside their modules
(``tests/fleet/test_engine.py``, ``tests/fleet/test_predict.py``, ``tests/monitor/test_monitor_history.py``,
``tests/models/test_files.py``).
"""

from __future__ import annotations

import errno
import json
import os
import zipfile

import numpy as np
import pytest

import greybox.cli as cli
from greybox import atomic
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.models import files


def _log(axis: str, seed: int = 0, n: int = 1500, dt: float = 0.002) -> AxisLog:
    t = np.arange(n) * dt
    velocity = 30 * 2 * np.pi * 0.6 * np.cos(2 * np.pi * 0.6 * t + seed)
    position = 30 * np.sin(2 * np.pi * 0.6 * t + seed)
    current = 0.8 * np.sign(velocity) + 0.01 * velocity + 0.05 * np.sin(7 * t + seed)
    return AxisLog(time=t, position=position, effort=current, axis=axis, velocity=velocity)


@pytest.fixture
def logs(tmp_path):
    paths = {}
    for name, axis, seed in (("x1", "X", 0), ("x2", "X", 1), ("y1", "Y", 2)):
        paths[name] = tmp_path / f"{name}.csv"
        write_log(_log(axis, seed), paths[name])
    return paths


def _main(capsys, *argv):
    status = cli.main([str(part) for part in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _train(capsys, out, *logs):
    return _main(capsys, "train", "--model", "coulomb", "--train", *logs, "--out", out, "--quiet")


def test_training_refuses_logs_of_two_axes_and_records_the_axis(logs, tmp_path, capsys):
    # before: exit 0, one model of X and Y, no axis recorded
    status, _, err = _train(capsys, tmp_path / "xy.gbm", logs["x1"], logs["y1"])
    assert status == 2 and "different axes (axis X: x1.csv; axis Y: y1.csv)" in err and "--axes" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "xy.gbm").exists()
    status, _, err = _train(capsys, tmp_path / "x.gbm", logs["x1"], logs["x2"])
    assert status == 0, err
    assert files.load_model(tmp_path / "x.gbm", records=True)[1]["training"]["axis"] == "X"
    status, out, _ = _main(capsys, "info", tmp_path / "x.gbm")
    assert "  axis           = X" in out


def test_predict_warns_of_a_log_of_another_axis_and_of_calibrating_on_a_training_file(logs, tmp_path, capsys):
    assert _train(capsys, tmp_path / "x.gbm", logs["x1"])[0] == 0
    status, _, err = _main(capsys, "predict", tmp_path / "x.gbm", logs["y1"], "--out", tmp_path / "y.parquet",
                           "--quiet")
    assert status == 0 and "y1.csv is of axis Y, but x.gbm was trained on axis X" in err
    status, _, err = _main(capsys, "predict", tmp_path / "x.gbm", logs["x2"], "--out", tmp_path / "x2.parquet",
                           "--calibration", logs["x1"], "--quiet")
    assert status == 0 and "calibration log x1.csv is the training file x1.csv of x.gbm (the same SHA-256)" in err
    assert "is of axis" not in err
    status, _, err = _main(capsys, "predict", tmp_path / "x.gbm", logs["x1"], "--out", tmp_path / "x1.parquet",
                           "--calibration", logs["x2"], "--quiet")
    assert status == 0 and "training file" not in err


def test_a_full_disk_or_read_only_file_system_is_one_line_naming_the_file(logs, tmp_path, capsys, monkeypatch):
    assert _train(capsys, tmp_path / "x.gbm", logs["x1"])[0] == 0
    for code in (errno.ENOSPC, errno.EROFS, errno.EACCES):
        def refused(source, target, code=code):
            raise OSError(code, os.strerror(code), str(source))

        monkeypatch.setattr(atomic.os, "replace", refused)
        out = tmp_path / "out.parquet"
        status, _, err = _main(capsys, "predict", tmp_path / "x.gbm", logs["x2"], "--out", out, "--quiet")
        assert status == 2 and err.strip().splitlines() == [f"greybox predict: error: {out}: {os.strerror(code)}"]
        assert not out.exists() and not list(tmp_path.glob(".out.parquet.*.tmp"))  # the temporary removed
        status, _, err = _train(capsys, tmp_path / "again.gbm", logs["x1"])
        assert status == 2 and err.strip().splitlines() == [
            f"greybox train: error: {tmp_path / 'again.gbm'}: {os.strerror(code)}"]


def test_an_unexpected_error_is_one_line_and_its_traceback_only_with_debug(logs, tmp_path, capsys, monkeypatch):
    assert _train(capsys, tmp_path / "x.gbm", logs["x1"])[0] == 0

    def bug(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(files, "_check_digest", bug)
    status, _, err = _main(capsys, "info", tmp_path / "x.gbm")
    assert status == 2 and err.strip().splitlines() == [
        "greybox info: internal error: ZeroDivisionError: a bug (a bug: please report it with the output of "
        "'greybox --debug ...')"]
    with pytest.raises(ZeroDivisionError):
        cli.main(["--debug", "info", str(tmp_path / "x.gbm")])


def test_a_plant_key_file_signs_and_checks_model_files(logs, tmp_path, capsys, monkeypatch):
    monkeypatch.delenv(files.KEY_ENV, raising=False)
    monkeypatch.delenv(files.KEY_FILE_ENV, raising=False)
    key = tmp_path / "plant.key"
    key.write_text("a secret of the plant\n")
    assert _train(capsys, tmp_path / "unsigned.gbm", logs["x1"])[0] == 0
    assert _main(capsys, "--key-file", key, "train", "--model", "coulomb", "--train", logs["x1"], "--out",
                 tmp_path / "signed.gbm", "--quiet")[0] == 0
    assert os.environ.get(files.KEY_FILE_ENV) is None  # the option holds for its command only
    assert _main(capsys, "--key-file", key, "info", tmp_path / "signed.gbm")[0] == 0
    status, _, err = _main(capsys, "--key-file", key, "info", tmp_path / "unsigned.gbm")
    assert status == 2 and "unsigned.gbm: not signed, and the plant's key is set" in err
    # the training record edited inside the ZIP (a forged training error): refused without a key too
    with zipfile.ZipFile(tmp_path / "signed.gbm") as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    document = json.loads(members["model.json"])
    document["records"]["training"]["training_error"]["rmse"] = 1e-9
    members["model.json"] = json.dumps(document).encode()
    with zipfile.ZipFile(tmp_path / "forged.gbm", "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    status, out, err = _main(capsys, "info", tmp_path / "forged.gbm")
    assert status == 2 and "member model.json was changed after the file was written" in err and "1e-09" not in out


def test_warnings_reach_the_terminal_as_one_note_line(logs, tmp_path, capsys):
    path = tmp_path / "x.gbm"
    assert _train(capsys, path, logs["x1"])[0] == 0
    with zipfile.ZipFile(path) as archive:  # a file of before the digest: loads with a warning
        members = {name: archive.read(name) for name in archive.namelist() if name != files.DIGEST_MEMBER}
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    status, _, err = _main(capsys, "info", path)
    notes = [line for line in err.splitlines() if "written before model files carried a digest" in line]
    assert status == 0 and len(notes) == 1 and notes[0].startswith("note: ")
    assert "warnings.warn" not in err and "UserWarning" not in err and ".py:" not in err


def test_a_killed_writers_temporary_file_is_removed_by_the_next_write(tmp_path):
    target = tmp_path / "out.parquet"
    dead = tmp_path / f".out.parquet.{2**22 + 12345}-0123456789abcdef.tmp"  # a process id no process has
    dead.write_bytes(b"x" * 1000)
    os.utime(dead, (1e9, 1e9))
    alive = tmp_path / f".out.parquet.{os.getpid()}-0123456789abcdef.tmp"  # a writer still running: kept
    alive.write_bytes(b"x")
    os.utime(alive, (os.path.getmtime(alive) - 3600,) * 2)
    atomic.write_text_atomic(target, "new")
    assert not dead.exists() and alive.exists() and target.read_text() == "new"


@pytest.mark.parametrize("model", ["coulomb", "auto"])
def test_an_all_zero_current_is_refused_in_one_line(tmp_path, capsys, model):
    # before, with --model auto: a ValueError traceback from the choice ("min() arg is an empty sequence")
    paths = []
    for seed in (0, 1):
        log = _log("X", seed)
        paths.append(tmp_path / f"zero{seed}.csv")
        write_log(AxisLog(time=log.time, position=log.position, effort=np.zeros_like(log.time), axis="X"), paths[-1])
    status, _, err = _main(capsys, "train", "--model", model, "--train", *paths, "--out", tmp_path / "z.gbm",
                           "--quiet")
    assert status == 2 and err.strip().splitlines() == [
        "greybox train: error: the effort of the training logs is zero throughout (zero0.csv, zero1.csv): nothing "
        "to fit; check the effort column (--columns) or the drive's recording"]


def test_the_staging_file_of_a_killed_parquet_writer_is_removed_by_the_next_write(tmp_path):
    # before: ".blocks.XXXX.tmp" (uncompressed, megabytes) stayed for good after a SIGKILL
    from greybox.errors import GreyboxError
    from greybox.predict.output import write_process_blocks

    target = tmp_path / "out.parquet"
    seen = []

    def blocks():  # looks at the directory while the writer runs, then stops it
        seen.extend(path.name for path in tmp_path.iterdir())
        raise GreyboxError("stop")
        yield

    with pytest.raises(GreyboxError, match="stop"):
        write_process_blocks(blocks(), target, metadata=dict)
    prefix = f".{target.name}.{os.getpid()}-"  # the writer's process, as remove_stale_temporaries reads it
    assert any(name.startswith(prefix) and name.endswith(".blocks.tmp") for name in seen), seen
    assert list(tmp_path.iterdir()) == []  # an error (not a kill) leaves nothing
    staging = tmp_path / f".out.parquet.{2**22 + 12345}-0123456789abcdef.tmp.01234567.blocks.tmp"
    staging.write_bytes(b"x" * 1000)
    os.utime(staging, (1e9, 1e9))
    atomic.write_text_atomic(target, "new")
    assert not staging.exists()


def test_a_fleet_output_of_the_earlier_naming_is_refused_before_any_work(tmp_path):
    # its outputs (log=<file stem>) would stay beside the new ones and be read twice as one dataset
    from greybox.errors import GreyboxError
    from greybox.fleet.predict import FleetJob, run_fleet

    out = tmp_path / "results"
    out.mkdir()
    (out / "_manifest.json").write_text(json.dumps({"format": "greybox-fleet", "format_version": 2, "logs": []}))
    job = FleetJob(str(tmp_path / "m1" / "a.csv"), "m1", str(tmp_path / "absent.gbm"), str(out), "a.csv")
    with pytest.raises(GreyboxError, match="earlier greybox, whose outputs are named otherwise"):
        run_fleet([job])
    assert sorted(path.name for path in out.iterdir()) == ["_manifest.json"]
