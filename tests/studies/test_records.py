"""Records: made by their command, refused when measured on uncommitted code, stale after a change."""

from __future__ import annotations

import json
import shutil
import subprocess

import pytest

from greybox.errors import GreyboxError
from studies.records import MEASURING, SPECS, RecordSpec, measure, stale_commits, uncommitted

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="the records are checked against git history")


def _git(root, *args):
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=root, check=True,
                   capture_output=True)


@pytest.fixture
def repo(tmp_path):
    """A repository with a measuring script that prints its figures as JSON, and a module it measures."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "model.py").write_text("GAIN = 2\n")
    (tmp_path / "other.txt").write_text("not measured\n")
    (tmp_path / "bench.py").write_text(
        "import json, os, sys\nsys.path.insert(0, '.')\nfrom pkg.model import GAIN\n"
        "print('progress line')\nprint(json.dumps({'gain': GAIN, 'measuring': os.environ.get(sys.argv[1])},"
        " indent=1))\n")
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "commit", "-qm", "first")
    return tmp_path


SPEC = RecordSpec("gain", ("bench.py", MEASURING), ("pkg", "bench.py"), "the gain")


def test_a_record_holds_the_figures_its_command_printed_and_where_they_were_measured(repo):
    record = measure(SPEC, root=repo)
    assert record["figures"] == {"gain": 2, "measuring": "gain"}
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=repo, capture_output=True, text=True).stdout.strip()
    assert record["commit"] == head and record["uncommitted"] == []
    assert len(record["load_before"]) == 3 and record["cores"] >= 1 and record["versions"]["python"]
    assert record["command"] == f"python bench.py {MEASURING}" and record["depends_on"] == ["pkg", "bench.py"]
    json.dumps(record, allow_nan=False)


def test_uncommitted_changes_to_what_a_record_measures_are_refused_unless_allowed(repo):
    (repo / "other.txt").write_text("changed, but not measured\n")
    assert uncommitted(SPEC.depends_on, root=repo) == []
    measure(SPEC, root=repo)
    (repo / "pkg" / "model.py").write_text("GAIN = 3\n")
    with pytest.raises(GreyboxError, match="uncommitted changes in what it measures.*pkg/model.py"):
        measure(SPEC, root=repo)
    record = measure(SPEC, root=repo, allow_dirty=True)
    assert record["figures"]["gain"] == 3 and record["uncommitted"] == ["pkg/model.py"]


def test_a_record_is_stale_after_a_commit_to_what_it_depends_on_and_only_then(repo):
    record = measure(SPEC, root=repo)
    assert stale_commits(record, root=repo) == []
    (repo / "other.txt").write_text("changed\n")
    _git(repo, "commit", "-qam", "a change elsewhere")
    assert stale_commits(record, root=repo) == []
    (repo / "pkg" / "model.py").write_text("GAIN = 3\n")
    _git(repo, "commit", "-qam", "the gain changes")
    stale = stale_commits(record, root=repo)
    assert len(stale) == 1 and stale[0].endswith("the gain changes")


def test_a_record_of_a_commit_outside_the_history_is_stale(repo):
    record = {**measure(SPEC, root=repo), "commit": "0" * 40}
    assert stale_commits(record, root=repo) == [f"{'0' * 9} is not in the history of HEAD"]


def test_a_command_that_fails_or_prints_no_object_makes_no_record(repo):
    (repo / "fails.py").write_text("import sys\nprint('{}')\nsys.exit(1)\n")
    (repo / "silent.py").write_text("print('done')\n")
    _git(repo, "add", ".")
    _git(repo, "commit", "-qm", "scripts")
    with pytest.raises(GreyboxError, match="exited with status 1"):
        measure(RecordSpec("f", ("fails.py",), ("pkg",), ""), root=repo)
    with pytest.raises(GreyboxError, match="printed no JSON object"):
        measure(RecordSpec("s", ("silent.py",), ("pkg",), ""), root=repo)


def test_every_spec_names_a_command_and_paths_of_the_repository():
    from studies.records import ROOT

    for spec in SPECS.values():
        assert (ROOT / spec.command[0]).is_file(), spec.name
        assert all((ROOT / path).exists() for path in spec.depends_on), spec.name
        assert spec.command[0] in spec.depends_on, f"{spec.name}: a change to its own command must make it stale"
