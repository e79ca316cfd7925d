"""``greybox monitor``: friction fingerprints of logs into a history, change detection, a dashboard."""

from __future__ import annotations

import argparse

from ._types import NumberRange


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "monitor",
        description=(
            "Fit each log's friction fingerprint (sliding and break-away level per direction, viscous "
            "coefficient, residual noise, with 95 %% intervals) on its stretches without process load, add it to "
            "the Parquet history DIR (machine/axis/date; a log already there is not fitted again), run a CUSUM "
            "change detector per feature against the first days' baseline and write the dashboard "
            "OUT/index.html, the axes most severe first. A log's day is its 'date' attribute or the YYYY-MM-DD "
            "in its file name."
        ),
    )
    parser.add_argument("logs", nargs="*", metavar="LOG", help="axis logs (any supported format), current in A")
    parser.add_argument("--history", required=True, metavar="DIR", help="fingerprint history (created if missing)")
    parser.add_argument("--out", required=True, metavar="DIR", help="directory of the dashboard index.html")
    parser.add_argument("--machine", metavar="NAME",
                        help="machine name of the logs (default: each log's 'machine' attribute)")
    parser.add_argument("--axis", metavar="NAME", help="axis to read from files of several axes")
    parser.add_argument("--model", metavar="FILE",
                        help="reference model of the axis (greybox train): fit only where its residual stays "
                             "within its noise (default: every log is an air cut)")
    parser.add_argument("--spindle-load", metavar="COLUMN",
                        help="column of the logs with the spindle load: fit only where the spindle idles (below "
                             "its 5th percentile plus a fifth of its span to the 99th, 0.2 s apart from any cut)")
    parser.add_argument("--find-cuts", action="store_true",
                        help="production logs without a spindle-load column: fit only where the current follows a "
                             "friction model learned from each log's fastest moves (greybox.monitor.cutting)")
    parser.add_argument("--workers", type=NumberRange(int, low=1), metavar="N",
                        help="fingerprint the logs on a local Dask cluster of N processes (greybox.fleet); default "
                             "one after the other in this process")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="fingerprint the logs on the Dask cluster of this scheduler (tcp://host:8786)")
    parser.add_argument("--baseline-days", type=NumberRange(int, low=3), default=28, metavar="N",
                        help="first days with a fingerprint that set each feature's baseline (default %(default)s)")
    parser.add_argument("--force", action="store_true", help="replace the dashboard of an earlier run in --out")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..fleet.monitor import monitor_fleet
    from ..monitor.report import baseline_note
    from ..monitor.workflow import run_monitor

    options = dict(machine=args.machine, axis=args.axis, model_path=args.model, spindle_column=args.spindle_load,
                   find_cuts=args.find_cuts, baseline_days=args.baseline_days, progress=print, force=args.force)
    if args.scheduler is not None or args.workers is not None:  # the logs fingerprinted on a Dask cluster
        result = monitor_fleet(args.logs, args.history, args.out, **options, scheduler=args.scheduler,
                               workers=args.workers)
    else:
        result = run_monitor(args.logs, args.history, args.out, **options)
    trends = result.detector.trends_
    copies = f", {len(result.duplicates)} copies of logs filed under another day (not filed)" \
        if result.duplicates else ""
    print(f"{result.fitted} logs fingerprinted, {result.known} already in the history{copies}; "
          f"{len(trends)} axes, {len(result.detector.alarms_)} alarms")
    for copy in result.duplicates:
        print(f"note: {copy}")
    for trend in trends:
        if len(trend.dates) <= result.detector.baseline_days:
            print(f"note: {trend.machine}/{trend.axis}: {baseline_note(trend, result.detector)}")
    for alarm in result.detector.alarms_:
        print(f"alarm: {alarm.describe()}")
    print(f"dashboard -> {result.page}")
    return 0
