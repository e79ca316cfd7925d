"""Head to head: teach-in envelopes of the raw current (the field's way) and of the model's process force.

Protocol, per seed of the twin (:mod:`greybox.twin.part_series`): one series of :data:`PARTS` one-minute parts
of the default part program through a warm-up in which the friction falls by 25 % (time constant
:data:`WARMUP_S`), with events: a missing blank in part :data:`MISSING`, an oversized blank (load x 1.3) in part
:data:`OVERSIZED`, tool wear of 1 % per part after part :data:`WEAR_START` (+15 % at part ``WEAR_START + 15``),
a breakage in part :data:`BREAKAGE` in the middle of its fourth cut. The envelope is taught on the first
:data:`TEACH` parts (a cold machine, as a teach-in at the start of a shift) with the false-alarm rate
:data:`RATE` per part for every variant, then every later part is checked:

- ``raw``: the measured current, no model (the field's process monitors);
- ``raw, re-levelled``: the same, each part shifted per direction to its air moves;
- ``force``: the process force of a GMS model trained once on the cold machine's air cuts;
- ``force, re-levelled``: the same, the model's current scaled per direction to each part's air moves.

Figures per variant: false alarms among the good parts (:data:`TEACH` + 1 ... :data:`WEAR_START` without the
two blank events); whether the missing and the oversized blank are flagged with the right kind; the first part
flagged after the wear starts, against the part that crosses +15 %; whether the breakage part is flagged and
how far the first missing-cut (or drop) stretch starts from the breakage; for the force, the error of each good
part's mean cut force against the truth over the same samples.

**The false-alarm rate** (:func:`false_alarm_series`, :func:`false_alarm_summary`): 38 good parts per seed cannot
show one false alarm in 1000, so further series of :data:`GOOD_PARTS` good parts (no tool event, the same
warm-up) are checked against envelopes taught on their first :data:`TEACH` parts. Per good part the study keeps
its largest standardised band deviation ``u = max |y - c| / s`` (while the reference moves) and ``|D|`` over its
limit. Counted: the parts flagged, with the Clopper-Pearson 95 % interval of the rate. Extrapolated: the band's
rate from the effective count ``M`` fitted to the checked parts' ``u`` (:func:`~greybox.process.envelope.band_count`,
with its two-sided 95 % interval) at each envelope's ``k_b``, plus the mean check's from a normal fitted to
``D / limit`` (its standard deviation's 95 % upper bound gives the upper end).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
from scipy.stats import beta, chi2, norm
from scipy.stats import t as student

from greybox.process.alignment import shifted
from greybox.process.check import check_part
from greybox.process.envelope import SPREAD_POOL, Envelope, band_count
from greybox.process.parts import PartSignal
from greybox.twin.cutting import cut_segments
from greybox.twin.datasets import ESSENTIAL_TRUTH_CHANNELS
from greybox.twin.part_series import PartSeriesSpec, ToolEvents, WarmUp, make_part_series, synthesize_part_series
from greybox.windows import centred_nanmean

__all__ = ["PARTS", "TEACH", "RATE", "VARIANTS", "GOOD_PARTS", "breakage_time", "false_alarm_series",
           "false_alarm_summary", "false_alarm_table", "head_to_head", "head_to_head_table", "seed_series", "targets",
           "truth_cut_force"]

PARTS, TEACH, WEAR_START, MISSING, OVERSIZED, BREAKAGE = 80, 10, 50, 30, 40, 75
#: Warm-up time constant [s] and drop.
WARMUP_S, DROP = 1200.0, 0.25
#: False alarms per good part the limits of every variant are set for.
RATE = 1e-3
#: Parts of a series of good parts (the first :data:`TEACH` taught, the others checked).
GOOD_PARTS = 130
#: The variants: name -> (signal kind, re-levelled).
VARIANTS = {"raw": ("raw", False), "raw, re-levelled": ("raw", True), "force": ("force", False),
            "force, re-levelled": ("force", True)}


def breakage_time() -> float:
    """Time [s] since a part's log start of the middle of the part's fourth cut.

    Taken from a part without random wait; a part's random wait (at most 0.2 s) moves it inside a cut of
    several seconds.
    """
    logs, _ = make_part_series(PartSeriesSpec(parts=1, jitter_s=0.0), 0)
    a, b = cut_segments(logs[0].extras["truth_process_A"])[3]
    return round(float(0.5 * (logs[0].time[a] + logs[0].time[b - 1])), 3)


def seed_series(seed: int, out_dir: Path, *, good_only: bool = False) -> tuple[Path, dict]:
    """Write the seed's series (one long Parquet log) and return it with its truth.

    Parameters
    ----------
    seed : int
        Seed of the series.
    out_dir : pathlib.Path
        Where to write it.
    good_only : bool, default False
        A series of :data:`GOOD_PARTS` good parts (no tool event) instead of the protocol's :data:`PARTS`.
    """
    import json

    if good_only:
        spec = PartSeriesSpec(parts=GOOD_PARTS, warm_up=WarmUp(DROP, WARMUP_S, WARMUP_S))
    else:
        events = ToolEvents(wear_pct_per_part=1.0, wear_start_part=WEAR_START, breakage_part=BREAKAGE,
                            breakage_time_s=breakage_time(), missing_blank=(MISSING,), oversized_blank=(OVERSIZED,))
        spec = PartSeriesSpec(parts=PARTS, warm_up=WarmUp(DROP, WARMUP_S, WARMUP_S), events=events)
    synthesize_part_series(spec, seed, out_dir, layout="series", truth_channels=ESSENTIAL_TRUTH_CHANNELS,
                           force=True, suffix="parquet")
    return out_dir / "X_series.parquet", json.loads((out_dir / "X_parts.json").read_text())


def _good_figures(envelope, done) -> tuple[float, float]:
    """A checked part's largest standardised band deviation ``u`` and ``|D|`` over its limit."""
    moving = envelope.direction_ != 0
    standardised = np.abs(done.signal - envelope.centre_)[moving] / envelope.spread_[moving]
    return float(np.nanmax(standardised)), abs(done.deviation) / done.deviation_limit


