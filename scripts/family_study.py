"""Robustness study on the family of truth axes (issue 15; see docs/synthetic-axis.md, 'The family of truth axes').

Draws ``--members`` axes of the family (four friction laws in turn, random
parameters in documented ranges), fits every model of the paper's experiment
1 on each axis' dataset A, tests on C and on C with a cut, and reports each
model's median and 90th percentile of test RE over the noise floor's RE and
of the process-force error (:mod:`studies.robustness`). Example (the
figures of the README)::

    python scripts/family_study.py --members 50 --seed 2026 --workers 2 --json family.json --markdown family.md

The JSON is rewritten after every member, so a long run can be followed.
``--choose-priors`` instead scores the GMS+SVR prior candidates on the training
runs (fit on three quarters of A, score on the rest of A and on B) of a
development family (:mod:`studies.priors`); with ``--model svr`` the
sole SVR's kernel candidates::

    python scripts/family_study.py --choose-priors --members 12 --seed 1 --workers 2 --json priors.json
    python scripts/family_study.py --choose-priors --model svr --members 12 --seed 1 --workers 2 --json svr.json
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.priors import run_prior_study
from studies.robustness import run_robustness_study


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=50, help="number of axes (default 50)")
    parser.add_argument("--seed", type=int, default=2026, help="family seed (default 2026)")
    parser.add_argument("--first", type=int, default=0, help="index of the first member (default 0)")
    parser.add_argument("--workers", type=int, default=1, help="processes running members side by side")
    parser.add_argument("--json", required=True, metavar="OUT", help="every member and the summary")
    parser.add_argument("--markdown", metavar="MD", help="the tables")
    parser.add_argument("--choose-priors", action="store_true",
                        help="score the GMS+SVR prior candidates on the training runs A and B instead")
    parser.add_argument("--model", choices=("gmssvr", "svr"), default="gmssvr",
                        help="with --choose-priors: the study, GMS+SVR's priors or the sole SVR's kernel")
    return parser.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.choose_priors:
        result = run_prior_study(args.json, members=args.members, family_seed=args.seed, workers=args.workers,
                                 model=args.model, progress=lambda line: print(line, flush=True))
        for name, cell in result["summary"].items():
            print(f"{name}: RE / noise floor, median (p90): rest of A {cell['A_tail']['median']:.3f} "
                  f"({cell['A_tail']['p90']:.3f}), B {cell['B']['median']:.3f} ({cell['B']['p90']:.3f}), "
                  f"mean {cell['mean']['median']:.3f}")
        print(f"best: {result['best']}; within 1 %: {', '.join(result['equivalent'])}; chosen: {result['chosen']} "
              f"({result['seconds'] / 60:.1f} min)")
        return 0
    text = run_robustness_study(args.json, markdown_path=args.markdown, members=args.members,
                                family_seed=args.seed, first=args.first, workers=args.workers,
                                progress=lambda line: print(line, flush=True))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
