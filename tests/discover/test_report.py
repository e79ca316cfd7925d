"""The evidence figure of ``greybox discover`` (issue 31, item 8): its legends overlap no axis label or tick."""

from __future__ import annotations

import matplotlib
import pytest

matplotlib.use("Agg")

from greybox.discover.report import plot_evidence  # noqa: E402
from greybox.discover.workflow import discover  # noqa: E402
from greybox.models.friction import CoulombModel  # noqa: E402
from studies.discovery import StudyCase, case_logs  # noqa: E402

#: A discovery run takes several seconds.
pytestmark = pytest.mark.slow


def test_the_evidence_legends_cover_no_label(tmp_path, monkeypatch):
    import matplotlib.pyplot as plt

    train, test, _ = case_logs(StudyCase("position_periodic_force", 1.5, 2, "coulomb", 10.0))
    result = discover(CoulombModel(), train, test, seed=2, max_effects=1)
    original = plt.Figure.savefig
    drawn = []

    def keep(figure, *args, **kwargs):
        written = original(figure, *args, **kwargs)
        figure.canvas.draw()  # the layout as drawn, at the figure's own resolution
        renderer = figure.canvas.get_renderer()
        legends = [*figure.legends, *(ax.get_legend() for ax in figure.axes if ax.get_legend())]
        texts = [text for ax in figure.axes
                 for text in (ax.xaxis.label, ax.yaxis.label, ax.title, *ax.get_xticklabels(), *ax.get_yticklabels())
                 if text.get_text() and text.get_visible()]
        drawn.append([(legend.get_window_extent(renderer), text.get_window_extent(renderer), text.get_text())
                      for legend in legends for text in texts])
        return written

    monkeypatch.setattr(plt.Figure, "savefig", keep)
    plot_evidence(result, tmp_path / "evidence.png")
    assert drawn and drawn[0]
    overlapping = [name for legend, text, name in drawn[0] if legend.overlaps(text)]
    assert not overlapping, overlapping