def false_alarm_series(seed: int, model: str, axis_config: str, out_dir: Path) -> dict:
    """Check a series of good parts against envelopes taught on its first parts, per variant.

    Parameters
    ----------
    seed : int
        Seed of the series.
    model : str
        Model file (:func:`head_to_head`).
    axis_config : str
        Axis file.
    out_dir : pathlib.Path
        Where the series is written.

    Returns
    -------
    dict
        Per variant: ``false_alarms``, ``good_parts``, ``band_factor``, ``maxima`` (``u`` per part) and
        ``mean_ratios`` (``|D|`` over its limit per part).
    """
    path, _ = seed_series(int(seed), out_dir, good_only=True)
    signals = {"raw": PartSignal(), "force": PartSignal(model=model, axis_config=axis_config)}
    read = {kind: source.parts(str(path)) for kind, source in signals.items()}
    results = {}
    for name, (kind, relevel) in VARIANTS.items():
        parts, unit = read[kind]
        envelope = Envelope(false_alarm_rate=RATE, relevel=relevel).fit(parts[:TEACH], unit=unit)
        checks = [check_part(envelope, part) for part in parts[TEACH:]]
        figures = [_good_figures(envelope, done) for done in checks]
        results[name] = {"false_alarms": sum(done.flagged for done in checks), "good_parts": len(checks),
                         "band_factor": envelope.band_factor_, "band_count": envelope.band_count_,
                         "maxima": [round(u, 4) for u, _ in figures],
                         "mean_ratios": [round(r, 4) for _, r in figures]}
    return results


