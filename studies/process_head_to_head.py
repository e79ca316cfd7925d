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
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from greybox.process.alignment import shifted
from greybox.process.check import check_part
from greybox.process.envelope import Envelope
from greybox.process.parts import PartSignal
from greybox.twin.cutting import cut_segments
from greybox.twin.datasets import ESSENTIAL_TRUTH_CHANNELS
from greybox.twin.part_series import PartSeriesSpec, ToolEvents, WarmUp, make_part_series, synthesize_part_series
from greybox.windows import centred_nanmean

__all__ = ["PARTS", "TEACH", "RATE", "VARIANTS", "breakage_time", "head_to_head", "seed_series"]

PARTS, TEACH, WEAR_START, MISSING, OVERSIZED, BREAKAGE = 80, 10, 50, 30, 40, 75
#: Warm-up time constant [s] and drop.
WARMUP_S, DROP = 1200.0, 0.25
#: False alarms per good part the limits of every variant are set for.
RATE = 1e-3
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


def seed_series(seed: int, out_dir: Path) -> tuple[Path, dict]:
    """Write the seed's series (one long log) and return it with its truth.

    Parameters
    ----------
    seed : int
        Seed of the series.
    out_dir : pathlib.Path
        Where to write it.
    """
    events = ToolEvents(wear_pct_per_part=1.0, wear_start_part=WEAR_START, breakage_part=BREAKAGE,
                        breakage_time_s=breakage_time(), missing_blank=(MISSING,), oversized_blank=(OVERSIZED,))
    spec = PartSeriesSpec(parts=PARTS, warm_up=WarmUp(DROP, WARMUP_S, WARMUP_S), events=events)
    import json

    synthesize_part_series(spec, seed, out_dir, layout="series", truth_channels=ESSENTIAL_TRUTH_CHANNELS,
                           force=True)
    return out_dir / "X_series.mcap", json.loads((out_dir / "X_parts.json").read_text())


def _truth_cut_force(envelope, part, shift: int) -> float:
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
    row = {"false_alarms": sum(checks[k][1].flagged for k in good), "good_parts": len(good),
           "missing_blank": "missing cut" in checks[MISSING][1].kinds,
           "oversized_blank": "rise" in checks[OVERSIZED][1].kinds,
           "wear_flagged_part": flagged_after[0] if flagged_after else None, "wear_crossing_part": crossing,
           "breakage_flagged": broken.flagged,
           "breakage_location_error_s": abs(min(starts) - at) if starts else None}
    if kind == "force":
        errors = []
        for k in good:
            part, done = checks[k]
            reference = _truth_cut_force(envelope, part, int(round(done.shift_s / envelope.sample_time_)))
            errors.append(100.0 * (done.cut_load / reference - 1.0))
        row["cut_force_error_pct"] = {"mean_abs": float(np.mean(np.abs(errors))), "max_abs": float(np.max(
            np.abs(errors))), "mean": float(np.mean(errors))}
    return row


def head_to_head(seeds, model: str, axis_config: str, *, work_dir: str | None = None,
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
    work_dir : str, optional
        Where the series are written (default a temporary directory, removed afterwards).
    progress : callable, optional
        Called with one line per seed and variant.

    Returns
    -------
    dict
        ``{seed: {variant: figures}}``.
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
                    progress(f"seed {seed}, {name}: {results[int(seed)][name]}")
    return results
