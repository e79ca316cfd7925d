"""The plant dashboard: one static HTML page of the axes, most severe first.

The page (``index.html``, readable in a browser without a server: figures embedded, plotly.js inline) has a
table of the axes sorted by severity, a table of the alarms, and per axis a figure of every feature over the days:
the daily value with its bootstrap interval, the baseline band (mean +- 2 standard deviations) over the
baseline days, and the start and detection day of each alarm; and the friction-along-travel map: per day
and position bin the friction's departure from its mean over the baseline days. After them the same
features per axis as interactive plotly charts (zoom, hover), with plotly.js included once in the page.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np

from ..atomic import write_text_atomic
from ..evaluate.html import render_html
from ..evaluate.plots import import_pyplot, save_figure
from ..evaluate.table import Table
from .detect import ChangeDetector
from .fingerprint import FEATURE_UNITS

__all__ = ["axis_figure", "baseline_note", "interactive_axis_html", "interactive_travel_html", "travel_map_figure",
           "write_report"]


def axis_figure(trend, detector: ChangeDetector, path) -> Path | None:
    """Write the figure of one axis' features over the days as a PNG.

    Parameters
    ----------
    trend : AxisTrend
        The axis (:attr:`ChangeDetector.trends_`).
    detector : ChangeDetector
        The fitted detector (its baseline length).
    path : path-like
        PNG file to write.

    Returns
    -------
    Path or None
        ``path``, or None when no feature of the axis is watched yet (fewer than two baseline days).
    """
    features = list(trend.baseline)
    if not features:
        return None
    plt = import_pyplot(path)
    figure, axes = plt.subplots(len(features), 1, figsize=(9, 1.7 * len(features) + 0.6), sharex=True,
                                squeeze=False)
    dates = np.array(trend.dates, dtype="datetime64[D]")
    n_base = min(detector.baseline_days, len(dates))
    alarms = {}
    for alarm in trend.alarms:
        alarms.setdefault(alarm.feature, []).append(alarm)
    for ax, feature in zip(axes[:, 0], features):
        mean, sd = trend.baseline[feature]
        ax.fill_between(dates, trend.lower[feature], trend.upper[feature], color="#1f77b4", alpha=0.2, lw=0,
                        label="95 % interval")
        ax.plot(dates, trend.values[feature], ".-", color="#1f77b4", lw=1, label="daily value")
        ax.axhspan(mean - 2 * sd, mean + 2 * sd, color="#2ca02c", alpha=0.15, lw=0, label="baseline +- 2 sd")
        ax.axvspan(dates[0], dates[n_base - 1], color="#999999", alpha=0.08, lw=0)
        for alarm in alarms.get(feature, []):
            ax.axvline(np.datetime64(alarm.start, "D"), color="#ff7f0e", ls="--", lw=1, label="change start")
            ax.axvline(np.datetime64(alarm.detected, "D"), color="#d62728", lw=1.5, label="alarm")
        ax.set_ylabel(f"{feature}\n[{FEATURE_UNITS[feature]}]", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].legend(fontsize=7, ncol=5, loc="lower left", bbox_to_anchor=(0.0, 1.02))
    height = figure.get_figheight()
    figure.suptitle(f"{trend.machine} / {trend.axis}: friction fingerprint per day (grey: baseline days)",
                    fontsize=9, y=1.0 - 0.12 / height)
    figure.autofmt_xdate()
    figure.subplots_adjust(left=0.11, right=0.98, bottom=0.08, top=1.0 - 0.75 / height, hspace=0.12)
    saved = save_figure(figure, path, dpi=90)
    plt.close(figure)
    return saved


def _travel_departure(trend, detector: ChangeDetector) -> tuple[np.ndarray, np.ndarray, int] | None:
    """Bin centres [mm], the daily map's departure [A] (days x bins) from its mean over the baseline days, and
    the number of baseline days; None without a map."""
    centres, daily = trend.travel_map
    if len(centres) == 0 or not np.any(np.isfinite(daily)):
        return None
    n_base = min(detector.baseline_days, len(trend.dates))
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        departure = daily - np.nanmean(daily[:n_base], axis=0)
    return np.asarray(centres), departure, n_base


def travel_map_figure(trend, detector: ChangeDetector, path) -> Path | None:
    """Write the friction-along-travel map of one axis: the departure from the baseline per day and position.

    Parameters
    ----------
    trend : AxisTrend
        The axis (:attr:`ChangeDetector.trends_`), with its daily map.
    detector : ChangeDetector
        The fitted detector (its baseline length).
    path : path-like
        PNG file to write.

    Returns
    -------
    Path or None
        ``path``, or None when the axis has no map.
    """
    found = _travel_departure(trend, detector)
    if found is None:
        return None
    centres, departure, n_base = found
    plt = import_pyplot(path)
    figure, ax = plt.subplots(figsize=(9, 2.8))
    limit = float(np.nanmax(np.abs(departure))) or 1e-3
    dates = np.array(trend.dates, dtype="datetime64[D]")
    step = np.median(np.diff(centres)) if len(centres) > 1 else 1.0
    image = ax.pcolormesh(np.append(dates, dates[-1] + np.timedelta64(1, "D")),
                          np.append(centres - step / 2, centres[-1] + step / 2), np.ma.masked_invalid(departure.T),
                          cmap="RdBu_r", vmin=-limit, vmax=limit, shading="flat")
    figure.colorbar(image, ax=ax, label="friction vs baseline [A]")
    for alarm in trend.alarms:
        if np.isfinite(alarm.position_mm):
            ax.plot(np.datetime64(alarm.detected, "D"), alarm.position_mm, "k*", ms=9)
    ax.set_ylabel("position [mm]", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.set_title(f"{trend.machine} / {trend.axis}: friction along the travel, departure from the first {n_base} days "
                 "(star: where an alarm found the largest departure)", fontsize=8)
    figure.autofmt_xdate()
    figure.tight_layout()
    saved = save_figure(figure, path, dpi=90)
    plt.close(figure)
    return saved


def interactive_axis_html(trend, detector: ChangeDetector, div_id: str) -> str:
    """The features of one axis over the days as an interactive plotly chart (an HTML ``div``, no script).

    The same content as :func:`axis_figure`: daily values with their intervals, the baseline band and the
    alarms' start and detection, one row per feature sharing the day axis, zoomable in the browser.

    Parameters
    ----------
    trend : AxisTrend
        The axis (:attr:`ChangeDetector.trends_`).
    detector : ChangeDetector
        The fitted detector (its baseline length).
    div_id : str
        HTML id of the chart's ``div``.

    Returns
    -------
    str or None
        The ``div`` and its inline call of plotly (plotly.js itself is included once per page), or None when
        no feature of the axis is watched yet (fewer than two baseline days).
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    features = list(trend.baseline)
    if not features:
        return None
    dates = [d.isoformat() for d in trend.dates]
    figure = make_subplots(rows=len(features), cols=1, shared_xaxes=True, vertical_spacing=0.012,
                           subplot_titles=[f"{f} [{FEATURE_UNITS[f]}]" for f in features])
    n_base = min(detector.baseline_days, len(dates))
    for row, feature in enumerate(features, start=1):
        mean, sd = trend.baseline[feature]
        lower, upper = trend.lower[feature].tolist(), trend.upper[feature].tolist()
        figure.add_trace(go.Scatter(x=dates + dates[::-1], y=upper + lower[::-1], fill="toself", line={"width": 0},
                                    fillcolor="rgba(31,119,180,0.2)", hoverinfo="skip", showlegend=False),
                         row=row, col=1)
        figure.add_trace(go.Scatter(x=dates, y=trend.values[feature].tolist(), mode="lines+markers",
                                    line={"color": "#1f77b4", "width": 1}, marker={"size": 4}, name=feature,
                                    showlegend=False), row=row, col=1)
        figure.add_hrect(y0=mean - 2 * sd, y1=mean + 2 * sd, fillcolor="rgba(44,160,44,0.15)", line_width=0,
                         row=row, col=1)
        figure.add_vrect(x0=dates[0], x1=dates[n_base - 1], fillcolor="rgba(150,150,150,0.1)", line_width=0,
                         row=row, col=1)
        for alarm in trend.alarms:
            if alarm.feature == feature:
                figure.add_vline(x=alarm.start.isoformat(), line={"color": "#ff7f0e", "dash": "dash", "width": 1},
                                 row=row, col=1)
                figure.add_vline(x=alarm.detected.isoformat(), line={"color": "#d62728", "width": 1.5},
                                 row=row, col=1)
    figure.update_layout(height=170 * len(features) + 80, margin={"l": 60, "r": 20, "t": 40, "b": 40},
                         title={"text": f"{trend.machine} / {trend.axis}: drag to zoom, double-click to reset",
                                "font": {"size": 13}}, template="simple_white")
    figure.update_annotations(font_size=10)
    return figure.to_html(full_html=False, include_plotlyjs=False, div_id=div_id)


