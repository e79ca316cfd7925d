"""The test suite's own rules (tests/conftest.py): real data sets skip by name when missing; no skips in CI."""

from __future__ import annotations

from pathlib import Path

import pytest

CONFTEST = Path(__file__).with_name("conftest.py").read_text()

USES_REAL_DATA = """
def test_reads_emps(real_data):
    assert (real_data("EMPS") / "DATA_EMPS.mat").read_text() == "stand-in"

def test_needs_nothing():
    assert True
"""


@pytest.fixture
def inner(pytester, monkeypatch, tmp_path):
    """A pytest run of its own with this suite's conftest, real data in an empty folder, no CI variable."""
    pytester.makeconftest(CONFTEST)
    real = tmp_path / "real"
    real.mkdir()
    monkeypatch.setenv("GREYBOX_REAL_DATA", str(real))
    monkeypatch.delenv("GREYBOX_NO_SKIP", raising=False)
    return pytester, real


def test_a_missing_real_data_folder_skips_naming_the_folder(inner):
    pytester, real = inner
    pytester.makepyfile(USES_REAL_DATA)
    result = pytester.runpytest("-rs")
    result.assert_outcomes(passed=1, skipped=1)
    assert result.ret == pytest.ExitCode.OK
    result.stdout.fnmatch_lines([f"SKIPPED*real data set EMPS not found: no folder {real / 'EMPS'}*"])


def test_a_present_real_data_folder_is_used(inner):
    pytester, real = inner
    (real / "EMPS").mkdir()
    (real / "EMPS" / "DATA_EMPS.mat").write_text("stand-in")
    pytester.makepyfile(USES_REAL_DATA)
    pytester.runpytest().assert_outcomes(passed=2)


def test_real_data_tests_carry_the_marker(inner):
    pytester, _ = inner
    pytester.makepyfile(USES_REAL_DATA)
    result = pytester.runpytest("-m", "not real_data")
    result.assert_outcomes(passed=1, deselected=1)


def test_with_no_skip_set_a_skipped_test_fails_the_run(inner, monkeypatch):
    pytester, real = inner
    pytester.makepyfile(USES_REAL_DATA)
    monkeypatch.setenv("GREYBOX_NO_SKIP", "1")
    result = pytester.runpytest()
    result.assert_outcomes(passed=1, skipped=1)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*GREYBOX_NO_SKIP=1: skipped tests fail this run*",
                                 f"*::test_reads_emps: *real data set EMPS not found: no folder {real / 'EMPS'}*"])


def test_with_no_skip_set_a_skipped_module_fails_the_run(inner, monkeypatch):
    pytester, _ = inner
    pytester.makepyfile(test_skipped="import pytest\npytest.skip('whole module', allow_module_level=True)\n",
                        test_passes="def test_passes():\n    assert True\n")
    monkeypatch.setenv("GREYBOX_NO_SKIP", "1")
    result = pytester.runpytest()
    result.assert_outcomes(passed=1, skipped=1)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*test_skipped.py: *whole module*"])


def test_with_no_skip_set_a_clean_run_passes_and_xfail_is_no_skip(inner, monkeypatch):
    pytester, real = inner
    (real / "EMPS").mkdir()
    (real / "EMPS" / "DATA_EMPS.mat").write_text("stand-in")
    pytester.makepyfile(USES_REAL_DATA + """
import pytest

@pytest.mark.xfail(reason="known", strict=True)
def test_known_failure():
    assert False
""")
    monkeypatch.setenv("GREYBOX_NO_SKIP", "1")
    result = pytester.runpytest()
    result.assert_outcomes(passed=2, xfailed=1)
    assert result.ret == pytest.ExitCode.OK
