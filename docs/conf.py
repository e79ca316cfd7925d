"""Sphinx configuration of the greybox documentation site.

Build it from the repository folder (``pip install -e ".[docs]"`` first)::

    sphinx-build -W --keep-going -b html docs docs/_build/html

The pages are the Markdown files of ``docs/`` (MyST), the API reference is generated from the
docstrings (numpydoc, autosummary over the whole ``greybox`` package, so a module added or moved is
picked up without editing a page), and the gallery runs the scripts of ``docs/examples/`` on the
data shipped in ``data/``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))  # document the sources beside this folder, not another installed copy
os.environ.setdefault("MPLBACKEND", "Agg")

import greybox  # noqa: E402

project = "greybox"
author = "the greybox authors"
copyright = "greybox authors"  # noqa: A001  (Sphinx's name)
version = release = greybox.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "examples/README.rst", "examples/*.py",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.md5", "auto_examples/*.json"]
templates_path = ["_templates"]

# --- MyST: the Markdown pages -------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3  # '[...](page.md#a-section)' links resolve
# Links from a page to repository files outside docs/ (examples/axis_x.toml, scripts/...) are plain
# links on GitHub; the site has no page for them.
suppress_warnings = ["myst.xref_missing",
                     # JSON examples with '...' in them: shown as text, unhighlighted
                     "misc.highlighting_failure"]

# --- API reference ---------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": False}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types and units
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- gallery -------------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": ["examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "run_stale_examples": False,
    "matplotlib_animations": False,
    "reset_modules_order": "both",
}

# --- HTML ----------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = "greybox"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path: list[str] = []


# --- pages added later ------------------------------------------------------------------------
# A Markdown page added to docs/ without editing index.md still gets into the navigation: the
# '{other-pages}' line of index.md's Guides list becomes the pages that no list of index.md names.
def _other_pages(app, docname: str, source: list[str]) -> None:
    if docname != root_doc:
        return
    text = source[0]
    named = {line.strip() for line in text.splitlines()}
    others = sorted(path.stem for path in DOCS.glob("*.md") if path.stem != root_doc and path.stem not in named)
    source[0] = text.replace("{other-pages}", "\n".join(others))


def _skip_member(app, what: str, name: str, obj, skip: bool, options) -> bool | None:
    """Leave out the ``set_*_request`` methods scikit-learn adds to every estimator class."""
    if name.startswith("set_") and name.endswith("_request"):
        return True
    return None


def setup(app) -> None:
    app.connect("source-read", _other_pages)
    app.connect("autodoc-skip-member", _skip_member)
