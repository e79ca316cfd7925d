"""``greybox live``: the process current and force of a live stream (MQTT or stdin), as it comes."""

from __future__ import annotations

import argparse
import sys

from ._types import FRACTION, POSITIVE, POSITIVE_INT, positive


def add_parser(subparsers) -> None:
    from ..live.messages import MAX_MESSAGE_BYTES, MAX_MESSAGE_DEPTH
    from ..live.report import LINE_INTERVAL_S, LINES_PER_INTERVAL
    from ..models.chunked import DEFAULT_CHUNK_S

    parser = subparsers.add_parser(
        "live",
        description="Run a model trained on air cuts over the samples of a live stream, message by message, "
        "carrying its state: per message the estimates it completes (the columns of 'greybox predict') go to the "
        "sink. Fed the samples of a log, the estimates equal 'greybox predict' on it. Messages: JSON (one sample "
        "or a batch) or CSV lines with the log column names (docs/live.md). Notes, alarms and the stats go to "
        "stderr, one line each.",
    )
    parser.add_argument("model", metavar="MODEL",
                        help="model file written by 'greybox train' (.gbm), or a machine model directory ('greybox "
                        "train --axes'): one estimate per axis, from one topic per axis (topics ending in the axis "
                        "name) or from messages of every axis's columns (X_position_mm, ...)")
    parser.add_argument("--source", required=True, metavar="SOURCE",
                        help="'-' (JSON or CSV lines on stdin) or mqtt://HOST[:PORT]/TOPIC")
    parser.add_argument("--sink", default="-", metavar="SINK",
                        help="'-' (JSON lines on stdout, the default) or mqtt://HOST[:PORT]/TOPIC (alarms on "
                        "TOPIC/alarm)")
    parser.add_argument("--axis-config", metavar="TOML",
                        help="axis metadata: adds force_process_N (torque_process_Nm), channel names")
    parser.add_argument("--machine", metavar="TOML",
                        help="with a machine model: the machine file with each axis's channels and mechanics (adds "
                        "each axis's force or torque)")
    parser.add_argument("--record", metavar="DIR",
                        help="also write the estimates to rolling Parquet files in DIR (the table of 'greybox "
                        "predict'), one per --record-s seconds of log time and per run, each written atomically")
    parser.add_argument("--record-s", type=positive("seconds"), default=60.0, metavar="S",
                        help="log seconds per recording file (default 60)")
    parser.add_argument("--limit", action="append", default=[], metavar="COLUMN=VALUE",
                        help="alarm when |COLUMN| of the output exceeds VALUE for --limit-hold, e.g. "
                        "force_process_N=1500 (repeatable)")
    parser.add_argument("--limit-hold", default="0", metavar="DURATION",
                        help="how long a limit must be exceeded before the alarm, e.g. 20ms (default 0)")
    parser.add_argument("--exit-on-alarm", action="store_true",
                        help="stop at the first alarm, exit status 3")
    parser.add_argument("--stats", metavar="JSON",
                        help="write the counters (received, estimated, dropped, lost, gaps, disconnections, "
                        "alarms) to this file every 10 s and at the end")
    parser.add_argument("--columns", metavar="MAP",
                        help="column mapping for other message names, e.g. 'position_mm=X1_pos,current_A=X1_cur'")
    parser.add_argument("--axis", metavar="NAME",
                        help="the axis to take from messages of several axes (columns NAME_position_mm, ...)")
    parser.add_argument("--sample-time", type=positive("seconds"), metavar="S",
                        help="nominal step [s] (default: the median step of the first 16 samples)")
    parser.add_argument("--time-tolerance", type=FRACTION, default=0.25, metavar="FRAC",
                        help="allowed deviation of a step from the nominal step (default 0.25): a longer step is a "
                        "gap (a new run, the state re-initialised), a shorter one drops the sample")
    parser.add_argument("--cutoff-hz", type=POSITIVE, metavar="HZ",
                        help="cut-off [Hz] of the derivative filter (default as 'greybox predict')")
    parser.add_argument("--chunk-s", type=positive("seconds"), default=DEFAULT_CHUNK_S, metavar="S",
                        help=f"chunk length in seconds (default {DEFAULT_CHUNK_S:g})")
    parser.add_argument("--max-message-bytes", type=POSITIVE_INT, default=MAX_MESSAGE_BYTES, metavar="N",
                        help=f"refuse a larger message in one line (default {MAX_MESSAGE_BYTES})")
    parser.add_argument("--max-depth", type=POSITIVE_INT, default=MAX_MESSAGE_DEPTH, metavar="N",
                        help=f"refuse JSON nested deeper (default {MAX_MESSAGE_DEPTH}; the message shapes need 2)")
    parser.add_argument("--lines-per-interval", type=POSITIVE_INT, default=LINES_PER_INTERVAL, metavar="N",
                        help=f"lines said per {LINE_INTERVAL_S:g} s about messages and samples (default "
                        f"{LINES_PER_INTERVAL}); the rest are counted in one summary line per {LINE_INTERVAL_S:g} s")
    parser.add_argument("--connect-timeout", type=positive("seconds"), default=10.0, metavar="S",
                        help="seconds to wait for the broker at the start (default 10)")
    parser.set_defaults(run=run)


def _say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    from ..data.io import parse_column_mapping
    from ..live.limits import parse_duration, parse_limit
    from ..live.messages import MessageBounds
    from ..live.run import run_live

    outcome = run_live(
        args.model, source=args.source, sink=args.sink, axis_config_path=args.axis_config, machine_path=args.machine,
        record_dir=args.record,
        record_s=args.record_s, limits=[parse_limit(text) for text in args.limit],
        hold_s=parse_duration(args.limit_hold), exit_on_alarm=args.exit_on_alarm, stats_path=args.stats,
        sample_time=args.sample_time, tolerance=args.time_tolerance, cutoff_hz=args.cutoff_hz, chunk_s=args.chunk_s,
        columns=parse_column_mapping(args.columns) if args.columns else None, axis=args.axis,
        connect_timeout=args.connect_timeout,
        bounds=MessageBounds(max_bytes=args.max_message_bytes, max_depth=args.max_depth),
        lines_per_interval=args.lines_per_interval, say=_say)
    for path in outcome.recorded:
        _say(f"recorded {path}")
    return outcome.status
