"""``greybox process``: teach an envelope of the cutting force from good parts, check parts against it."""

from __future__ import annotations

import argparse

from ..errors import GreyboxError
from ._types import NON_NEGATIVE, NON_NEGATIVE_INT, NumberRange, positive

#: A false-alarm rate per part.
RATE = NumberRange(float, low=0, high=0.5, low_open=True, high_open=True, description="a rate in (0, 0.5)")
#: A share in (0, 1).
SHARE = NumberRange(float, low=0, high=1, low_open=True, high_open=True, description="a fraction in (0, 1)")


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "process",
        description=(
            "Watch the cut over repeated parts (docs/process.md). 'teach' learns, from good parts, the process "
            "force of a model trained on air cuts (its process current without an axis file; the raw current "
            "with --raw) along the part, aligned by the parts' velocity, with a band set for a false-alarm rate "
            "per part; 'check' flags the parts and stretches that leave it, names the kind (rise, drop, missing "
            "cut, extra cut) and writes a report. A log is one part or a series: split by its 'part' column, "
            "else at rests of at least --min-rest seconds."
        ),
    )
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    teach = actions.add_parser("teach", help="learn an envelope from good parts",
                               description="Learn an envelope from good parts and write it (JSON).")
    teach.add_argument("inputs", nargs="+", metavar="MODEL PART_LOG",
                       help="the model file (greybox train), then the logs of good parts; with --raw only logs")
    teach.add_argument("--out", required=True, metavar="ENVELOPE", help="envelope file to write (.json)")
    teach.add_argument("--raw", action="store_true",
                       help="watch the raw measured current (no model), as the field's process monitors do")
    teach.add_argument("--axis-config", metavar="TOML", help="axis file: watch the process force [N] (torque)")
    teach.add_argument("--false-alarm-rate", type=RATE, default=1e-3, metavar="P",
                       help="false alarms per good part the limits are set for (default %(default)s)")
    teach.add_argument("--smoothing", type=positive("seconds"), default=0.1, metavar="S",
                       help="moving-mean window [s] of the signal (default %(default)s)")
    teach.add_argument("--max-shift", type=NON_NEGATIVE, default=1.0, metavar="S",
                       help="largest timing difference [s] between parts (default %(default)s)")
    teach.add_argument("--relevel", action="store_true",
                       help="re-level each part on its air moves per direction before comparing (the friction "
                            "falls as the machine warms up)")
    teach.add_argument("--cut-share", type=SHARE, default=0.2, metavar="F",
                       help="cut samples: where the taught load exceeds this share of its largest (default "
                            "%(default)s)")
    teach.add_argument("--min-rest", type=positive("seconds"), default=2.0, metavar="S",
                       help="shortest rest [s] between two parts of a log without part column (default "
                            "%(default)s)")
    teach.add_argument("--force", action="store_true", help="replace an existing envelope file")
    teach.set_defaults(run=run_teach)
    check = actions.add_parser("check", help="check parts against an envelope",
                               description="Check every part of the logs against an envelope; write the report "
                                           "(parts.csv, stretches.csv, report.json, figures) into a directory.")
    check.add_argument("envelope", metavar="ENVELOPE", help="envelope file (greybox process teach)")
    check.add_argument("logs", nargs="+", metavar="LOG", help="logs of parts: one part each, or series")
    check.add_argument("--out", required=True, metavar="DIR", help="report directory")
    check.add_argument("--model", metavar="FILE", help="the envelope's model file, if it moved")
    check.add_argument("--axis-config", metavar="TOML", help="the envelope's axis file, if it moved")
    check.add_argument("--figures", type=NON_NEGATIVE_INT, default=3, metavar="N",
                       help="figures of the worst flagged parts (default %(default)s)")
    check.add_argument("--force", action="store_true", help="write into a report directory that holds files")
    check.set_defaults(run=run_check)


def run_teach(args: argparse.Namespace) -> int:
    from ..process.run import teach_logs

    model, logs = (None, args.inputs) if args.raw else (args.inputs[0], args.inputs[1:])
    if not logs:
        raise GreyboxError("give the model file and at least one log of good parts (or --raw and logs)")
    if args.raw and args.axis_config:
        raise GreyboxError("--axis-config converts a model's process current; --raw watches the measured current")
    envelope = teach_logs(logs, args.out, model=model, axis_config=args.axis_config, min_rest_s=args.min_rest,
                          force=args.force, progress=print, false_alarm_rate=args.false_alarm_rate,
                          smoothing_s=args.smoothing, max_shift_s=args.max_shift, relevel=args.relevel,
                          cut_share=args.cut_share)
    print(f"envelope of the {envelope.signal_['kind']} signal [{envelope.unit_}] from {envelope.n_parts_} parts, "
          f"{envelope.centre_.size * envelope.sample_time_:.1f} s each; band +-{envelope.band_factor_:.2f} spreads, "
          f"mean cut load {envelope.cut_load_:.4g} {envelope.unit_} +-{envelope.deviation_limit_:.3g} -> {args.out}")
    return 0


def run_check(args: argparse.Namespace) -> int:
    from ..process.run import check_logs

    done = check_logs(args.envelope, args.logs, args.out, model=args.model, axis_config=args.axis_config,
                      figures=args.figures, force=args.force, progress=print)
    flagged = [c for c in done.checks if c.flagged]
    for check in flagged:
        print(f"flagged: part {check.number} of {check.source}: {', '.join(check.kinds)}"
              + "".join(f"; {s.kind} {s.start_s:.2f}-{s.end_s:.2f} s" for s in check.stretches[:3]))
    print(f"{len(done.checks)} parts checked ({done.log_s:.0f} s of log in {done.elapsed_s:.1f} s), "
          f"{len(flagged)} flagged -> {args.out}")
    return 0
