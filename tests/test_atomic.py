"""Atomic output: a failed write leaves the old file and no temporary behind."""

import os
import stat

import pytest

from greybox.atomic import atomic_output, write_text_atomic


def test_success_replaces_target_with_plain_permissions(tmp_path):
    target = tmp_path / "report.md"
    target.write_text("old")
    write_text_atomic(target, "new")
    assert target.read_text() == "new"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.md"]


def test_failure_keeps_old_content_and_removes_temporary(tmp_path):
    target = tmp_path / "model.gbm"
    target.write_text("precious")
    with pytest.raises(RuntimeError):
        with atomic_output(target) as temporary:
            temporary.write_text("half")
            raise RuntimeError("writer died")
    assert target.read_text() == "precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.gbm"]


def test_missing_directory_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_text_atomic(tmp_path / "nowhere" / "x.txt", "x")


def test_a_signal_right_after_the_temporary_file_is_made_leaves_no_file(tmp_path, monkeypatch):
    """SIGTERM the moment the temporary file exists: its handler's exception still finds the file and removes it."""
    import signal

    from greybox import atomic

    class Stop(Exception):
        pass

    def stop(signum, frame):
        raise Stop()

    made = os.open

    def open_then_signal(name, *args, **kwargs):
        handle = made(name, *args, **kwargs)
        if str(name).endswith(".tmp"):
            os.kill(os.getpid(), signal.SIGTERM)  # the handler runs before the descriptor is even closed
        return handle

    previous = signal.signal(signal.SIGTERM, stop)
    monkeypatch.setattr(atomic.os, "open", open_then_signal)
    try:
        with pytest.raises(Stop):
            with atomic.atomic_output(tmp_path / "out.csv") as temporary:
                temporary.write_text("never finished")
    finally:
        monkeypatch.undo()
        signal.signal(signal.SIGTERM, previous)
    assert list(tmp_path.iterdir()) == []
