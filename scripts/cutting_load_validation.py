"""Cutting under load on the family of truth axes: mean process force per pass direction (issue 16).

Fits Stribeck, GMS and GMS+SVR (the paper's experiment 2 on each member's air
cuts A and B), cuts dataset D with a force that opposes the motion on one
stroke and pushes the table along on the other, and compares the process
force ``greybox predict`` gives with the member's axis file against the true
one (:mod:`studies.cutting_load`). Example (the figures of the README)::

    python scripts/cutting_load_validation.py --members 24 --seed 2026 --workers 2 --json load.json --markdown load.md
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.cutting_load import run_cutting_load_study


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=24, help="number of axes (default 24)")
    parser.add_argument("--seed", type=int, default=2026, help="family seed (default 2026)")
    parser.add_argument("--first", type=int, default=0, help="index of the first member (default 0)")
    parser.add_argument("--workers", type=int, default=1, help="processes running members side by side")
    parser.add_argument("--json", required=True, metavar="OUT", help="every member and the summary")
    parser.add_argument("--markdown", metavar="MD", help="the tables")
    return parser.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    print(run_cutting_load_study(args.json, markdown_path=args.markdown, members=args.members,
                                 family_seed=args.seed, first=args.first, workers=args.workers,
                                 progress=lambda line: print(line, flush=True)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