def _band_rate(maxima, factors, count: float) -> float:
    scale = math.sqrt(1.0 + 1.0 / TEACH)
    dof = SPREAD_POOL * (TEACH - 1)
    inside = [1.0 - 2.0 * student.sf(k / scale, dof) for k in factors]
    return float(np.mean([1.0 - g ** count for g in inside]))


def false_alarm_summary(rows) -> dict:
    """Pooled false-alarm figures of good parts (module docstring).

    Parameters
    ----------
    rows : sequence of dict
        Per series, one variant's figures: ``false_alarms``, ``good_parts``, ``band_factor``, ``maxima``,
        ``mean_ratios``.

    Returns
    -------
    dict
        ``false_alarms``, ``good_parts``, ``counted_ci`` (Clopper-Pearson 95 %), ``band_count`` (``M`` fitted
        to the parts' ``u``, with ``band_count_ci``), ``band_rate`` and ``mean_rate`` (extrapolated, each with
        a 95 % interval), ``rate`` and ``rate_ci`` (their sum).
    """
    alarms = sum(row["false_alarms"] for row in rows)
    parts = sum(row["good_parts"] for row in rows)
    low = 0.0 if alarms == 0 else float(beta.ppf(0.025, alarms, parts - alarms + 1))
    high = 1.0 if alarms == parts else float(beta.ppf(0.975, alarms + 1, parts - alarms))
    maxima = np.concatenate([row["maxima"] for row in rows])
    factors = np.concatenate([[row["band_factor"]] * len(row["maxima"]) for row in rows])
    count, _ = band_count(maxima, SPREAD_POOL * (TEACH - 1), math.sqrt(1.0 + 1.0 / TEACH))
    scale = 2.0 * maxima.size  # 2 M S is chi-square with 2 n degrees of freedom
    counts = (count * chi2.ppf(0.025, scale) / scale, count * chi2.ppf(0.975, scale) / scale)
    band = [_band_rate(maxima, factors, c) for c in (count, *counts)]
    ratios = np.concatenate([row["mean_ratios"] for row in rows])
    sd = float(np.sqrt(np.mean(ratios ** 2)))  # |D| / limit of good parts, centred at 0
    sd_high = sd * math.sqrt(ratios.size / chi2.ppf(0.025, ratios.size))
    mean = [2.0 * float(norm.sf(1.0 / sd)), 2.0 * float(norm.sf(1.0 / sd_high))]
    return {"false_alarms": alarms, "good_parts": parts, "counted_ci": [low, high], "band_count": count,
            "band_count_ci": list(counts), "band_rate": band[0], "band_rate_ci": [band[1], band[2]],
            "mean_rate": mean[0], "mean_rate_high": mean[1], "rate": band[0] + mean[0],
            "rate_ci": [band[1], band[2] + mean[1]]}


def truth_cut_force(envelope, part, shift: int) -> float:
    """Mean truth process force [N] over the envelope's cut samples of a part laid on the grid by ``shift``.

    Parameters
    ----------
    envelope : Envelope
        The envelope.
    part : Part
        A twin part (with ``truth_process_force_N``).
    shift : int
        Its shift [samples].
    """
    truth = centred_nanmean(shifted(part.extras["truth_process_force_N"], shift, envelope.centre_.size),
                        envelope.width_)
    return float(np.nanmean((envelope.direction_ * truth)[envelope.cut_]))


