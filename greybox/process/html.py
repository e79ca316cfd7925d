"""The check's report as one HTML page: the parts and stretches, and the figured parts over their envelope.

``report.html`` (readable in a browser without a server, plotly.js inline once) has the table of the parts
(flagged first), the table of the stretches, and per figured part (the same parts as the PNG figures) an
interactive chart: the band, the taught centre, the part's smoothed signal along the reference part, and the
stretches outside shaded, with their kind on hover. The signal is drawn at every ``DRAW_STEP``-th position of the
reference grid (the smoothing window holds ten of them).
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import Sequence

import numpy as np

from ..atomic import write_text_atomic
from ..evaluate.html import render_html
from ..evaluate.table import Table

__all__ = ["part_chart_html", "write_html_report"]

#: Seconds after a labelled stretch within which the next one is shaded without a label of its own.
LABEL_GAP_S = 2.0


def _step(envelope) -> int:
    """Positions per point drawn: a tenth of the smoothing window (at least 1)."""
    return max(1, envelope.width_ // 10)


def part_chart_html(envelope, check, div_id: str) -> str:
    """A part's signal over its envelope as an interactive plotly chart (an HTML ``div``, no plotly.js).

    Parameters
    ----------
    envelope : Envelope
        The envelope.
    check : PartCheck
        The part's check (its ``signal`` on the reference grid).
    div_id : str
        HTML id of the chart's ``div``.
    """
    import plotly.graph_objects as go

    step = _step(envelope)
    time = (np.arange(envelope.centre_.size) * envelope.sample_time_)[::step]
    centre, band = envelope.centre_[::step], envelope.band_[::step]
    signal = np.asarray(check.signal, dtype=float)[::step]
    unit = f" [{envelope.unit_}]" if envelope.unit_ else ""
    figure = go.Figure()
    figure.add_trace(go.Scatter(x=np.concatenate([time, time[::-1]]).tolist(),
                                y=np.concatenate([centre + band, (centre - band)[::-1]]).tolist(), fill="toself",
                                fillcolor="rgba(150,150,150,0.35)", line={"width": 0}, hoverinfo="skip",
                                name="envelope"))
    figure.add_trace(go.Scatter(x=time.tolist(), y=centre.tolist(), line={"color": "#666666", "width": 1},
                                name="taught centre"))
    figure.add_trace(go.Scatter(x=time.tolist(), y=[None if not np.isfinite(v) else float(v) for v in signal],
                                line={"color": "#1f77b4", "width": 1}, name=f"part {check.number}"))
    labelled = -np.inf  # a stretch within LABEL_GAP_S of the last one labelled goes without its own label
    for stretch in check.stretches:
        label = stretch.start_s - labelled > LABEL_GAP_S
        labelled = stretch.start_s if label else labelled
        figure.add_vrect(x0=stretch.start_s - check.shift_s, x1=stretch.end_s - check.shift_s,
                         fillcolor="rgba(214,39,40,0.3)", line_width=0,
                         **({"annotation_text": stretch.kind, "annotation_position": "top left",
                             "annotation_font_size": 9} if label else {}))
    verdict = ", ".join(check.kinds) if check.flagged else "inside"
    figure.update_layout(height=380, margin={"l": 60, "r": 20, "t": 40, "b": 40}, template="simple_white",
                         title={"text": f"{Path(check.source).name}, part {check.number}: {verdict}",
                                "font": {"size": 13}},
                         xaxis_title="time along the reference part [s]",
                         yaxis_title=f"{envelope.signal_.get('kind', 'signal')}{unit}")
    return figure.to_html(full_html=False, include_plotlyjs=False, div_id=div_id)


def write_html_report(envelope, checks: Sequence, figured: Sequence, path: str | PathLike) -> Path:
    """Write ``report.html``: the tables of the parts and the stretches, a chart per figured part.

    Parameters
    ----------
    envelope : Envelope
        The envelope the parts were checked against.
    checks : sequence of PartCheck
        The checks, in order.
    figured : sequence of PartCheck
        The parts drawn, in order.
    path : str or path-like
        The page to write.
    """
    from plotly.offline import get_plotlyjs

    unit = envelope.unit_
    ordered = sorted(checks, key=lambda c: not c.flagged)
    parts = Table("Parts, flagged first", ["file", "part", "flagged", "kinds", f"D [{unit}]", f"limit [{unit}]",
                                           f"mean cut load [{unit}]", "stretches"],
                  [[Path(c.source).name, str(c.number), "yes" if c.flagged else "no", ", ".join(c.kinds),
                    f"{c.deviation:+.4g}", f"{c.deviation_limit:.4g}", f"{c.cut_load:.4g}", str(len(c.stretches))]
                   for c in ordered],
                  ["D: the part's mean load deviation over the taught cut samples; flagged when |D| exceeds its "
                   "limit or a stretch leaves the band."])
    stretch_rows = [[Path(c.source).name, str(c.number), s.kind, f"{s.start_s:.3f}", f"{s.end_s:.3f}",
                     f"{s.peak:.2f}", f"{s.deviation:+.4g}"] for c in checks for s in c.stretches]
    stretches = Table("Stretches outside the band", ["file", "part", "kind", "start [s]", "end [s]",
                                                     "peak [band half-widths]", f"mean deviation [{unit}]"],
                      stretch_rows or [["none", "", "", "", "", "", ""]],
                      ["Times since the part's first sample."])
    flagged = sum(c.flagged for c in checks)
    page = render_html(title="Parts against their envelope", tables=[parts, stretches], page_dir=Path(path).parent,
                       intro=f"{len(checks)} parts checked against an envelope of the {envelope.signal_.get('kind')} "
                             f"signal taught on {envelope.n_parts_} parts (band +-{envelope.band_factor_:.2f} "
                             f"spreads, false-alarm rate {envelope.false_alarm_rate:g} per part): {flagged} flagged.")
    charts = [part_chart_html(envelope, check, f"part-{index}") for index, check in enumerate(figured)]
    interactive = ('<h2 id="charts">Parts over the envelope</h2>\n<script type="text/javascript">'
                   + get_plotlyjs() + "</script>\n" + "\n".join(charts) + "\n")
    return write_text_atomic(path, page.replace("</body></html>", interactive + "</body></html>"))
