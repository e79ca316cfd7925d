"""Validation study of the discovery workflow on the synthetic axis (a benchmark; see docs/discover.md).

Hides every library effect at several strengths in synthetic logs, runs
``greybox.discover.workflow.discover`` on each, and reports the false-positive
rate on null data, the naming accuracy and the test-gap closure against the
true term (:mod:`studies.discovery`). Four sections:

``coulomb``  Coulomb plant (the base model class is exactly right), Coulomb base model.
``twin``     the twin's truth plant, GMS base model (the plant's own structure
             may be found too: counted as background, not as false).
``family``   axes of the independent hysteresis family (:mod:`studies.hysteresis_axis`,
             a Bouc-Wen friction law the workflow was not developed on), GMS base model,
             a null axis and one hidden effect per seed (:mod:`studies.discovery_family`).
``emps``     the real EMPS benchmark (``--data`` directory): base fitted on
             DATA_EMPS, tested on DATA_EMPS_PULSES, Coulomb and GMS bases (both
             with an offset); errors also on the benchmark's decimated samples.

Example (the figures of docs/discover.md)::

    python scripts/discovery_study.py --section coulomb --json coulomb.json --markdown coulomb.md
    python scripts/discovery_study.py --section twin --json twin.json --markdown twin.md
    python scripts/discovery_study.py --section family --first-seed 100 --seeds 5 --workers 2 \
        --json family.json --markdown family.md
    python scripts/discovery_study.py --section emps --data ../shared/data/real/EMPS --json emps.json --markdown emps.md
    python scripts/discovery_study.py --section emps --record   # the JSON last on standard output

The JSON is rewritten after every case, so a long run can be followed (and
an interrupted one still holds its cases).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.discovery import SECTIONS, run_section
from studies.discovery_family import run_family_study

#: Default EMPS folder: ``$GREYBOX_REAL_DATA/EMPS``, else ``../shared/data/real/EMPS`` beside the repository.
DEFAULT_EMPS = Path(os.environ.get("GREYBOX_REAL_DATA")
                    or Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real") / "EMPS"


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--section", required=True, choices=sorted([*SECTIONS, "family"]))
    outputs = parser.add_mutually_exclusive_group(required=True)
    outputs.add_argument("--json", metavar="OUT", help="all cases and the summary")
    outputs.add_argument("--record", action="store_true",
                         help="write no file: print the JSON document last on standard output, on one line (the "
                              "command of a record, scripts/record.py)")
    parser.add_argument("--markdown", metavar="MD", help="the tables")
    parser.add_argument("--seeds", type=int, help="seeds per effect and ratio")
    parser.add_argument("--null-seeds", type=int, help="null data sets")
    parser.add_argument("--ratios", help="effect RMS over noise RMS, comma-separated")
    parser.add_argument("--duration", type=float, help="length of the training and test logs [s]")
    parser.add_argument("--effects", help="comma-separated hidden effects (default: the whole library)")
    parser.add_argument("--first-seed", type=int, default=0, help="family: seed of the first axis (default 0)")
    parser.add_argument("--workers", type=int, default=1, help="family: processes running cases side by side")
    parser.add_argument("--data", metavar="DIR", default=str(DEFAULT_EMPS),
                        help=f"emps: directory of DATA_EMPS.mat and DATA_EMPS_PULSES.mat (default {DEFAULT_EMPS})")
    args = parser.parse_args(argv)
    if args.record and args.markdown:
        parser.error("--record writes no file: give --markdown with --json")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    if not args.record:
        return _run(args)
    with tempfile.TemporaryDirectory() as scratch:
        args.json = str(Path(scratch) / "study.json")
        status = _run(args)
        document = json.loads(Path(args.json).read_text(encoding="utf-8"))
    print(json.dumps(document))
    return status


def _run(args: argparse.Namespace) -> int:
    ratios = tuple(float(r) for r in args.ratios.split(",")) if args.ratios else None
    effects = tuple(args.effects.split(",")) if args.effects else None
    if args.section == "family":
        options = {key: value for key, value in (("seeds", args.seeds), ("null_seeds", args.null_seeds),
                                                 ("ratios", ratios), ("duration_s", args.duration),
                                                 ("effects", effects)) if value is not None}
        text = run_family_study(args.json, markdown_path=args.markdown, first_seed=args.first_seed,
                                workers=args.workers, progress=lambda line: print(line, flush=True), **options)
        print(text)
        return 0
    text = run_section(args.section, args.json, markdown_path=args.markdown, seeds=args.seeds,
                       null_seeds=args.null_seeds,
                       ratios=ratios, duration_s=args.duration, effects=effects,
                       data=args.data, progress=lambda line: print(line, flush=True))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
