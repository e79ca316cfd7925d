"""A titled table of text cells, the unit of every report: Markdown here, HTML in :mod:`greybox.evaluate.html`.

It sits below both :mod:`greybox.evaluate.report` (which builds tables and
writes the report files) and :mod:`greybox.evaluate.html` (which renders
them), so that neither imports the other in both directions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Table"]


@dataclass
class Table:
    """A titled table of text cells, rendered to Markdown here and to HTML in :mod:`greybox.evaluate.html`.

    Attributes
    ----------
    title : str
    header : list of str
    rows : list of list of str
    notes : list of str
        Sentences printed under the table.
    """

    title: str
    header: list[str]
    rows: list[list[str]]
    notes: list[str] = field(default_factory=list)

    def pipe_lines(self) -> list[str]:
        """The header and the rows as the lines of a Markdown pipe table, without title or notes."""
        return ["| " + " | ".join(self.header) + " |", "|" + "|".join("---" for _ in self.header) + "|",
                *("| " + " | ".join(row) + " |" for row in self.rows)]

    def to_markdown(self) -> str:
        """The table as a Markdown section (``###`` title, pipe table, notes)."""
        lines = [f"### {self.title}", "", *self.pipe_lines()]
        if self.notes:
            lines.append("")
            lines += [f"{note}  " if i < len(self.notes) - 1 else note for i, note in enumerate(self.notes)]
        return "\n".join(lines) + "\n"

    def to_text(self) -> list[str]:
        """The table as plain text lines, for a page without Markdown: the title, the header and rows in
        columns padded to their widest cell (numbers right-aligned), a rule under the header, then the notes."""
        widths = [max([len(name), *(len(row[k]) for row in self.rows)]) for k, name in enumerate(self.header)]

        def numeric(cell: str) -> bool:
            return cell.replace(".", "", 1).replace("-", "", 1).replace("e", "", 1).replace("+", "").isdigit()

        def line(cells) -> str:
            return "  ".join(cell.rjust(width) if numeric(cell) else cell.ljust(width)
                             for cell, width in zip(cells, widths)).rstrip()

        return [self.title, line(self.header), "  ".join("-" * width for width in widths),
                *(line(row) for row in self.rows), *self.notes]

