"""``greybox plan``: write the air-cut NC program that records the paper's datasets A and B on a machine."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from ..atomic import check_output_path, write_text_atomic
from ..errors import GreyboxError
from ._types import FINITE, NON_NEGATIVE_INT, POSITIVE, SEED, NumberList, NumberSpan, positive


def add_parser(subparsers) -> None:
    from ..nc.gcode import DIALECTS
    from ..nc.plan import AirCutPlan

    defaults = AirCutPlan("X", (0.0, 1.0), (0.0, 1.0), (1.0, 2.0))
    parser = subparsers.add_parser(
        "plan",
        description="Write an NC program (ISO G-code: G90, G1 with F per minute, G4 dwells) for one axis: a "
        "warm-up, dataset A (random feed steps with reversals and sinusoidal motion as short linear moves "
        "inside the window) and dataset B (constant-feed sweeps over the travel). Record the axis while it "
        "runs, train on the log; 'greybox synth --plan PROGRAM' runs it on the twin first. Positions in mm "
        "(axes X, Y, Z) or deg (A, B, C), feeds per minute.",
    )
    # "--travel -510:0": a span that starts with a minus is a value, not an option (argparse takes only
    # negative numbers for values); the pattern extends argparse's own to LOW:HIGH
    parser._negative_number_matcher = re.compile(r"^-\d+$|^-\d*\.\d+$|^-\d*\.?\d*:")
    parser.add_argument("--axis", required=True, choices=["X", "Y", "Z", "A", "B", "C"], help="NC axis letter")
    parser.add_argument("--travel", required=True, type=NumberSpan(FINITE), metavar="LOW:HIGH",
                        help="travel swept by dataset B, e.g. -510:0 (mm, or deg)")
    parser.add_argument("--window", required=True, type=NumberSpan(FINITE), metavar="LOW:HIGH",
                        help="measurement window of dataset A inside the travel, e.g. -275:-225")
    parser.add_argument("--feed", required=True, type=NumberSpan(POSITIVE), metavar="LOW:HIGH",
                        help="feeds of dataset A per minute, e.g. 100:2000")
    parser.add_argument("--sweep-feeds", type=NumberList(POSITIVE), default=defaults.sweep_feeds, metavar="F,F,...",
                        help="feeds of the sweeps of dataset B per minute (default 600,1800, the paper's)")
    parser.add_argument("--duration-a", type=positive("seconds"), default=defaults.duration_a_s, metavar="S",
                        help=f"approximate length of dataset A in s (default {defaults.duration_a_s:g})")
    parser.add_argument("--warmup", type=NON_NEGATIVE_INT, default=defaults.warmup_strokes, metavar="N",
                        help=f"warm-up strokes over the travel (default {defaults.warmup_strokes}; 0: none)")
    parser.add_argument("--warmup-feed", type=positive("feed per minute"), default=defaults.warmup_feed,
                        metavar="F", help=f"feed of the warm-up (default {defaults.warmup_feed:g})")
    parser.add_argument("--max-feed", type=positive("feed per minute"), default=defaults.max_feed, metavar="F",
                        help=f"highest feed the axis may be programmed (default {defaults.max_feed:g})")
    parser.add_argument("--max-acceleration", type=positive("acceleration"), default=defaults.max_acceleration,
                        metavar="A", help="acceleration the axis reaches per s^2, for the checks and the sines "
                        f"(default {defaults.max_acceleration:g})")
    parser.add_argument("--seed", type=SEED, default=0, metavar="N", help="seed of the random moves (default 0)")
    parser.add_argument("--dialect", choices=DIALECTS, default="sinumerik",
                        help="sinumerik: dwell G4 F<s>, comments after ';' (default); fanuc: G04 X<s>, (comments)")
    parser.add_argument("--out", required=True, metavar="PROGRAM", help="program file to write, e.g. aircuts.mpf")
    parser.add_argument("--force", action="store_true", help="overwrite PROGRAM if it exists")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from .. import __version__
    from ..nc.gcode import write_program
    from ..nc.plan import AirCutPlan, plan_air_cuts

    out = Path(args.out)
    check_output_path(out, overwrite=args.force)
    plan = AirCutPlan(args.axis, args.travel, args.window, args.feed, sweep_feeds=args.sweep_feeds,
                      duration_a_s=args.duration_a, warmup_strokes=args.warmup, warmup_feed=args.warmup_feed,
                      max_feed=args.max_feed, max_acceleration=args.max_acceleration)
    program = plan_air_cuts(plan, seed=args.seed)
    unit = plan.unit
    header = [f"greybox {__version__} air-cut plan (greybox plan), seed {args.seed}",
              f"axis {plan.axis}: travel {plan.travel[0]:g}..{plan.travel[1]:g} {unit}, window "
              f"{plan.window[0]:g}..{plan.window[1]:g} {unit}, feeds {plan.feed[0]:g}-{plan.feed[1]:g} {unit}/min",
              "record position, velocity and motor current of the axis while it runs (e.g. 2 ms trace)"]
    if not out.parent.is_dir():
        raise GreyboxError(f"{out}: directory {out.parent} does not exist")
    write_text_atomic(out, write_program(program, dialect=args.dialect, header=header))
    moves = len(program.positions)
    print(f"wrote {out}: {moves} moves and {len(program.blocks) - moves} dwells, axis {plan.axis}, sections: "
          + "; ".join(title.split(":")[0] for _, title in program.sections))
    return 0