def interactive_travel_html(trend, detector: ChangeDetector, div_id: str) -> str | None:
    """The friction-along-travel map of one axis as an interactive plotly heat map (an HTML ``div``, no script).

    The same content as :func:`travel_map_figure`: per day and position bin the friction's departure from
    its mean over the baseline days, a star where an alarm found the largest departure; zoomable, the
    departure of a cell shown on hover.

    Parameters
    ----------
    trend : AxisTrend
        The axis (:attr:`ChangeDetector.trends_`), with its daily map.
    detector : ChangeDetector
        The fitted detector (its baseline length).
    div_id : str
        HTML id of the chart's ``div``.

    Returns
    -------
    str or None
        The ``div`` and its inline call of plotly (plotly.js itself is included once per page), or None when
        the axis has no map.
    """
    import plotly.graph_objects as go

    found = _travel_departure(trend, detector)
    if found is None:
        return None
    centres, departure, n_base = found
    limit = float(np.nanmax(np.abs(departure))) or 1e-3
    dates = [d.isoformat() for d in trend.dates]
    cells = np.where(np.isfinite(departure.T), departure.T, None).tolist()  # JSON null: an empty cell
    figure = go.Figure(go.Heatmap(x=dates, y=centres.tolist(), z=cells, colorscale="RdBu", reversescale=True,
                                  zmin=-limit, zmax=limit, colorbar={"title": {"text": "vs baseline [A]"}},
                                  hovertemplate="%{x}<br>%{y:.1f} mm<br>%{z:+.4f} A<extra></extra>"))
    stars = [alarm for alarm in trend.alarms if np.isfinite(alarm.position_mm)]
    if stars:
        figure.add_trace(go.Scatter(x=[a.detected.isoformat() for a in stars], y=[a.position_mm for a in stars],
                                    mode="markers", marker={"symbol": "star", "size": 12, "color": "black"},
                                    text=[a.feature for a in stars], name="alarm", showlegend=False,
                                    hovertemplate="alarm: %{text}<br>%{x}<br>%{y:.1f} mm<extra></extra>"))
    figure.update_layout(height=360, margin={"l": 60, "r": 20, "t": 40, "b": 40}, template="simple_white",
                         yaxis_title="position [mm]",
                         title={"text": f"{trend.machine} / {trend.axis}: friction along the travel, departure from "
                                        f"the first {n_base} days (drag to zoom)", "font": {"size": 13}})
    return figure.to_html(full_html=False, include_plotlyjs=False, div_id=div_id)


