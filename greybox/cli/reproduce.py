"""``greybox reproduce``: run the paper's two experiments on the shipped data and write the report."""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path

from ..errors import GreyboxError
from ..evaluate.pattern import paper_pattern, sole_svr_beside_paper
from ..evaluate.report import check_output_dir
from ..reproduce.experiments import EXPERIMENTS, find_log, reproduce
from ._spelling import message_text
from ._types import POSITIVE_INT


def default_data_dir() -> Path:
    """The shipped synthetic logs: ``./data`` when run in a greybox checkout, else the source tree's ``data/``.

    A plain (non-editable) install puts the package in site-packages, away from the
    repository's ``data/``; the README runs the command from the repository root.
    """
    here = Path.cwd() / "data"
    if (here / "X_A.mcap").is_file():
        return here
    return Path(__file__).resolve().parents[2] / "data"


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "reproduce",
        description="Experiment 1 (paper's Table 3): train on A, test on C. Experiment 2 (Table 4): train on A + B "
        "(GMS+SVR: GMS on A, SVR on B), test on C + D. Coulomb, Stribeck, LuGre, GMS, SVR and GMS+SVR models on "
        "every axis; writes metrics.json/csv, tables.md, PNG figures, index.html and the model files into DIR.",
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="report directory (new or empty)")
    parser.add_argument("--axis", nargs="+", default=["X", "Y"], metavar="AXIS", help="axes to run (default: X Y)")
    parser.add_argument("--data", metavar="DIR",
                        help="directory of the <axis>_<dataset>.mcap logs "
                        "(default: ./data, else the source tree's data/)")
    parser.add_argument("--quick", action="store_true",
                        help="smoke run: first 30 s of every log, small optimisation budgets")
    parser.add_argument("--jobs", type=POSITIVE_INT, default=2, metavar="N",
                        help="worker processes; the axes run in parallel (default 2)")
    parser.add_argument("--force", action="store_true", help="write into a non-empty DIR")
    parser.add_argument("--no-models", action="store_true", help="do not save the fitted model files")
    verbosity = parser.add_mutually_exclusive_group()
    verbosity.add_argument("--quiet", action="store_true", help="no progress display")
    verbosity.add_argument("--verbose", action="store_true", help="also show every model's identification progress")
    parser.set_defaults(run=run)


class _Elapsed:
    """Progress lines on stderr, prefixed with the time since the start; a fit's warning as a note."""

    def __init__(self):
        self.started = time.perf_counter()

    def __call__(self, item: str | Warning) -> None:
        line = item if isinstance(item, str) else "  note: " + message_text(item, settable=False)
        print(f"[{time.perf_counter() - self.started:6.1f} s] {line}", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    axes = list(dict.fromkeys(a.strip() for a in args.axis if a.strip()))
    if not axes:
        raise GreyboxError("--axis names no axis")
    data_dir = Path(args.data) if args.data else default_data_dir()
    if not data_dir.is_dir():
        hint = "" if args.data else " (no shipped data next to the package: give --data DIR)"
        raise GreyboxError(f"{data_dir}: data directory does not exist{hint}")
    out_dir = check_output_dir(args.out, force=args.force)
    if out_dir.exists() and out_dir.resolve() == data_dir.resolve():
        raise GreyboxError(f"{out_dir}: is the data directory; choose another report directory")
    datasets = dict.fromkeys(d for experiment in EXPERIMENTS for d in experiment.datasets)
    for axis in axes:  # fail on a missing log before any fitting
        for dataset in datasets:
            find_log(data_dir, axis, dataset)

    command = ["greybox", "reproduce", "--out", str(out_dir), "--axis", *axes, "--data", str(data_dir)]
    command += ["--quick"] * args.quick
    progress = None if args.quiet else _Elapsed()
    result = reproduce(out_dir, data_dir, axes=axes, quick=args.quick, jobs=args.jobs,
                       save_models=not args.no_models, progress=progress,
                       model_progress=True if args.verbose else None,
                       intro="Command: " + " ".join(shlex.quote(part) for part in command))
    print(f"reproduced {len(axes)} axis/axes in {result.seconds:.0f} s")
    for name in ("metrics_json", "metrics_csv", "tables", "html"):
        print(f"  {result.files[name]}")
    print(f"  {len(result.files['figures'])} figures, {len(result.files['models'])} model files in {out_dir}")
    checks = paper_pattern(result.records)
    if checks:
        caveat = " (--quick: small search budgets, not the figures of a full run)" if args.quick else ""
        print(f"the paper's pattern: {sum(c['met'] for c in checks)} of {len(checks)} checks met{caveat}")
        for c in checks:
            print(f"  {'met    ' if c['met'] else 'not met'} {c['check']} ({c['axis']}): {c['ours']} "
                  f"(target {c['target']}, paper {c['paper']})")
    figures = sole_svr_beside_paper(result.records)
    if figures:
        print("the sole SVR beside the paper (shown, not checked: the paper's SVR training is not described "
              "in enough detail to copy):")
        for f in figures:
            print(f"  {f['figure']} ({f['axis']}): {f['ours']} (paper {f['paper']})")
    return 0
