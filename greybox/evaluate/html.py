"""One self-contained HTML page bundling a report's tables and figures.

Figures are embedded as base64 ``data:`` URIs, so the page can be mailed or
moved on its own; pass ``embed=False`` to reference the PNG files by their
path relative to the page instead (a smaller page that needs its folder).
"""

from __future__ import annotations

import base64
import html
import os
from pathlib import Path
from typing import Sequence

from ..atomic import write_text_atomic
from .table import Table

__all__ = ["render_html", "write_html", "STYLE"]

#: The page's style sheet: plain, readable, printable.
STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #222;
       max-width: 1200px; margin: 2em auto; padding: 0 1em; line-height: 1.45; }
h1 { font-size: 1.6em; border-bottom: 2px solid #1f77b4; padding-bottom: .2em; }
h2 { font-size: 1.3em; margin-top: 2em; }
h3 { font-size: 1.1em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: .6em 0; font-size: .9em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; }
th { background: #eef3f8; text-align: center; }
td { text-align: right; font-variant-numeric: tabular-nums; }
td:first-child { text-align: left; white-space: nowrap; }
tr:nth-child(even) td { background: #fafafa; }
.note { color: #555; font-size: .85em; margin: .2em 0; max-width: 60em; }
.scroll { overflow-x: auto; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #444; font-size: .9em; margin-top: .3em; }
nav a { margin-right: 1em; }
"""


def _table_html(table: Table) -> str:
    head = "".join(f"<th>{html.escape(cell)}</th>" for cell in table.header)
    body = "\n".join("<tr>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>"
                     for row in table.rows)
    notes = "".join(f'<p class="note">{html.escape(note)}</p>' for note in table.notes)
    return (f"<h3>{html.escape(table.title)}</h3>\n<div class=\"scroll\"><table>\n<thead><tr>{head}</tr></thead>\n"
            f"<tbody>\n{body}\n</tbody></table></div>\n{notes}")


def _image_source(path: Path, page_dir: Path, embed: bool) -> str:
    if embed:
        return "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode("ascii")
    return html.escape(Path(os.path.relpath(path, page_dir)).as_posix(), quote=True)


def render_html(*, title: str, tables: Sequence[Table] = (), figures: Sequence[tuple[str, str | os.PathLike]] = (),
                intro: str = "", page_dir: str | os.PathLike = ".", embed: bool = True) -> str:
    """The report page as a string.

    Parameters
    ----------
    title : str
        Page heading.
    tables : sequence of Table
        Shown first, in order.
    figures : sequence of (caption, path)
        PNG files, shown after the tables.
    intro : str
        First paragraph (plain text; blank lines separate paragraphs).
    page_dir : path-like
        Directory of the page, for relative image paths when not embedding.
    embed : bool, default True
        Embed the images as base64 instead of linking them.

    Returns
    -------
    str
    """
    page_dir = Path(page_dir)
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             f"<title>{html.escape(title)}</title>", f"<style>{STYLE}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>"]
    if tables and figures:
        parts.append('<nav><a href="#tables">Tables</a><a href="#figures">Figures</a></nav>')
    for paragraph in (p.strip() for p in intro.split("\n\n")):
        if paragraph:
            parts.append(f"<p>{html.escape(paragraph)}</p>")
    if tables:
        parts.append('<h2 id="tables">Tables</h2>')
        parts += [_table_html(table) for table in tables]
    if figures:
        parts.append('<h2 id="figures">Figures</h2>')
        for caption, path in figures:
            source = _image_source(Path(path), page_dir, embed)
            parts.append(f'<figure><img src="{source}" alt="{html.escape(caption, quote=True)}">'
                         f"<figcaption>{html.escape(caption)}</figcaption></figure>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def write_html(path: str | os.PathLike, *, title: str, tables: Sequence[Table] = (),
               figures: Sequence[tuple[str, str | os.PathLike]] = (), intro: str = "", embed: bool = True) -> Path:
    """Write :func:`render_html` to ``path`` atomically and return the path.

    Parameters
    ----------
    path : path-like
        HTML file to write; its directory is the page directory for relative image paths.
    title : str
        Page heading (and window title).
    tables : sequence of Table
        Shown first, in order.
    figures : sequence of (caption, path)
        PNG files, shown after the tables.
    intro : str
        First paragraph (plain text; blank lines separate paragraphs).
    embed : bool, default True
        Embed the images as base64 instead of linking them relative to the page.
    """
    path = Path(path)
    text = render_html(title=title, tables=tables, figures=figures, intro=intro, page_dir=path.parent, embed=embed)
    return write_text_atomic(path, text)