def baseline_note(trend, detector: ChangeDetector) -> str:
    """One line on an axis whose baseline is not complete yet: nothing can be detected on it so far.

    Parameters
    ----------
    trend : AxisTrend
        The axis.
    detector : ChangeDetector
        The fitted detector (its baseline length).

    Returns
    -------
    str
        The line; empty when the axis has more days than the baseline.
    """
    days, needed = len(trend.dates), detector.baseline_days
    if days > needed:
        return ""
    return (f"baseline not yet complete: {days} of {needed} days with a fingerprint; too few days to detect "
            f"anything, changes are watched from day {needed + 1} on ({needed + 1 - days} more days)")


def write_report(detector: ChangeDetector, out_dir) -> Path:
    """Write the dashboard ``out_dir/index.html`` of a fitted detector.

    Parameters
    ----------
    detector : ChangeDetector
        Fitted on the history.
    out_dir : path-like
        Directory of the page (created if missing); ``index.html`` in it is replaced.

    Returns
    -------
    Path
        The page written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for trend in detector.trends_:
        first = trend.alarms[0] if trend.alarms else None
        rows.append([trend.machine, trend.axis, str(len(trend.dates)),
                     f"{trend.dates[0].isoformat()} to {trend.dates[-1].isoformat()}", f"{trend.severity:.2f}",
                     first.describe().split(": ", 1)[1] if first else baseline_note(trend, detector) or "none",
                     "stale: retrain (greybox train) on recent air moves" if first else "current"])
    axes_table = Table("Axes, most severe first", ["machine", "axis", "days", "period", "severity", "first alarm",
                                                    "model"], rows,
                       [f"Severity: largest CUSUM sum over its feature's calibrated threshold (h = "
                        f"{min(detector.thresholds_.values()):.2f} to {detector.threshold_:.2f}; 1 or more: an alarm). "
                        f"Baseline: the first {detector.baseline_days} days of each axis."])
    alarm_rows = [[a.machine, a.axis, a.feature, a.direction, a.start.isoformat(), a.detected.isoformat(),
                   f"{a.shift:+.1f}", "" if not np.isfinite(a.p_value) else f"{a.p_value:.2g}"]
                  for a in detector.alarms_]
    alarm_table = Table("Alarms", ["machine", "axis", "feature", "direction", "start", "detected",
                                   "shift [sd]", "p"], alarm_rows or [["none", "", "", "", "", "", "", ""]],
                        ["shift: mean change since the start in baseline standard deviations; p: one-sided Welch "
                         "t-test of the days since the start against the baseline days."])
    with tempfile.TemporaryDirectory() as scratch:
        figures = []
        for i, trend in enumerate(detector.trends_):
            png = axis_figure(trend, detector, Path(scratch) / f"axis_{i}.png")
            if png is not None:
                figures.append((f"{trend.machine} / {trend.axis} (severity {trend.severity:.2f})", png))
            travel = travel_map_figure(trend, detector, Path(scratch) / f"travel_{i}.png")
            if travel is not None:
                figures.append((f"{trend.machine} / {trend.axis}: friction along the travel", travel))
        page = render_html(title="Friction fingerprints", tables=[axes_table, alarm_table],
                           figures=figures, embed=True, page_dir=out,
                          intro="Per axis and day: sliding and break-away friction levels per direction, viscous "
                                "coefficients, residual noise, backlash width, amplitude of the lead-periodic "
                                "friction and the largest local friction excess along the travel, fitted on the "
                                "logs' stretches without process load, with 95 % bootstrap intervals; and the "
                                "friction along the travel against its baseline.")
    from plotly.offline import get_plotlyjs

    charts = []
    for i, trend in enumerate(detector.trends_):
        chart = interactive_axis_html(trend, detector, f"axis-{i}")
        if chart is not None:
            charts.append(chart)
        travel = interactive_travel_html(trend, detector, f"travel-{i}")
        if travel is not None:
            charts.append(travel)
    interactive = ('<h2 id="interactive">Interactive charts</h2>\n<script type="text/javascript">'
                   + get_plotlyjs() + "</script>\n" + "\n".join(charts) + "\n")
    page = page.replace("</body></html>", interactive + "</body></html>")
    return write_text_atomic(out / "index.html", page)
