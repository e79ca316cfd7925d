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


def test_a_signal_while_the_temporary_file_is_made_leaves_no_file(tmp_path, monkeypatch):
    """SIGTERM right after the temporary file exists (before the block that removes it) is held back."""
    import signal
    import tempfile

    from greybox.atomic import atomic_output

    class Stop(Exception):
        pass

    def stop(signum, frame):
        raise Stop()

    made = tempfile.mkstemp

    def mkstemp_then_signal(*args, **kwargs):
        result = made(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGTERM)  # arrives here unless held back
        return result

    previous = signal.signal(signal.SIGTERM, stop)
    monkeypatch.setattr(tempfile, "mkstemp", mkstemp_then_signal)
    try:
        with pytest.raises(Stop):
            with atomic_output(tmp_path / "out.csv") as temporary:
                temporary.write_text("never finished")
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert list(tmp_path.iterdir()) == []
