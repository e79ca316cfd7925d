"""Shared fixtures: small synthetic axis logs with known content; the real data sets; the no-skip rule.

Real data. Tests that read a third-party data set (EMPS, the UMich CNC mill, ...) take the fixture
``real_data`` and call ``real_data("EMPS")``: it returns the data set's folder, or skips the test with a
reason naming the missing folder. The folders are looked up in ``$GREYBOX_REAL_DATA`` if set, else in
``../shared/data/real`` beside the repository (README, "Real data for the tests"). Such tests carry the
marker ``real_data`` (``pytest -m "not real_data"`` leaves them out).

No skips. With ``GREYBOX_NO_SKIP=1`` (``.ci/run`` sets it when ``../shared`` exists) a session in which any
test or module was skipped fails (exit status 1), naming the skipped tests and their reasons.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from greybox.data.log import AxisLog

pytest_plugins = ["pytester"]

#: Default folder of the real data sets: ``../shared/data/real`` beside the repository.
SHARED_REAL_DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "real"


def real_data_root() -> Path:
    """The folder holding the real data sets: ``$GREYBOX_REAL_DATA`` if set, else ``../shared/data/real``."""
    override = os.environ.get("GREYBOX_REAL_DATA")
    return Path(override).expanduser().resolve() if override else SHARED_REAL_DATA


def real_data_folder(name: str) -> Path:
    """The folder of the real data set ``name``; skips the calling test if the folder is missing."""
    folder = real_data_root() / name
    if not folder.is_dir():
        pytest.skip(f"real data set {name} not found: no folder {folder} "
                    "(README, 'Real data for the tests'; or set GREYBOX_REAL_DATA)")
    return folder


@pytest.fixture(scope="session")
def real_data():
    """``real_data(name)``: the folder of a real data set, or a skip naming the missing folder."""
    return real_data_folder


class NoSkip:
    """Records every skipped test or module; with ``GREYBOX_NO_SKIP=1`` a session with a skip fails."""

    def __init__(self):
        self.skipped: list[tuple[str, str]] = []

    def _note(self, report):
        if report.skipped and not hasattr(report, "wasxfail"):  # an xfail is reported as skipped, too
            longrepr = report.longrepr
            reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
            self.skipped.append((report.nodeid, reason))

    def pytest_runtest_logreport(self, report):
        self._note(report)

    def pytest_collectreport(self, report):
        self._note(report)

    def pytest_terminal_summary(self, terminalreporter):
        if _no_skip() and self.skipped:
            terminalreporter.section("GREYBOX_NO_SKIP=1: skipped tests fail this run", red=True)
            for nodeid, reason in self.skipped:
                terminalreporter.line(f"{nodeid}: {reason}")

    @pytest.hookimpl(trylast=True)
    def pytest_sessionfinish(self, session, exitstatus):
        if _no_skip() and self.skipped and session.exitstatus == pytest.ExitCode.OK:
            session.exitstatus = pytest.ExitCode.TESTS_FAILED


def _no_skip() -> bool:
    return os.environ.get("GREYBOX_NO_SKIP", "") not in ("", "0")


def pytest_configure(config):
    config.addinivalue_line("markers", "real_data: reads a third-party data set (through the real_data fixture)")
    config.pluginmanager.register(NoSkip(), "greybox-no-skip")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if "real_data" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.real_data)


def sine_log(n: int = 2000, sample_time: float = 0.002, *, seed: int = 0, **fields) -> AxisLog:
    """A log of a sinusoidal stroke: position 50 sin(2 pi 0.5 t) mm, noisy current in A."""
    rng = np.random.default_rng(seed)
    time = np.arange(n) * sample_time
    position = 50.0 * np.sin(2 * np.pi * 0.5 * time)
    values = dict(
        time=time,
        position=position,
        effort=0.01 * np.gradient(position, sample_time) + rng.normal(0.0, 0.1, n),
        axis="X",
        dataset="T",
    )
    values.update(fields)
    return AxisLog(**values)


@pytest.fixture
def make_log():
    """Factory of small sinusoidal axis logs, see :func:`sine_log`."""
    return sine_log
