"""Paths that the package, the docs and the studies cite exist in the repository.

A page or docstring that points a reader at ``tests/test_x.py`` or ``greybox/y.py`` is
only useful while that file exists; moving a test without its citations leaves the
reader nowhere. Files outside the repository (a design card, a paper folder beside
the checkout) are not cited at all: a fresh clone has only the repository. The
real-data folder beside the repository (``../shared/data/...``) is the one exception,
as the place the tests look for data a user puts there.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The folders and files whose text is read for citations.
CITING = ["greybox", "docs", "studies", "scripts", "benchmarks", "tests", "README.md", "pyproject.toml", ".ci"]

#: A repository path: one of the repository's top folders, then a file with a known suffix.
PATH = re.compile(r"(?<![\w./-])((?:greybox|tests|docs|studies|scripts|benchmarks|examples)/"
                  r"[\w./-]*?\w\.(?:py|md|toml|json|c))\b")

#: Citations of files outside the repository.
OUTSIDE = re.compile(r"DESIGN\.md|\.\./shared/(?!data\b)")

#: Paths a text may name without their existing: built by the docs build, or measured records (whether each
#: record a page renders exists and is current is tests/studies/test_result_pages.py's to check).
GENERATED = ("docs/_build/", "docs/api/", "docs/auto_examples/", "docs/results/")


def _texts():
    for entry in CITING:
        path = ROOT / entry
        files = [path] if path.is_file() else sorted(path.rglob("*"))
        for file in files:
            read = file.suffix in {".py", ".md", ".rst", ".toml", ".txt", ""} and file.is_file()
            if read and "_build" not in file.parts and file.resolve() != Path(__file__).resolve():
                yield file.relative_to(ROOT), file.read_text(encoding="utf-8", errors="replace")


TEXTS = list(_texts())


def test_the_citing_texts_are_found():
    names = {str(name) for name, _ in TEXTS}
    assert "README.md" in names and "greybox/metrics.py" in names and "docs/layout.md" in names


def test_every_repository_path_a_text_cites_exists():
    missing = {}
    for name, text in TEXTS:
        paths = sorted({match for match in PATH.findall(text)
                        if not match.startswith(GENERATED) and not (ROOT / match).exists()})
        if paths:
            missing[str(name)] = paths
    assert not missing, "texts cite files that do not exist: " + "; ".join(
        f"{name}: {', '.join(paths)}" for name, paths in missing.items())


def test_no_text_cites_a_file_outside_the_repository():
    outside = {str(name): sorted(set(OUTSIDE.findall(text))) for name, text in TEXTS if OUTSIDE.search(text)}
    assert not outside, "texts cite files outside the repository: " + "; ".join(
        f"{name}: {', '.join(cited)}" for name, cited in outside.items())


def test_the_path_pattern_finds_a_moved_test_and_an_outside_file():
    assert PATH.findall("see tests/test_friction_gms.py and greybox/metrics.py.") == [
        "tests/test_friction_gms.py", "greybox/metrics.py"]
    assert OUTSIDE.findall("as in DESIGN.md and ../shared/papers/README.md, data in ../shared/data/real") == [
        "DESIGN.md", "../shared/"]
