"""Per-part mean cut force error of the re-levelled force: the re-levelling factor per part or pooled over parts.

Development seeds only. On the head to head's series of a seed (:func:`studies.process_head_to_head.seed_series`;
``--good``: its series of good parts), the envelope of the re-levelled force is taught on parts 1-10, and each
checked good part's mean cut force over the taught cut samples is compared with the truth over the same samples,
the force computed with the model's current scaled per direction by a factor ``beta``:

- ``none``: ``beta = 0`` (no re-levelling);
- ``per part``: the part's own factor, fitted on its air samples (what ``greybox process check --relevel`` does);
- ``pooled H``: per direction, a straight line fitted to the factors of the parts within ``H`` parts of it
  (itself included) against their start time, taken at its start (the warm-up is slow against a part);
- ``warm-up law``: per direction, ``a + b exp(-t / tau)`` fitted to every part's factor against its start
  time ``t`` (the twin's law, ``tau`` by a grid search);
- ``true friction``: the model's current replaced by the twin's true current without process (the current
  noise is all that is left: the floor no re-levelling can go below).

Printed per variant: the mean, 95th percentile and largest of the absolute per-part errors [%], and their mean.

    greybox train --model gms --train data/X_A.mcap data/X_C.mcap --out gms_x.gbm
    python scripts/process_cut_force_pooling.py --model gms_x.gbm --seed 101
    python scripts/process_cut_force_pooling.py --model gms_x.gbm --seed 111 --good
    python scripts/process_cut_force_pooling.py --record    # both, the model trained first: one JSON object

``--record`` (the record ``process-pooling``) trains the model into a temporary directory (``greybox train``, in
this process) unless ``--model`` is given, and runs the protocol's series of seed 101 and the good parts of seed 111.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.cli import main as greybox  # noqa: E402
from greybox.predict.relevel import relevelled  # noqa: E402
from greybox.process.check import check_part  # noqa: E402
from greybox.process.envelope import Envelope  # noqa: E402
from greybox.process.parts import PartSignal  # noqa: E402
from greybox.windows import centred_nanmean  # noqa: E402
from studies.process_head_to_head import MISSING, OVERSIZED, RATE, TEACH, WEAR_START, seed_series  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
HALF_WIDTHS = (1, 2, 3, 5, 8, 12)
NAMES = ("negative", "positive")
#: The record's runs: the protocol's series of development seed 101, the good parts of development seed 111.
RECORD_RUNS = ((101, False), (111, True))
#: How the model is trained (on the shipped cold machine's air cuts, as the head to head).
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "data/X_C.mcap")


def _laid(envelope, part):
    """The part's arrays on the reference grid: process current, model current, velocity, truth force, true
    current without process."""
    _, template, _, place = envelope._aligned(part)
    extras = part.extras
    true_level = place(extras["truth_current_A"] - extras["truth_process_A"])
    measured = part.current + part.level  # the process current is the measured current minus the model's
    return {"current": place(part.current), "template": template, "velocity": place(part.velocity),
            "truth": place(extras["truth_process_force_N"]), "true_process": place(measured) - true_level}


def _cut_force(envelope, part, laid, current) -> float:
    force = centred_nanmean(part.convert(current, laid["velocity"]), envelope.width_, complete=True)
    return float(np.nanmean((envelope.direction_ * force)[envelope.cut_]))


def _scaled(envelope, laid, beta) -> np.ndarray:
    held = envelope.held_direction_
    factor = np.where(held < 0, beta[0], np.where(held > 0, beta[1], 0.0))
    return laid["current"] - factor * laid["template"]


def _local_line(times, values, half: int) -> np.ndarray:
    out = np.empty_like(values)
    for k in range(values.size):
        near = slice(max(0, k - half), min(values.size, k + half + 1))
        slope, intercept = np.polyfit(times[near], values[near], 1)
        out[k] = slope * times[k] + intercept
    return out


def _warm_up_fit(times, values) -> np.ndarray:
    best = None
    for tau in np.geomspace(120.0, 20000.0, 80):
        design = np.column_stack([np.ones_like(times), np.exp(-(times - times[0]) / tau)])
        coef, *_ = np.linalg.lstsq(design, values, rcond=None)
        residual = float(np.sum((design @ coef - values) ** 2))
        if best is None or residual < best[0]:
            best = (residual, design @ coef)
    return best[1]


def _summary(errors) -> dict:
    errors = np.asarray(errors)
    magnitude = np.abs(errors)
    return {"mean_abs": float(magnitude.mean()), "p95_abs": float(np.percentile(magnitude, 95)),
            "max_abs": float(magnitude.max()), "mean": float(errors.mean()), "sd": float(errors.std(ddof=1)),
            "parts": int(errors.size)}


def pooled_errors(model: str, axis_config: str, seed: int, good_only: bool) -> dict:
    """Each checked good part's mean cut force error for every way of choosing the re-levelling factor.

    Parameters
    ----------
    model : str
        GMS model file trained on ``data/X_A.mcap`` and ``data/X_C.mcap``.
    axis_config : str
        The axis file.
    seed : int
        Seed of the twin's series.
    good_only : bool
        The seed's series of good parts instead of the protocol's series.

    Returns
    -------
    dict
        ``seed``, ``good_series``, ``parts`` and, per variant, the summary of the per-part errors [%]
        (``mean_abs``, ``p95_abs``, ``max_abs``, ``mean``, ``sd``, ``parts``); ``factor_sd_part_to_part``: the
        part-to-part standard deviation of each direction's factor.
    """
    with tempfile.TemporaryDirectory() as scratch:
        path, _ = seed_series(seed, Path(scratch), good_only=good_only)
        parts, unit = PartSignal(model=model, axis_config=axis_config).parts(str(path))
    envelope = Envelope(false_alarm_rate=RATE, relevel=True).fit(parts[:TEACH], unit=unit)
    if good_only:
        good = {part.number for part in parts[TEACH:]}
    else:
        good = {k for k in range(TEACH + 1, WEAR_START + 1) if k not in (MISSING, OVERSIZED)}
    checked = parts[TEACH:]
    laid = [_laid(envelope, part) for part in checked]
    betas = np.array([[relevelled(one["current"], envelope.held_direction_, envelope.air_,
                                  template=one["template"])[1][name] for name in NAMES] for one in laid])
    times = np.array([part.start_s for part in checked])
    truths = np.array([float(np.nanmean((envelope.direction_ * centred_nanmean(one["truth"], envelope.width_))
                                        [envelope.cut_])) for one in laid])
    variants = {"none": np.zeros_like(betas), "per part": betas}
    for half in HALF_WIDTHS:
        variants[f"pooled {half}"] = np.column_stack([_local_line(times, betas[:, j], half) for j in range(2)])
    variants["warm-up law"] = np.column_stack([_warm_up_fit(times, betas[:, j]) for j in range(2)])
    keep = [k for k, part in enumerate(checked) if part.number in good]
    figures = {"seed": seed, "good_series": good_only, "parts": len(keep)}
    for name, beta in variants.items():
        errors = [100.0 * (_cut_force(envelope, checked[k], laid[k], _scaled(envelope, laid[k], beta[k]))
                           / truths[k] - 1.0) for k in keep]
        figures[name] = _summary(errors)
    own = check_part(envelope, checked[keep[0]]).cut_load
    again = _cut_force(envelope, checked[keep[0]], laid[keep[0]], _scaled(envelope, laid[keep[0]], betas[keep[0]]))
    assert abs(own - again) < 1e-6 * max(1.0, abs(own)), (own, again)  # the per-part variant is the check's
    errors = [100.0 * (_cut_force(envelope, checked[k], laid[k], laid[k]["true_process"]) / truths[k] - 1.0)
              for k in keep]
    figures["true friction"] = _summary(errors)
    figures["factor_sd_part_to_part"] = {name: float(np.std(np.diff(betas[:, j]), ddof=1) / np.sqrt(2.0))
                                         for j, name in enumerate(NAMES)}
    return figures


def _print(figures: dict) -> None:
    for name, row in figures.items():
        if isinstance(row, dict) and "max_abs" in row:
            print(f"{name:>14}: |error| mean {row['mean_abs']:.2f} %, p95 {row['p95_abs']:.2f} %, max "
                  f"{row['max_abs']:.2f} %; signed mean {row['mean']:+.2f} %, sd {row['sd']:.2f} % "
                  f"({row['parts']} parts)")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", help="GMS model file trained on data/X_A.mcap data/X_C.mcap (required but "
                        "with --record, which trains it when not given)")
    parser.add_argument("--axis-config", default=str(ROOT / "examples" / "axis_x.toml"))
    parser.add_argument("--seed", type=int, default=101)
    parser.add_argument("--good", action="store_true", help="the seed's series of good parts")
    parser.add_argument("--record", action="store_true", help="seed 101 and the good parts of seed 111, one JSON "
                        "object printed last (the record process-pooling)")
    args = parser.parse_args(argv)
    if not args.record:
        if not args.model:
            parser.error("--model is required without --record")
        figures = pooled_errors(args.model, args.axis_config, args.seed, args.good)
        _print(figures)
        print(json.dumps(figures))
        return 0
    with tempfile.TemporaryDirectory() as scratch:
        model = args.model
        if model is None:
            model = str(Path(scratch) / "gms_x.gbm")
            if greybox([*TRAIN, "--quiet", "--out", model]) != 0:
                raise SystemExit(f"greybox {' '.join(TRAIN)} failed")
        runs = [pooled_errors(model, args.axis_config, seed, good) for seed, good in RECORD_RUNS]
    for figures in runs:
        print(f"seed {figures['seed']}{' (good parts)' if figures['good_series'] else ''}:")
        _print(figures)
    print(json.dumps({"model": "greybox " + " ".join(TRAIN) if args.model is None else args.model, "runs": runs}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
