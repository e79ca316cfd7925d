"""Time ``greybox live``: compute per sample, CPU share of 16 axes, latency through a local Mosquitto broker.

All figures come from one run and are printed with the core count and the load of the machine:

1. compute: a GMS+SVR model's live session (decode the JSON message, estimate, encode the output)
   over ``--seconds`` of a shipped log in messages of ``--batch`` samples, on one core (affinity set,
   one BLAS and numba thread); the time of each message divided by its samples, percentiles over the
   messages after the look-ahead has filled: wall-clock time (what a sample waits, including the time
   the core spends on other processes) and the thread's CPU time (the work itself). The figures are those
   of the first pass; with ``--repeats R`` (default 5) the run is made R times and the percentiles of
   each message's least CPU time over the passes are printed too: on a core shared with other jobs the
   CPU time of a message also holds what their interference costs (caches refilled, interrupts), which
   differs from pass to pass, while the code's own cost of a message is the same in every pass;
2. CPU share of ``--axes`` axes at 500 Hz: as many sessions in one process, each fed the log; the
   process CPU time divided by the stream's duration (the share of one core they need to keep up); only
   the sessions run meanwhile (no publisher, no MQTT thread). The first pass's share, every pass's, and
   their median over the ``--repeats R`` passes (the target's figure: one pass on a shared machine holds a
   varying share of other jobs' interference, the median is not moved by one pass); also each message's
   least CPU time over the R passes, summed (the code's own cost, as in 1.);
3. end to end: a Mosquitto broker on a free loopback port, ``greybox live`` reading and writing it, the
   log published at real time in batches of ``--batch`` (500 Hz, 50 messages/s); per message, the time
   from its publication to the arrival of the output message it completes (percentiles, and the count of
   messages over 5 ms). The benchmark's publisher writes each message to its socket in the thread that
   stamps it (no network thread of the benchmark's own to wake). Also the CPU time of the ``greybox live``
   process over the stream (all its threads: the estimates and paho's network threads) as a share of one
   core. Each estimate also waits for the look-ahead of the derivatives (printed), on top of that time.

    python benchmarks/bench_live.py --model x.gbm --seconds 20

4. with ``--record-minutes M``: a synthetic cutting log of M minutes streamed through a session that
   records it (rolling Parquet files of 60 s), against ``greybox predict`` on the same log: the largest
   difference of the model current, and the resident memory after 10 % and at the end of the stream
   (its growth over the last 90 % of the stream: flat memory is a growth near 0).

The broker runs with ``set_tcp_nodelay true`` and the benchmark's publisher sets ``TCP_NODELAY``, as
``greybox live`` does on its own connections. The compute and CPU-share runs hold the objects of their
start-up out of the garbage collector's passes as ``greybox live`` does while its stream runs
(:func:`greybox.live.run.settled_memory`); ``greybox live`` of the end-to-end run also loads its compiled
kernels before it reads the first message (the compute runs warm up on the log's first 100 messages).

Without ``--model`` a GMS+SVR model is fitted on data/X_A.mcap and data/X_B.mcap with fixed
hyperparameters (as benchmarks/bench_gmssvr_predict.py does).

With ``--low-latency`` it measures the low-latency mode (``greybox live --latency low``, issue 42) instead:

5. the cut force: the twin's cutting logs (``greybox.twin.make_dataset`` of X, datasets C and D, seed 2024,
   ``cutting=True``; not the seeds 7 and 11 the causal filter's setting was chosen on) and the independent
   split's ``cut_D.csv``, each streamed through ``greybox live`` in both modes (JSON messages of ``--batch``
   samples; velocity logged and acceleration derived, then position only, both derived); the mean process
   force over the samples where the true cutting force is not zero, per mode, and their relative difference;
   the models are GMS+SVR with the fixed hyperparameters above, fitted on the air cuts of the same source
   (data/X_A, X_B; aircut_A, B, C with the split's ``axis.toml``);
6. end to end as 3., with ``--latency low`` and ``--limit current_process_A=LIMIT`` (``--alarm-limit``): per
   message the time from its publication to its estimate, and per alarm message (raised or cleared) the time
   from the publication of the message that raised or cleared it to the alarm's arrival.

    nice -n 10 python benchmarks/bench_live.py --low-latency
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # one core: before numba is imported

import argparse  # noqa: E402
import contextlib  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import shutil  # noqa: E402
import socket  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data"


INDEPENDENT = ROOT.parent / "shared" / "data" / "independent" / "axis_dev"


def _model(path: str | None, folder: Path, train=(DATA / "X_A.mcap", DATA / "X_B.mcap"), name="bench") -> Path:
    if path:
        return Path(path)
    from greybox.data.io import read_log
    from greybox.data.prepare import prepare
    from greybox.models.files import save_model
    from greybox.models.friction.gms import GMSModel
    from greybox.models.gmssvr import GMSSVRModel

    runs = prepare([read_log(log) for log in train])
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=100), optimize=False, C=0.5, epsilon=0.02, gamma=3.0,
                        n_subset=2000).fit(runs)
    out = folder / f"{name}.gbm"
    save_model(model, out)
    return out


def _messages(log, batch: int) -> list[str]:
    columns = {"time_s": log.time, "position_mm": log.position, "velocity_mm_s": log.velocity,
               "current_A": log.effort}
    if log.velocity is None:  # position only: the velocity derived too
        del columns["velocity_mm_s"]
    return [json.dumps({name: values[k:k + batch].tolist() for name, values in columns.items()} | {"seq": seq})
            for seq, k in enumerate(range(0, len(log), batch))]


class _Null(io.TextIOBase):
    def write(self, text):
        return len(text)


def _session(model_path, step_s: float):
    from greybox.live.estimator import LiveEstimator
    from greybox.live.session import LiveSession
    from greybox.live.sinks import LineSink
    from greybox.models.files import load_model

    estimator = LiveEstimator(load_model(model_path), sample_time=step_s)
    return LiveSession(estimator, LineSink(_Null()), say=lambda line: None)


def _compute_pass(model_path, messages, step_s: float) -> tuple[list, list]:
    from greybox.live.sources import Received

    session = _session(model_path, step_s)
    times, cpu = [], []
    for k, message in enumerate(messages):
        item = Received(message, f"message {k}", 0.0)
        started, started_cpu = time.perf_counter(), time.thread_time()
        session.handle(item)
        times.append(time.perf_counter() - started)
        cpu.append(time.thread_time() - started_cpu)
    return times, cpu


def compute(model_path, messages, batch: int, lookahead: int, step_s: float, repeats: int = 1) -> dict:
    skip = lookahead // batch + 2
    passes = [_compute_pass(model_path, messages, step_s) for _ in range(repeats)]
    times, cpu = passes[0]
    per_sample = np.array(times[skip:]) / batch * 1e6
    cpu_per_sample = np.array(cpu[skip:]) / batch * 1e6
    figures = {"messages": len(per_sample), "batch": batch,
               "p50_us_per_sample": float(np.percentile(per_sample, 50)),
               "p99_us_per_sample": float(np.percentile(per_sample, 99)), "max_us_per_sample": float(per_sample.max()),
               "cpu_p50_us_per_sample": float(np.percentile(cpu_per_sample, 50)),
               "cpu_p99_us_per_sample": float(np.percentile(cpu_per_sample, 99)),
               "cpu_max_us_per_sample": float(cpu_per_sample.max())}
    if repeats > 1:  # each message's least CPU time over the passes: the code's own cost, other jobs' share left out
        least = np.min([np.array(cpu[skip:]) for _, cpu in passes], axis=0) / batch * 1e6
        figures.update({"repeats": repeats, "least_cpu_p50_us_per_sample": float(np.percentile(least, 50)),
                        "least_cpu_p99_us_per_sample": float(np.percentile(least, 99)),
                        "least_cpu_max_us_per_sample": float(least.max())})
    return figures


def _share_pass(model_path, messages, axes: int, step_s: float) -> np.ndarray:
    """The process CPU time [s] of each message handled by ``axes`` fresh sessions, one after another."""
    from greybox.live.sources import Received

    sessions = [_session(model_path, step_s) for _ in range(axes)]
    used = np.empty(len(messages))
    for k, message in enumerate(messages):
        started = time.process_time()
        for session in sessions:
            session.handle(Received(message, f"message {k}", 0.0))
        used[k] = time.process_time() - started
    return used


def cpu_share(model_path, messages, axes: int, duration_s: float, step_s: float, repeats: int = 1) -> dict:
    """CPU of ``axes`` sessions fed the stream, as a share of one core: each pass's process CPU time over the
    stream's duration, the first pass's and the median over the passes (the target's figure: on a shared
    machine one pass's CPU time also holds what other jobs cost it, more in one pass than in the next, and the
    median of the passes is not moved by one unlucky or lucky pass); with ``repeats`` > 1 also the sum of each
    message's least CPU time over the passes (the code's own cost, other jobs' interference left out, as for the
    compute run).

    Only the sessions run in the process meanwhile (the end-to-end run's publisher comes later): the figure
    holds every session's decoding of its message, the estimates and the output messages' text, not the
    MQTT network threads (the end-to-end run prints the ``greybox live`` process's whole CPU time)."""
    passes = [_share_pass(model_path, messages, axes, step_s) for _ in range(repeats)]
    used = float(passes[0].sum())
    shares = [float(pass_cpu.sum()) / duration_s for pass_cpu in passes]
    figures = {"axes": axes, "stream_s": duration_s, "cpu_s": used, "share_of_one_core": used / duration_s,
               "pass_shares_of_one_core": shares, "median_share_of_one_core": float(np.median(shares))}
    if repeats > 1:
        least = float(np.min(passes, axis=0).sum())
        figures.update({"repeats": repeats, "least_cpu_s": least, "least_share_of_one_core": least / duration_s})
    return figures


def _resident_mb() -> float:
    with open("/proc/self/statm") as stream:
        return int(stream.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def recording(model_path, minutes: float, batch: int, folder: Path) -> dict:
    import pandas as pd

    from greybox.cli import main as greybox_main
    from greybox.data.io import write_log
    from greybox.live.estimator import LiveEstimator
    from greybox.live.recording import Recorder
    from greybox.live.session import LiveSession
    from greybox.live.sinks import LineSink
    from greybox.live.sources import Received
    from greybox.models.files import load_model
    from greybox.twin import make_dataset

    log = make_dataset("X", "C", 7, duration_s=60.0 * minutes, cutting=True).replace(extras={})
    log_path, table = folder / "long.parquet", folder / "long-predict.parquet"
    write_log(log, log_path)
    with contextlib.redirect_stdout(io.StringIO()):  # the benchmark prints its JSON line only
        assert greybox_main(["predict", str(model_path), str(log_path), "--out", str(table), "--quiet"]) == 0
    model = load_model(model_path)
    recorder = Recorder(folder / "rec", model=model, chunk_s=60.0, every_s=60.0)
    session = LiveSession(LiveEstimator(model, sample_time=log.sample_time), LineSink(_Null()),
                          say=lambda line: None, recorder=recorder)
    columns = {"time_s": log.time, "position_mm": log.position, "velocity_mm_s": log.velocity, "current_A": log.effort}
    starts = range(0, len(log), batch)
    memory = {}
    started = time.perf_counter()
    for seq, k in enumerate(starts):
        message = json.dumps({name: values[k:k + batch].tolist() for name, values in columns.items()})
        session.handle(Received(message, f"message {seq}", 0.0))
        if seq == len(starts) // 10:
            memory["resident_mb_at_10_percent"] = _resident_mb()
    session.finish()
    session.close()
    elapsed = time.perf_counter() - started
    memory["resident_mb_at_end"] = _resident_mb()
    memory["resident_growth_mb_10_to_100_percent"] = memory["resident_mb_at_end"] - memory["resident_mb_at_10_percent"]
    expected = pd.read_parquet(table, columns=["current_model_A"])["current_model_A"].to_numpy()
    largest, offset = 0.0, 0
    for path in recorder.written:
        part = pd.read_parquet(path, columns=["current_model_A"])["current_model_A"].to_numpy()
        largest = max(largest, float(abs(part - expected[offset:offset + part.size]).max()))
        offset += part.size
    return {"minutes": minutes, "samples": len(log), "recorded": offset, "files": len(recorder.written),
            "largest_difference_A": largest, "stream_wall_s": elapsed, **memory}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _publisher(port: int):
    """A client of the broker that writes each message to its socket in the calling thread.

    Without a network thread of its own (no ``loop_start``), paho writes a QoS 0 message at once in
    ``publish``: the time stamped just before it is the time the message goes out, not that time plus the
    wake-up of a network thread of the benchmark's own (which the end-to-end figure would count).
    """
    import paho.mqtt.client as mqtt

    publisher = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2)
    publisher.on_socket_open = lambda c, u, sock: sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    publisher.connect("127.0.0.1", port, keepalive=600)
    deadline = time.monotonic() + 10
    while not publisher.is_connected():
        publisher.loop(0.05)
        if time.monotonic() > deadline:
            raise RuntimeError("the benchmark's publisher did not connect")
    return publisher


def _process_cpu_s(pid: int) -> float:
    """User and system CPU time of process ``pid``, all its threads [s] (Linux ``/proc``)."""
    with open(f"/proc/{pid}/stat") as stream:
        fields = stream.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def end_to_end(model_path, messages, folder: Path, batch: int, step_s: float, latency: str = "exact",
               alarm_limit: float | None = None) -> dict:
    import paho.mqtt.client as mqtt

    binary = shutil.which("mosquitto", path=os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin"]))
    if binary is None:
        return {"skipped": "the mosquitto broker is not installed (Debian package 'mosquitto')"}
    port = _free_port()
    config = folder / "mosquitto.conf"
    # set_tcp_nodelay: the broker sends each message at once (Nagle's algorithm would hold a small message
    # back until the previous one is acknowledged); greybox's own clients set TCP_NODELAY themselves
    config.write_text(f"listener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\n")
    broker = subprocess.Popen([binary, "-c", str(config)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    live = None
    try:
        deadline = time.monotonic() + 10
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise RuntimeError("mosquitto did not start") from None
                time.sleep(0.05)
        arrived: dict = {}
        alarms: list = []  # (seq of the message that raised or cleared it, arrival)
        ready = threading.Event()
        client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2)
        client.on_connect = lambda c, u, f, r, p=None: c.subscribe("process/X/#" if alarm_limit else "process/X")
        client.on_subscribe = lambda *args: ready.set()

        def on_message(c, u, message):
            now = time.perf_counter()
            payload = json.loads(message.payload)
            if message.topic.startswith("process/X/alarm/"):
                if payload.get("seq") is not None and not message.retain:
                    alarms.append((payload["seq"], now))
            elif message.topic == "process/X" and payload.get("seq") is not None:
                arrived[payload["seq"]] = now  # not the tail estimated once the stream went idle

        client.on_message = on_message
        client.on_socket_open = lambda c, u, sock: sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        client.connect("127.0.0.1", port)
        client.loop_start()
        ready.wait(10)
        live = subprocess.Popen([sys.executable, "-m", "greybox", "live", str(model_path), "--source",
                                 f"mqtt://127.0.0.1:{port}/axis/X", "--sink", f"mqtt://127.0.0.1:{port}/process/X",
                                 "--sample-time", str(step_s), "--latency", latency]
                                + (["--limit", f"current_process_A={alarm_limit}"] if alarm_limit else []),
                                stderr=subprocess.PIPE, text=True)
        live.stderr.readline()  # connected
        publisher = _publisher(port)
        published = {}
        cpu_start = _process_cpu_s(live.pid)
        start = time.perf_counter()
        for seq, message in enumerate(messages):
            due = start + (seq + 1) * batch * step_s
            while time.perf_counter() < due:
                time.sleep(min(0.001, max(0.0, due - time.perf_counter())))
            published[seq] = time.perf_counter()
            publisher.publish("axis/X", message)  # written to the socket here, by this thread
        streamed_s = time.perf_counter() - start
        time.sleep(1.0)
        live_cpu_s = _process_cpu_s(live.pid) - cpu_start
        publisher.disconnect()
        client.disconnect()
        client.loop_stop()
    finally:
        if live is not None:
            live.terminate()
            live.wait(30)
        broker.terminate()
        broker.wait(10)
    delays = np.array([arrived[seq] - published[seq] for seq in published if seq in arrived]) * 1e3
    figures = {"latency": latency, "messages": len(published), "answered": len(delays), "rate_hz": 1 / step_s,
               "batch": batch, "p50_ms": float(np.percentile(delays, 50)), "p99_ms": float(np.percentile(delays, 99)),
               "max_ms": float(delays.max()), "over_5_ms": int((delays > 5.0).sum()),
               "live_cpu_s": live_cpu_s, "live_cpu_share_of_one_core": live_cpu_s / streamed_s}
    if alarm_limit:
        to_alarm = np.array([now - published[seq] for seq, now in alarms if seq in published]) * 1e3
        figures.update({"alarm_limit_A": alarm_limit, "alarms": len(to_alarm)})
        if to_alarm.size:
            figures.update({"alarm_p50_ms": float(np.percentile(to_alarm, 50)),
                            "alarm_p99_ms": float(np.percentile(to_alarm, 99)), "alarm_max_ms": float(to_alarm.max())})
    return figures


def _live_force(model_path, log, axis_config, batch: int, latency: str) -> np.ndarray:
    """The process force ``greybox live`` gives for ``log`` streamed in messages of ``batch`` samples."""
    from greybox.live.run import run_live

    out = io.StringIO()
    run_live(model_path, source="-", axis_config_path=axis_config, sample_time=log.sample_time, latency=latency,
             stdin=io.StringIO("\n".join(_messages(log, batch))), stdout=out, say=lambda line: None)
    rows = [json.loads(line) for line in out.getvalue().splitlines() if line.strip()]
    time_s = np.concatenate([row["time_s"] for row in rows if "alarm" not in row])
    force = np.concatenate([row["force_process_N"] for row in rows if "alarm" not in row])
    if not np.array_equal(time_s, log.time[:time_s.size]) or time_s.size < len(log) - 1:
        raise RuntimeError(f"{log.source}: the {latency} mode estimated {time_s.size} of {len(log)} samples")
    return force  # a lone last sample of a message is left (the model steps over two samples at least)


def cut_force(model_path, log, truth_n: np.ndarray, axis_config, batch: int) -> dict:
    """Mean process force over the cutting samples, exact and low-latency mode, and their relative difference."""
    forces = {latency: _live_force(model_path, log, axis_config, batch, latency) for latency in ("exact", "low")}
    cutting = truth_n[:min(force.size for force in forces.values())] != 0.0
    means = {latency: float(force[:cutting.size][cutting].mean()) for latency, force in forces.items()}
    difference = forces["low"][:cutting.size] - forces["exact"][:cutting.size]
    return {"log": str(log.source), "velocity_logged": log.velocity is not None, "samples": len(log),
            "cutting_samples": int(cutting.sum()),
            "rms_difference_N": float(np.sqrt(np.mean(difference[cutting] ** 2))),
            "mean_cut_force_exact_N": means["exact"], "mean_cut_force_low_N": means["low"],
            "mean_cut_force_truth_N": float(truth_n[:cutting.size][cutting].mean()),
            "relative_difference": abs(means["low"] - means["exact"]) / abs(means["exact"])}


def low_latency_force(twin_model, folder: Path, batch: int) -> list[dict]:
    """:func:`cut_force` on the twin's cutting logs (``twin_model``) and on the independent split's cut."""
    import pandas as pd

    from greybox.data.io import read_log
    from greybox.twin import make_dataset

    figures = []
    for dataset in ("C", "D"):
        log = make_dataset("X", dataset, 2024, cutting=True)
        truth = log.extras["truth_process_force_N"]
        log = log.replace(extras={}, source=f"twin X {dataset} seed 2024, cutting")
        for given in (log, log.replace(velocity=None)):
            figures.append(cut_force(twin_model, given, truth, ROOT / "examples" / "axis_x.toml", batch))
    if INDEPENDENT.is_dir():
        model = _model(None, folder, [INDEPENDENT / f"aircut_{name}.csv" for name in "ABC"], "independent")
        log = read_log(INDEPENDENT / "cut_D.csv").replace(source="independent split, axis_dev/cut_D.csv")
        truth = pd.read_csv(INDEPENDENT / "cut_D_truth.csv")["F_cut_true_N"].to_numpy()
        for given in (log, log.replace(velocity=None)):
            figures.append(cut_force(model, given, truth, INDEPENDENT / "axis.toml", batch))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model file (default: a GMS+SVR fitted on data/X_A, X_B)")
    parser.add_argument("--log", default=str(DATA / "X_C.mcap"), help="log to stream (default data/X_C.mcap)")
    parser.add_argument("--seconds", type=float, default=20.0, help="seconds of the log to stream (default 20)")
    parser.add_argument("--batch", type=int, default=10, help="samples per message (default 10)")
    parser.add_argument("--axes", type=int, default=16, help="axes of the CPU-share run (default 16)")
    parser.add_argument("--core", type=int, default=0, help="core of the compute runs (default 0)")
    parser.add_argument("--repeats", type=int, default=5,
                        help="passes of the compute and CPU-share runs; their least CPU time per message, and the "
                        "CPU share's median over the passes, are printed too (default 5)")
    parser.add_argument("--record-minutes", type=float, default=0.0,
                        help="also stream and record a synthetic log of this many minutes (default 0: not)")
    parser.add_argument("--low-latency", action="store_true",
                        help="measure the low-latency mode instead: the cut force against the exact mode, and the "
                        "end-to-end and publish-to-alarm times with --latency low")
    parser.add_argument("--alarm-limit", type=float, default=0.25,
                        help="with --low-latency: the limit on |current_process_A| [A] whose alarms are timed "
                        "(default 0.25)")
    args = parser.parse_args()
    load_at_start = os.getloadavg()

    from threadpoolctl import threadpool_limits

    from greybox.data.io import read_log
    from greybox.data.prepare import derivative_margin
    from greybox.data.prepare import trim as trim_log
    from greybox.live.run import settled_memory

    with tempfile.TemporaryDirectory() as folder, threadpool_limits(limits=1):
        model_path = _model(args.model, Path(folder))
        log = read_log(args.log)
        log = trim_log(log, None, float(log.time[0]) + args.seconds - 1e-9)
        messages = _messages(log, args.batch)
        if args.low_latency:
            figures = {"end_to_end_low": end_to_end(model_path, messages, Path(folder), args.batch, log.sample_time,
                                                    latency="low", alarm_limit=args.alarm_limit),
                       "cut_force": low_latency_force(model_path, Path(folder), args.batch)}
            figures.update({"model": str(args.model or "GMS+SVR fitted by the benchmark"), "log": args.log,
                            "seconds": log.duration, "cpu_count": os.cpu_count(), "load_average_start": load_at_start,
                            "load_average": os.getloadavg()})
            print(json.dumps(figures))
            return
        lookahead = derivative_margin(log.sample_time)
        affinity = os.sched_getaffinity(0)
        os.sched_setaffinity(0, {args.core})
        try:
            step = log.sample_time
            _ = compute(model_path, messages[:100], args.batch, lookahead, step)  # compile and warm up
            with settled_memory():
                figures = {"compute": compute(model_path, messages, args.batch, lookahead, step, args.repeats),
                           "cpu_share": cpu_share(model_path, messages, args.axes, log.duration, step, args.repeats)}
        finally:
            os.sched_setaffinity(0, affinity)
        figures["end_to_end"] = end_to_end(model_path, messages, Path(folder), args.batch, log.sample_time)
        if args.record_minutes > 0:
            figures["recording"] = recording(model_path, args.record_minutes, args.batch, Path(folder))
    figures.update({"model": str(args.model or "GMS+SVR fitted by the benchmark"), "log": args.log,
                    "seconds": log.duration, "lookahead_samples": lookahead,
                    "lookahead_s": lookahead * log.sample_time, "cpu_count": os.cpu_count(),
                    "load_average_start": load_at_start, "load_average": os.getloadavg()})
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
