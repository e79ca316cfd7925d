"""``greybox live``: the process current and force of a live stream (MQTT, OPC UA or stdin), as it comes."""

from __future__ import annotations

import argparse
import sys

from ._types import FRACTION, GAP_STEPS, POSITIVE, POSITIVE_INT, NumberRange, non_negative, positive

#: The QoS levels taken.
QOS = NumberRange(int, low=0, high=1, description="a QoS of 0 or 1")


def add_parser(subparsers) -> None:
    from ..live.broker import PASSWORD_ENV
    from ..live.lookahead import LATENCIES
    from ..live.messages import MAX_MESSAGE_BYTES, MAX_MESSAGE_DEPTH
    from ..live.opcua import OPCUA_PASSWORD_ENV, SECURITY_MODES, SECURITY_POLICIES
    from ..live.report import LINE_INTERVAL_S, LINES_PER_INTERVAL
    from ..live.sources import DEFAULT_IDLE_S
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
    parser.add_argument("--config", metavar="TOML",
                        help="read options from this file: keys are the option names (record_s = 60, limit = "
                        "['force_process_N=1500'], tls_ca = 'ca.pem', ...); the command line overrides them")
    parser.add_argument("--source", metavar="SOURCE",
                        help="'-' (JSON or CSV lines on stdin), mqtt[s]://[USER@]HOST[:PORT]/TOPIC (wildcards + "
                        "and #; mqtts for TLS) or opc.tcp://[USER@]HOST[:PORT] (an OPC UA server's variables, named "
                        "by --node); required, here or in --config")
    parser.add_argument("--sink", default="-", metavar="SINK",
                        help="'-' (JSON lines on stdout, the default) or mqtt[s]://[USER@]HOST[:PORT]/TOPIC (alarms "
                        "retained on TOPIC/alarm/COLUMN, the status on TOPIC/status)")
    parser.add_argument("--username", metavar="USER", help="broker user name (or USER@ in the address)")
    parser.add_argument("--password-file", metavar="FILE",
                        help=f"file whose first line is the broker password (default: the environment variable "
                        f"{PASSWORD_ENV}); never on the command line")
    parser.add_argument("--tls-ca", metavar="PEM", help="CA certificate of the broker's certificate (mqtts://; "
                        "default the system's CAs)")
    parser.add_argument("--tls-cert", metavar="PEM", help="client certificate, for brokers that require one")
    parser.add_argument("--tls-key", metavar="PEM", help="key of the client certificate")
    parser.add_argument("--client-id", metavar="ID",
                        help="MQTT client id (the connections are ID-in and ID-out); default unique per host and "
                        "process; give a fixed one per instance so that a restarted service takes up its session")
    parser.add_argument("--qos", type=QOS, default=1, metavar="N",
                        help="QoS of the subscription, the estimates and the alarms: 1 (default, none lost while the "
                        "broker is away) or 0")
    parser.add_argument("--session-expiry", type=POSITIVE_INT, default=3600, metavar="S",
                        help="seconds the broker keeps the session (and the messages for it) after a loss "
                        "(default 3600)")
    parser.add_argument("--queue-size", type=POSITIVE_INT, default=100_000, metavar="N",
                        help="most output messages held while the broker is away (default 100000); beyond, counted "
                        "as lost")
    parser.add_argument("--status-topic", metavar="TOPIC",
                        help="retained status (online/offline, the counters every 10 s) on this topic; default "
                        "SINK_TOPIC/status with an MQTT sink")
    parser.add_argument("--node", action="append", default=[], metavar="COLUMN=NODEID",
                        help="with an opc.tcp:// source: the variable giving a column, e.g. "
                        "'position_mm=ns=2;s=Axis.X.Position' (repeatable: time, position, velocity, current, ...; "
                        "X_position_mm, ... for the axes of a machine model)")
    parser.add_argument("--opcua-password-file", metavar="FILE",
                        help=f"file whose first line is the OPC UA user's password (the user in the address, "
                        f"opc.tcp://USER@HOST; default: the environment variable {OPCUA_PASSWORD_ENV})")
    parser.add_argument("--opcua-security", metavar="POLICY,MODE",
                        help=f"OPC UA message security, POLICY one of {', '.join(SECURITY_POLICIES)}, MODE one of "
                        f"{', '.join(SECURITY_MODES)} (e.g. Basic256Sha256,SignAndEncrypt); with --opcua-cert and "
                        "--opcua-key")
    parser.add_argument("--opcua-cert", metavar="PEM", help="the client's application certificate (PEM or DER)")
    parser.add_argument("--opcua-key", metavar="PEM", help="the key of the client's certificate")
    parser.add_argument("--opcua-server-cert", metavar="PEM",
                        help="the server's certificate: accept that server only")
    parser.add_argument("--sampling-ms", type=non_negative("milliseconds"), default=0.0, metavar="MS",
                        help="OPC UA sampling interval of each variable (default 0: as fast as the server samples)")
    parser.add_argument("--publishing-ms", type=positive("milliseconds"), default=20.0, metavar="MS",
                        help="OPC UA publishing interval of the subscription (default 20)")
    parser.add_argument("--opcua-queue-size", type=POSITIVE_INT, default=1000, metavar="N",
                        help="values the server holds per variable between two publishes (default 1000)")
    parser.add_argument("--opcua-stamp-tolerance-ms", type=non_negative("milliseconds"), default=0.5, metavar="MS",
                        help="largest difference between the source time stamps of one sample's variables (default "
                        "0.5; 0: one stamp per sample); without a time_s variable a sample's time is the mean of its "
                        "variables' stamps")
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
    parser.add_argument("--envelope", metavar="ENVELOPE",
                        help="envelope file of 'greybox process teach' (taught with this model): each part of the "
                        "stream (starting after a rest) is checked against it while it is cut; a stretch outside "
                        "raises an alarm at once (docs/process.md)")
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
    parser.add_argument("--max-gap", type=GAP_STEPS, metavar="STEPS",
                        help="bridge glitches as 'greybox predict --resample S --max-gap STEPS' does: resample the "
                        "stream onto its nominal step (linear interpolation), leave out samples holding NaN, and "
                        "start a new run only at a step longer than STEPS nominal steps (default: no resampling; "
                        "--time-tolerance applies)")
    parser.add_argument("--latency", choices=LATENCIES, default="exact",
                        help="'exact' (default): the derivatives of 'greybox predict', each estimate after its "
                        "look-ahead (0.368 s at 2 ms); 'low': causal derivatives, each message's estimates at once, "
                        "the derived acceleration delayed by the causal filter (1.4 ms at 2 ms for a logged velocity, "
                        "2.4 ms for a position, whose derived velocity is led to no delay at low frequencies)")
    parser.add_argument("--cutoff-hz", type=POSITIVE, metavar="HZ",
                        help="cut-off [Hz] of the derivative filter (default as 'greybox predict'; with --latency "
                        "low 0.9 of the Nyquist frequency)")
    parser.add_argument("--chunk-s", type=positive("seconds"), default=DEFAULT_CHUNK_S, metavar="S",
                        help=f"chunk length in seconds (default {DEFAULT_CHUNK_S:g})")
    parser.add_argument("--max-message-bytes", type=POSITIVE_INT, default=MAX_MESSAGE_BYTES, metavar="N",
                        help=f"refuse a larger message in one line (default {MAX_MESSAGE_BYTES})")
    parser.add_argument("--max-depth", type=POSITIVE_INT, default=MAX_MESSAGE_DEPTH, metavar="N",
                        help=f"refuse JSON nested deeper (default {MAX_MESSAGE_DEPTH}; the message shapes need 2)")
    parser.add_argument("--lines-per-interval", type=POSITIVE_INT, default=LINES_PER_INTERVAL, metavar="N",
                        help=f"lines said per {LINE_INTERVAL_S:g} s about messages and samples (default "
                        f"{LINES_PER_INTERVAL}); the rest are counted in one summary line per {LINE_INTERVAL_S:g} s")
    parser.add_argument("--idle-s", type=POSITIVE, default=DEFAULT_IDLE_S, metavar="S",
                        help=f"after S seconds without a message, estimate the samples waiting for their look-ahead "
                        f"as the end of a run (default {DEFAULT_IDLE_S:g}; the next sample starts a new run)")
    parser.add_argument("--connect-timeout", type=positive("seconds"), default=10.0, metavar="S",
                        help="seconds to wait for the broker at the start (default 10)")
    for action in parser._actions:
        _record_given(action)
    parser.set_defaults(run=run, live_parser=parser)


