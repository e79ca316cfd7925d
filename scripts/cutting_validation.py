"""Validation of ``greybox predict`` on the synthetic axis: recovery of a known cutting-force current.

Runs the protocol of :mod:`studies.cutting` (models fitted on the
shipped air cuts, cutting logs of the twin at several cut strengths, the
process current recovered and compared with the truth) and prints its tables.

Usage::

    python scripts/cutting_validation.py --markdown validation.md --json validation.json --plot-dir figures
    python scripts/cutting_validation.py --record    # the figures as one JSON object last (scripts/record.py)
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.errors import GreyboxError
from greybox.twin.cutting import CuttingSpec
from studies.cutting import DEFAULT_STRENGTHS, KINDS, cutting_validation

ROOT = Path(__file__).resolve().parents[1]


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return value


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data", help="folder of the shipped air cuts X_A...X_D")
    parser.add_argument("--axis-config", type=Path, default=ROOT / "examples" / "axis_x.toml")
    parser.add_argument("--seed", type=int, default=7, help="seed of the cutting logs (the shipped data use 2024)")
    parser.add_argument("--model", nargs="+", default=list(KINDS), metavar="KIND", help="model kinds (default: all)")
    parser.add_argument("--strengths", type=_positive, nargs="+", default=list(DEFAULT_STRENGTHS), metavar="A",
                        help="cut strengths swept [A at 1000 mm/min, full engagement]")
    parser.add_argument("--strength", type=float, default=CuttingSpec().strength_A,
                        help="cut strength of the detailed table [A] (one of --strengths)")
    parser.add_argument("--target", type=float, default=0.95, help="correlation target")
    parser.add_argument("--chunk-s", type=float, default=60.0, help="chunk length of the prediction [s]")
    parser.add_argument("--markdown", type=Path, help="write the tables here")
    parser.add_argument("--json", type=Path, help="write all figures here")
    parser.add_argument("--plot-dir", type=Path, help="write the correlation figure and one picture per model and "
                        "test log (at the detailed strength) here")
    parser.add_argument("--force", action="store_true", help="overwrite existing outputs")
    parser.add_argument("--record", action="store_true",
                        help="print every figure as one JSON object at the end (the record of scripts/record.py)")
    args = parser.parse_args(argv)

    kinds = list(dict.fromkeys(args.model))
    try:
        result = cutting_validation(args.data, args.axis_config, seed=args.seed, kinds=kinds,
                                    strengths=tuple(args.strengths), strength=args.strength, target=args.target,
                                    chunk_s=args.chunk_s, markdown_path=args.markdown, json_path=args.json,
                                    plot_dir=args.plot_dir, progress=lambda line: print(line, flush=True),
                                    force=args.force)
    except GreyboxError as error:
        parser.error(str(error))
    print()
    print(result.tables, end="")
    noise = ", ".join(f"{name} {rms:.4f} A" for name, rms in result.noise_rms_A.items())
    print(f"noise floor rms(truth_noise_A): {noise}")
    if result.figure is not None:
        print(f"wrote {result.figure}")
    if args.record:
        print(json.dumps({"seed": args.seed, "strengths_A": list(args.strengths), "detail_strength_A": args.strength,
                          "target": args.target, "force_constant_N_per_A": result.force_constant_N_per_A,
                          "rows": result.rows, "cases": result.summaries}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
