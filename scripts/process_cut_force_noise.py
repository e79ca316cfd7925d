"""Where the per-part mean cut force error of the re-levelled force envelope comes from (development seeds only).

On the head to head's series of a seed (:func:`studies.process_head_to_head.seed_series`), the envelope of the
re-levelled force is taught on parts 1-10 and each good part's mean cut force compared with the truth, three
times: as logged; with the current's measurement noise removed where the envelope re-levels (the air samples,
widened by a smoothing length: the re-levelling factor then carries no noise); and with the noise removed
everywhere (the twin's ``truth_current_A`` is the current without noise). What is left in the third is the
method's bias; the second shows what no re-levelling can remove, the noise over the part's own cut.

    greybox train --model gms --train data/X_A.mcap data/X_C.mcap --out gms_x.gbm
    python scripts/process_cut_force_noise.py --model gms_x.gbm --seed 101
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.data.io import read_log  # noqa: E402
from greybox.process.check import check_part  # noqa: E402
from greybox.process.envelope import Envelope  # noqa: E402
from greybox.process.parts import PartSignal  # noqa: E402
from studies.process_head_to_head import (  # noqa: E402
    MISSING,
    OVERSIZED,
    RATE,
    TEACH,
    WEAR_START,
    seed_series,
    truth_cut_force,
)

ROOT = Path(__file__).resolve().parents[1]


def _errors(envelope, parts, noises, where) -> list[float]:
    errors = []
    for part in parts:
        noise = noises[part.number]
        if where is not None:
            shift = int(round(check_part(envelope, part).shift_s / envelope.sample_time_))
            index = np.flatnonzero(where) + shift
            mask = np.zeros(noise.size)
            mask[index[(index >= 0) & (index < noise.size)]] = 1.0
            noise = noise * (np.convolve(mask, np.ones(2 * envelope.width_ + 1), mode="same") > 0)
        current = part.current - noise
        quiet = dataclasses.replace(part, current=current, signal=part.convert(current, part.velocity))
        done = check_part(envelope, quiet)
        truth = truth_cut_force(envelope, part, int(round(done.shift_s / envelope.sample_time_)))
        errors.append(100.0 * (done.cut_load / truth - 1.0))
    return errors


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", required=True, help="GMS model file trained on data/X_A.mcap data/X_C.mcap")
    parser.add_argument("--axis-config", default=str(ROOT / "examples" / "axis_x.toml"))
    parser.add_argument("--seed", type=int, default=101)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as scratch:
        path, _ = seed_series(args.seed, Path(scratch))
        parts, unit = PartSignal(model=args.model, axis_config=args.axis_config).parts(str(path))
        log = read_log(path)
    envelope = Envelope(false_alarm_rate=RATE, relevel=True).fit(parts[:TEACH], unit=unit)
    good = [part for part in parts if TEACH < part.number <= WEAR_START and part.number not in (MISSING, OVERSIZED)]
    noises = {}
    for part in good:
        a = int(np.searchsorted(log.time, part.start_s - 1e-9))
        noises[part.number] = (log.effort[a:a + part.time.size]
                               - log.extras["truth_current_A"][a:a + part.time.size])
    zero = {number: np.zeros_like(noise) for number, noise in noises.items()}
    figures = {}
    for name, (noise, where) in {"as logged": (zero, None), "no noise in air": (noises, envelope.air_),
                                 "no noise": (noises, None)}.items():
        errors = np.array(_errors(envelope, good, noise, where))
        figures[name] = {"mean": float(errors.mean()), "sd": float(errors.std(ddof=1)),
                         "max_abs": float(np.abs(errors).max()), "parts": int(errors.size)}
        print(f"{name}: mean {errors.mean():+.2f} %, sd {errors.std(ddof=1):.2f} %, largest |error| "
              f"{np.abs(errors).max():.2f} % over {errors.size} good parts")
    print(json.dumps({"seed": args.seed, **figures}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