def _record_given(action: argparse.Action) -> None:
    """Make ``action`` note its destination in ``namespace.given`` when the command line gives it."""
    base = type(action)

    class Given(base):
        def __call__(self, parser, namespace, values, option_string=None):
            namespace.given = getattr(namespace, "given", frozenset()) | {self.dest}
            super().__call__(parser, namespace, values, option_string)

    Given.__name__ = base.__name__
    action.__class__ = Given


def _configured(args: argparse.Namespace) -> argparse.Namespace:
    """``args`` with the options of ``--config`` that the command line does not give."""
    from ..errors import GreyboxError
    from ._live_config import read_config

    parser, given = args.live_parser, getattr(args, "given", frozenset())
    if args.config:
        actions = {action.dest: action for action in parser._actions if action.option_strings}
        for dest, value in read_config(args.config, actions).items():
            if dest not in given:
                setattr(args, dest, value)
    if not args.source:
        raise GreyboxError("--source is required (on the command line or in --config)")
    return args


def _say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    from ..data.io import parse_column_mapping
    from ..live.broker import BrokerOptions, read_password
    from ..live.limits import parse_duration, parse_limit
    from ..live.messages import MessageBounds
    from ..live.opcua import OPCUA_PASSWORD_ENV, OpcUaOptions, is_opcua_address, parse_nodes
    from ..live.run import run_live

    args = _configured(args)
    opcua = None
    if args.node or is_opcua_address(args.source):
        opcua = OpcUaOptions(
            nodes=parse_nodes(args.node), password=read_password(args.opcua_password_file, variable=OPCUA_PASSWORD_ENV,
                                                                 option="--opcua-password-file"),
            security=args.opcua_security, cert_file=args.opcua_cert, key_file=args.opcua_key,
            server_cert_file=args.opcua_server_cert, sampling_ms=args.sampling_ms, publishing_ms=args.publishing_ms,
            queue_size=args.opcua_queue_size, connect_timeout=args.connect_timeout,
            stamp_tolerance_ms=args.opcua_stamp_tolerance_ms)
    broker = BrokerOptions(username=args.username, password=read_password(args.password_file), ca_file=args.tls_ca,
                           cert_file=args.tls_cert, key_file=args.tls_key, client_id=args.client_id, qos=args.qos,
                           session_expiry_s=args.session_expiry, queue_size=args.queue_size,
                           connect_timeout=args.connect_timeout)
    outcome = run_live(
        args.model, source=args.source, sink=args.sink, axis_config_path=args.axis_config, machine_path=args.machine,
        record_dir=args.record, envelope_path=args.envelope,
        record_s=args.record_s, limits=[parse_limit(text) for text in args.limit],
        hold_s=parse_duration(args.limit_hold), exit_on_alarm=args.exit_on_alarm, stats_path=args.stats,
        sample_time=args.sample_time, tolerance=args.time_tolerance, cutoff_hz=args.cutoff_hz, chunk_s=args.chunk_s,
        max_gap=args.max_gap, latency=args.latency,
        columns=parse_column_mapping(args.columns) if args.columns else None, axis=args.axis,
        broker=broker, status_topic=args.status_topic, opcua=opcua,
        bounds=MessageBounds(max_bytes=args.max_message_bytes, max_depth=args.max_depth),
        lines_per_interval=args.lines_per_interval, idle_s=args.idle_s, say=_say)
    for path in outcome.recorded:
        _say(f"recorded {path}")
    return outcome.status
