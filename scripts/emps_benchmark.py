"""The EMPS benchmark: greybox's friction models on a real ball-screw drive.

Runs the benchmark's protocol (:mod:`studies.emps`: data, filtering,
decimated relerr, the published IDIM-LS estimators beside the greybox fits)
and prints the Markdown table.

Usage::

    python scripts/emps_benchmark.py --json emps.json --markdown emps.md --plot emps.png
    python scripts/emps_benchmark.py --record --quiet   # the results as JSON on standard output
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.errors import GreyboxError
from studies.emps import MODEL_NAMES, TEST_FILE, TRAIN_FILE, emps_benchmark, run_benchmark

#: Default data folder: ``$GREYBOX_REAL_DATA/EMPS``, else ``../shared/data/real/EMPS`` beside the repository
#: (as the tests look for it).
DEFAULT_DATA = Path(os.environ.get("GREYBOX_REAL_DATA")
                    or Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real") / "EMPS"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    outputs = parser.add_mutually_exclusive_group(required=True)
    outputs.add_argument("--json", type=Path, metavar="OUT", help="JSON results file")
    outputs.add_argument("--record", action="store_true",
                         help="write no file: print the JSON results on standard output, last "
                              "(the command of a record, scripts/record.py)")
    parser.add_argument("--markdown", type=Path, metavar="MD", help="Markdown table")
    parser.add_argument("--plot", type=Path, metavar="PNG", help="figure of measured vs modelled force")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, metavar="DIR",
                        help=f"folder with {TRAIN_FILE} and {TEST_FILE} (default: %(default)s)")
    parser.add_argument("--models", nargs="+", choices=MODEL_NAMES, default=list(MODEL_NAMES), metavar="NAME",
                        help=f"models to run (default: all of {', '.join(MODEL_NAMES)})")
    parser.add_argument("--model-seed", type=int, default=0, help="seed of the multi-start identifications")
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    parser.add_argument("--force", action="store_true", help="overwrite existing output files")
    args = parser.parse_args(argv)
    if args.record and (args.markdown or args.plot):
        parser.error("--record writes no file: give --markdown and --plot with --json")
    try:
        if args.record:
            results, _ = run_benchmark(args.data, args.models, args.model_seed, progress=None if args.quiet else True)
            print(json.dumps(results, indent=1))
            return 0
        table = emps_benchmark(args.data, args.json, markdown_path=args.markdown, plot_path=args.plot,
                               names=args.models, seed=args.model_seed, progress=None if args.quiet else True,
                               force=args.force)
    except GreyboxError as error:
        print(f"emps_benchmark: error: {error}", file=sys.stderr)
        return 2
    print(table, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