def _variant(parts, unit: str, relevel: bool, truth: dict, kind: str) -> dict:
    envelope = Envelope(false_alarm_rate=RATE, relevel=relevel).fit(parts[:TEACH], unit=unit)
    checks = {part.number: (part, check_part(envelope, part)) for part in parts[TEACH:]}
    good = [k for k in range(TEACH + 1, WEAR_START + 1) if k not in (MISSING, OVERSIZED)]
    crossing = int(truth["wear_15pct_part"])
    flagged_after = [k for k in range(WEAR_START + 1, BREAKAGE) if checks[k][1].flagged]
    broken = checks[BREAKAGE][1]
    at = float(truth["events_settings"]["breakage_time_s"])
    starts = [s.start_s for s in broken.stretches if s.kind in ("missing cut", "drop") and s.end_s >= at - 0.5]
    figures = [_good_figures(envelope, checks[k][1]) for k in good]
    row = {"false_alarms": sum(checks[k][1].flagged for k in good), "good_parts": len(good),
           "band_factor": envelope.band_factor_, "band_count": envelope.band_count_,
           "maxima": [round(u, 4) for u, _ in figures], "mean_ratios": [round(r, 4) for _, r in figures],
           "missing_blank": "missing cut" in checks[MISSING][1].kinds,
           "oversized_blank": "rise" in checks[OVERSIZED][1].kinds,
           "wear_flagged_part": flagged_after[0] if flagged_after else None, "wear_crossing_part": crossing,
           "breakage_flagged": broken.flagged,
           "breakage_location_error_s": abs(min(starts) - at) if starts else None}
    if kind == "force":
        errors = []
        for k in good:
            part, done = checks[k]
            reference = truth_cut_force(envelope, part, int(round(done.shift_s / envelope.sample_time_)))
            errors.append(100.0 * (done.cut_load / reference - 1.0))
        row["cut_force_error_pct"] = {"mean_abs": float(np.mean(np.abs(errors))), "max_abs": float(np.max(
            np.abs(errors))), "mean": float(np.mean(errors))}
    return row


def head_to_head(seeds, model: str, axis_config: str, *, good_seeds=(), work_dir: str | None = None,
                 progress=None) -> dict:
    """Run the protocol (module docstring) on each seed; figures per seed and variant.

    Parameters
    ----------
    seeds : sequence of int
        Seeds of the twin's series.
    model : str
        Model file trained on the cold machine's air cuts (``greybox train --model gms --train data/X_A.mcap
        data/X_C.mcap``).
    axis_config : str
        Axis file of the X axis (``examples/axis_x.toml``).
    good_seeds : sequence of int, default ()
        Seeds of series of good parts checked for the false-alarm rate (:func:`false_alarm_series`).
    work_dir : str, optional
        Where the series are written (default a temporary directory, removed afterwards).
    progress : callable, optional
        Called with one line per seed and variant.

    Returns
    -------
    dict
        ``{"series": {seed: {variant: figures}}, "good": {seed: {variant: figures}}, "false_alarms": {variant:
        summary}}``, the summary (:func:`false_alarm_summary`) over the good parts of both.
    """
    results = {}
    with tempfile.TemporaryDirectory(dir=work_dir) as scratch:
        for seed in seeds:
            path, truth = seed_series(int(seed), Path(scratch) / f"seed_{seed}")
            signals = {"raw": PartSignal(), "force": PartSignal(model=model, axis_config=axis_config)}
            read = {kind: source.parts(str(path)) for kind, source in signals.items()}
            results[int(seed)] = {}
            for name, (kind, relevel) in VARIANTS.items():
                parts, unit = read[kind]
                results[int(seed)][name] = _variant(parts, unit, relevel, truth, kind)
                if progress:
                    shown = {k: v for k, v in results[int(seed)][name].items() if k not in ("maxima", "mean_ratios")}
                    progress(f"seed {seed}, {name}: {shown}")
        good = {}
        for seed in good_seeds:
            good[int(seed)] = false_alarm_series(int(seed), model, axis_config, Path(scratch) / f"good_{seed}")
            if progress:
                progress(f"good parts, seed {seed}: " + ", ".join(
                    f"{name} {row['false_alarms']} / {row['good_parts']}" for name, row in good[int(seed)].items()))
    summary = {name: false_alarm_summary([rows[name] for rows in (*results.values(), *good.values())])
               for name in VARIANTS}
    return {"series": results, "good": good, "false_alarms": summary}


