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

The JSON is rewritten after every case, so a long run can be followed (and
an interrupted one still holds its cases).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.discovery import SECTIONS, run_section
from studies.discovery_family import run_family_study


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--section", required=True, choices=sorted([*SECTIONS, "family"]))
    parser.add_argument("--json", required=True, metavar="OUT", help="all cases and the summary")
    parser.add_argument("--markdown", metavar="MD", help="the tables")
    parser.add_argument("--seeds", type=int, help="seeds per effect and ratio")
    parser.add_argument("--null-seeds", type=int, help="null data sets")
    parser.add_argument("--ratios", help="effect RMS over noise RMS, comma-separated")
    parser.add_argument("--duration", type=float, help="length of the training and test logs [s]")
    parser.add_argument("--effects", help="comma-separated hidden effects (default: the whole library)")
    parser.add_argument("--first-seed", type=int, default=0, help="family: seed of the first axis (default 0)")
    parser.add_argument("--workers", type=int, default=1, help="family: processes running cases side by side")
    parser.add_argument("--data", metavar="DIR", help="emps: directory of DATA_EMPS.mat and DATA_EMPS_PULSES.mat")
    return parser.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.section == "emps" and not args.data:
        raise SystemExit("--section emps needs --data DIR")
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
