"""Mean cut force per part of ``greybox predict``, with and without ``--relevel``, on a twin part series.

Development measurement behind the default of ``greybox predict --relevel`` (docs/predict.md): each part's mean
process force over the samples where the tool cuts (``truth_process_force_N`` not zero) against the truth's
mean over the same samples, for the parts given. Write the series first, e.g.

    greybox synth --parts 20 --warmup-drop 0 --seed 101 --out cold101 --part-layout series --truth essential
    python scripts/predict_relevel.py --model gms_x.gbm --series cold101/X_series.mcap --parts 1-20 --chunk-s 120

or let ``--record`` write both series of the page (the cold one above, and the process head to head's series of
seed 101 through a warm-up), train the model (``greybox train --model gms --train data/X_A.mcap data/X_C.mcap``)
and print every figure as one JSON object last (the record of ``scripts/record.py``):

    python scripts/predict_relevel.py --record
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.data.axis_config import read_axis_config  # noqa: E402
from greybox.data.reading import read_prepared  # noqa: E402
from greybox.models.files import load_model  # noqa: E402
from greybox.predict.process import predict_process  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: How the record's model is trained.
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "data/X_C.mcap")
#: The record's cold series (no warm-up), as greybox synth writes it.
COLD = ("synth", "--parts", "20", "--warmup-drop", "0", "--seed", "101", "--part-layout", "series", "--truth",
        "essential")
#: The good parts of the process head to head's series (the taught ones, the missing and oversized blanks, the
#: worn and broken tool left out).
DEV_PARTS = "11-29,31-39,41-50"
#: The chunks the record re-levels with [s].
CHUNKS = (60.0, 120.0)


def _parts(text: str) -> list[int]:
    numbers = []
    for piece in text.split(","):
        low, _, high = piece.partition("-")
        numbers += list(range(int(low), int(high or low) + 1))
    return numbers


def read_series(series: str) -> tuple:
    """A part series' runs, and its ``part`` and ``truth_process_force_N`` channels joined over the runs."""
    runs = read_prepared(series, {})
    return (runs, np.concatenate([run.extras["part"] for run in runs]),
            np.concatenate([run.extras["truth_process_force_N"] for run in runs]))


def part_errors(model, series: tuple, axis_config: str, parts: str, relevel: bool, chunk_s: float) -> dict:
    """Error of each part's mean cut force [% of the truth's], with or without re-levelling.

    Parameters
    ----------
    model : CurrentModel
        The fitted model.
    series : tuple
        A part series as :func:`read_series` gives it.
    axis_config : str
        Axis file (TOML) converting the process current into force.
    parts : str
        The parts, e.g. ``"11-29,31-39"``.
    relevel : bool
        Re-level the model per chunk (``greybox predict --relevel``).
    chunk_s : float
        Chunk length [s].

    Returns
    -------
    dict
        ``parts`` (how many had a cut), ``mean_pct``, ``mean_abs_pct``, ``max_abs_pct``.
    """
    runs, part, truth = series
    result = predict_process(model, runs, axis_config=read_axis_config(axis_config), relevel=relevel,
                             chunk_s=chunk_s)
    errors = []
    for number in _parts(parts):
        cut = (part == number) & (truth != 0)
        if cut.any():
            estimated, true = np.mean(result.load[cut]), np.mean(truth[cut])
            errors.append(100.0 * (estimated - true) / abs(true) * np.sign(true))
    errors = np.array(errors)
    return {"parts": int(errors.size), "mean_pct": float(errors.mean()), "mean_abs_pct": float(np.abs(errors).mean()),
            "max_abs_pct": float(np.abs(errors).max())}


def _say(label: str, relevel: bool, chunk_s: float, errors: dict) -> None:
    print(f"{label}relevel {'on ' if relevel else 'off'} (chunk {chunk_s:g} s): {errors['parts']} parts, mean cut "
          f"force error {errors['mean_pct']:+.2f} % on average, mean abs {errors['mean_abs_pct']:.2f} %, "
          f"max abs {errors['max_abs_pct']:.2f} %", flush=True)


def record(axis_config: str) -> dict:
    """Write both series of the page, train the model, and measure every setting of the page's table."""
    from studies.process_head_to_head import DROP, WARMUP_S, seed_series

    greybox = str(Path(sys.executable).with_name("greybox"))
    figures = {"model": "greybox " + " ".join(TRAIN), "chunks_s": list(CHUNKS), "series": {}}
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        subprocess.run([greybox, *TRAIN, "--out", str(scratch / "gms_x.gbm")], cwd=ROOT, check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run([greybox, *COLD, "--out", str(scratch / "cold101")], cwd=ROOT, check=True,
                       stdout=subprocess.DEVNULL)
        warm, _ = seed_series(101, scratch / "dev101")
        model = load_model(scratch / "gms_x.gbm")
        cases = (("warm-up", warm, DEV_PARTS, f"warm-up, friction -{100 * DROP:g} % (time constant "
                  f"{WARMUP_S / 60:g} min), the process head to head's series of seed 101"),
                 ("cold", scratch / "cold101" / "X_series.mcap", "1-20", "cold machine (no warm-up), `greybox "
                  + " ".join(COLD) + "`"))
        for name, path, parts, what in cases:
            series = read_series(str(path))
            off = part_errors(model, series, axis_config, parts, False, CHUNKS[0])
            _say(f"{name}: ", False, CHUNKS[0], off)
            on = {}
            for chunk_s in CHUNKS:
                on[f"{chunk_s:g}"] = part_errors(model, series, axis_config, parts, True, chunk_s)
                _say(f"{name}: ", True, chunk_s, on[f"{chunk_s:g}"])
            figures["series"][name] = {"what": what, "parts": parts, "off": off, "on": on}
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model")
    parser.add_argument("--series", help="one long log of a part series with its truth channels")
    parser.add_argument("--axis-config", default="examples/axis_x.toml")
    parser.add_argument("--parts", help="the good parts, e.g. 11-29,31-39,41-50")
    parser.add_argument("--chunk-s", type=float, default=60.0)
    parser.add_argument("--record", action="store_true",
                        help="write the page's two series, train the model, measure and print every figure as JSON")
    args = parser.parse_args()
    if args.record:
        print(json.dumps(record(args.axis_config), indent=1))
        return
    if not (args.model and args.series and args.parts):
        parser.error("give --model, --series and --parts (or --record)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a model file without a digest: said by greybox itself elsewhere
        model = load_model(args.model)
    series = read_series(args.series)
    for relevel in (False, True):
        _say("", relevel, args.chunk_s, part_errors(model, series, args.axis_config, args.parts, relevel,
                                                    args.chunk_s))


if __name__ == "__main__":
    main()