def head_to_head_table(series: dict) -> str:
    """The protocol's figures as a Markdown table, one row per variant, the seeds' figures side by side.

    Parameters
    ----------
    series : dict
        ``{seed: {variant: figures}}`` (:func:`head_to_head`'s ``"series"``).
    """
    lines = ["| variant | false alarms / good parts | missing blank | oversized blank | wear flagged at part "
             "(+15 % at) | breakage flagged, located within | mean cut force error (mean / max abs) |",
             "|---|---|---|---|---|---|---|"]
    for name in VARIANTS:
        rows = [series[seed][name] for seed in series]
        alarms = sum(r["false_alarms"] for r in rows)
        total = sum(r["good_parts"] for r in rows)
        wear = ", ".join(f"{r['wear_flagged_part']} ({r['wear_crossing_part']})" for r in rows)
        located = ", ".join("miss" if not r["breakage_flagged"] else
                            (f"{r['breakage_location_error_s']:.2f} s" if r["breakage_location_error_s"] is not None
                             else "flagged, no stretch") for r in rows)
        force = ", ".join(f"{r['cut_force_error_pct']['mean_abs']:.2f} / {r['cut_force_error_pct']['max_abs']:.2f} %"
                          for r in rows if "cut_force_error_pct" in r) or "-"
        lines.append(f"| {name} | {alarms} / {total} | {sum(r['missing_blank'] for r in rows)} / {len(rows)} | "
                     f"{sum(r['oversized_blank'] for r in rows)} / {len(rows)} | {wear} | {located} | {force} |")
    return "\n".join(lines) + "\n"


def false_alarm_table(summary: dict) -> str:
    """The false-alarm figures (:func:`false_alarm_summary` per variant) as a Markdown table.

    Parameters
    ----------
    summary : dict
        ``{variant: summary}``.
    """
    lines = ["| variant | good parts flagged | counted rate, 95 % interval | effective count M (95 %) | "
             "extrapolated rate per part (95 %) |", "|---|---|---|---|---|"]
    for name in VARIANTS:
        f = summary[name]
        lines.append(f"| {name} | {f['false_alarms']} / {f['good_parts']} | {f['counted_ci'][0]:.4f}-"
                     f"{f['counted_ci'][1]:.4f} | {f['band_count']:.0f} ({f['band_count_ci'][0]:.0f}-"
                     f"{f['band_count_ci'][1]:.0f}) | {f['rate']:.1e} ({f['rate_ci'][0]:.1e}-{f['rate_ci'][1]:.1e}) |")
    return "\n".join(lines) + "\n"


def targets(results: dict, name: str) -> dict:
    """Whether a variant meets the issue's targets on every seed of a set.

    Parameters
    ----------
    results : dict
        One set's results (:func:`head_to_head`).
    name : str
        The variant.

    Returns
    -------
    dict
        ``wear`` (flagged, after the wear starts, at most 5 parts after the part that crosses +15 %),
        ``breakage`` (flagged in its part, the stretch within 0.2 s), ``rate`` (neither the counted nor the
        extrapolated false-alarm rate's 95 % interval wholly above :data:`RATE`), ``cut_force`` (every good
        part's mean cut force within 2 %; None for a signal without one).
    """
    rows = [series[name] for series in results["series"].values()]
    rate = results["false_alarms"][name]
    force = [r["cut_force_error_pct"]["max_abs"] for r in rows if "cut_force_error_pct" in r]
    return {"wear": all(r["wear_flagged_part"] is not None and r["wear_flagged_part"] <= r["wear_crossing_part"] + 5
                        for r in rows),
            "breakage": all(r["breakage_flagged"] and r["breakage_location_error_s"] is not None
                            and r["breakage_location_error_s"] <= 0.2 for r in rows),
            "rate": rate["rate_ci"][0] <= RATE and rate["counted_ci"][0] <= RATE,
            "cut_force": (max(force) <= 2.0) if force else None}
