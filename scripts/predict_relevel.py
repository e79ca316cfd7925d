"""Mean cut force per part of ``greybox predict``, with and without ``--relevel``, on a twin part series.

Development measurement behind the default of ``greybox predict --relevel`` (docs/predict.md): each part's mean
process force over the samples where the tool cuts (``truth_process_force_N`` not zero) against the truth's
mean over the same samples, for the parts given. Write the series first, e.g.

    greybox synth --parts 20 --warmup-drop 0 --seed 101 --out cold101 --part-layout series --truth essential
    python scripts/predict_relevel.py --model gms_x.gbm --series cold101/X_series.mcap --parts 1-20 --chunk-s 120
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from greybox.data.axis_config import read_axis_config
from greybox.data.reading import read_prepared
from greybox.models.files import load_model
from greybox.predict.process import predict_process


def _parts(text: str) -> list[int]:
    numbers = []
    for piece in text.split(","):
        low, _, high = piece.partition("-")
        numbers += list(range(int(low), int(high or low) + 1))
    return numbers


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", required=True)
    parser.add_argument("--series", required=True, help="one long log of a part series with its truth channels")
    parser.add_argument("--axis-config", default="examples/axis_x.toml")
    parser.add_argument("--parts", required=True, help="the good parts, e.g. 11-29,31-39,41-50")
    parser.add_argument("--chunk-s", type=float, default=60.0)
    args = parser.parse_args()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a model file without a digest: said by greybox itself elsewhere
        model = load_model(args.model)
    runs = read_prepared(args.series, {})
    part = np.concatenate([run.extras["part"] for run in runs])
    truth = np.concatenate([run.extras["truth_process_force_N"] for run in runs])
    config = read_axis_config(args.axis_config)
    for relevel in (False, True):
        result = predict_process(model, runs, axis_config=config, relevel=relevel, chunk_s=args.chunk_s)
        errors = []
        for number in _parts(args.parts):
            cut = (part == number) & (truth != 0)
            if cut.any():
                estimated, true = np.mean(result.load[cut]), np.mean(truth[cut])
                errors.append(100.0 * (estimated - true) / abs(true) * np.sign(true))
        errors = np.array(errors)
        print(f"relevel {'on ' if relevel else 'off'} (chunk {args.chunk_s:g} s): {errors.size} parts, mean cut force "
              f"error {errors.mean():+.2f} % on average, mean abs {np.abs(errors).mean():.2f} %, "
              f"max abs {np.abs(errors).max():.2f} %")


if __name__ == "__main__":
    main()
