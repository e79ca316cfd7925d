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

#: A repository path: one of the repository's top folders, then a file with a known suffix (code, pages, the
#: shipped logs and configuration).
PATH = re.compile(r"(?<![\w./-])((?:greybox|tests|docs|studies|scripts|benchmarks|examples|\.ci)/"
                  r"[\w./-]*?\w\.(?:py|md|toml|json|c|mcap|csv|parquet|yml|yaml|sh))\b"
                  r"|(?<![\w./-])(data/[\w.-]+\.(?:mcap|csv|parquet))\b")

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
        cited = {path for match in PATH.findall(text) for path in match if path}
        if name.parts[0] == "tests":  # the tests make up logs under a temporary data/ folder
            cited = {path for path in cited if not path.startswith("data/")}
        paths = sorted(path for path in cited if not path.startswith(GENERATED) and not (ROOT / path).exists())
        if paths:
            missing[str(name)] = paths
    assert not missing, "texts cite files that do not exist: " + "; ".join(
        f"{name}: {', '.join(paths)}" for name, paths in missing.items())


#: A Markdown link: its target (a file relative to the page, an anchor, or both).
LINK = re.compile(r"\]\(([^)\s]+)\)")
#: The pages whose links are read: the README and the documentation's Markdown.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _anchor(heading: str) -> str:
    """The anchor of a Markdown heading, as GitHub and MyST's heading anchors make it."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    return {_anchor(heading) for heading in re.findall(r"^#+\s+(.*)$", page.read_text(encoding="utf-8"), re.M)}


def _broken_links(page: Path) -> list[str]:
    broken = []
    for target in LINK.findall(page.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):
            continue  # a web address
        file, _, anchor = target.partition("#")
        dest = (page.parent / file) if file else page
        if file.startswith(("auto_examples/", "api/")):
            continue  # built by the docs build
        if not dest.exists():
            broken.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
            broken.append(target)
    return broken


def test_every_link_of_a_page_reaches_a_file_and_heading_that_exist():
    broken = {str(page.relative_to(ROOT)): links for page in PAGES if (links := _broken_links(page))}
    assert not broken, "pages link to files or headings that do not exist: " + "; ".join(
        f"{name}: {', '.join(links)}" for name, links in broken.items())


def test_the_link_check_finds_a_moved_page_and_a_renamed_heading(tmp_path):
    (tmp_path / "b.md").write_text("# The choice against `coulomb:offset`\n", encoding="utf-8")
    page = tmp_path / "a.md"
    page.write_text("[ok](b.md#the-choice-against-coulomboffset) [gone](c.md) [renamed](b.md#the-choice) "
                    "[web](https://example.org/x.md)\n", encoding="utf-8")
    assert _broken_links(page) == ["c.md", "b.md#the-choice"]


def test_no_text_cites_a_file_outside_the_repository():
    outside = {str(name): sorted(set(OUTSIDE.findall(text))) for name, text in TEXTS if OUTSIDE.search(text)}
    assert not outside, "texts cite files outside the repository: " + "; ".join(
        f"{name}: {', '.join(cited)}" for name, cited in outside.items())


def test_the_path_pattern_finds_a_moved_test_and_an_outside_file():
    found = PATH.findall("see tests/test_friction_gms.py and greybox/metrics.py, on data/X_A.mcap.")
    assert [path for match in found for path in match if path] == [
        "tests/test_friction_gms.py", "greybox/metrics.py", "data/X_A.mcap"]
    assert OUTSIDE.findall("as in DESIGN.md and ../shared/papers/README.md, data in ../shared/data/real") == [
        "DESIGN.md", "../shared/"]
