"""Benchmark of read_log on a one-hour 500 Hz axis log in MCAP, CSV and Parquet.

Synthesises a log (1.8 M samples at the default one hour and 2 ms: position,
velocity, current and three extra channels, full-precision floats), writes it
in each format to a temporary directory, then reads each file with
:func:`greybox.data.read_log` in a fresh Python subprocess. Reported per
format: read time [s] (wall clock around ``read_log``, validation included),
peak memory [MB] as the subprocess's peak resident set size (``VmHWM`` in
``/proc/self/status``, Linux; ``ru_maxrss`` would include the parent's
memory, which a forked child inherits in that figure), so it includes the
interpreter and the imported libraries; ``<fmt>_base_mb`` is the peak after
the imports, before reading. Also file size [MB] and write time [s]. The
read time includes the lazy imports a fresh process needs for that format
(pyarrow, numba and its cached kernels for MCAP).

``--stages`` instead profiles the MCAP read in this process, kernels warm: CPU
seconds [s] of each stage run on one thread over the whole file (chunks
decompressed and CRC-checked, split into records, the channel's messages
selected with their time stamps, parsed, joined into columns, converted to an
AxisLog), and wall and CPU seconds of ``read_log`` on the pool.

``--hour`` times reading only, on the one-hour log that ``bench_predict_hour.py``
reads (the twin's axis X, run 21, with cutting: 1.8 M samples of 10 numbers):
the median of ``--reads`` reads by ``read_log`` in this process after one read
that warms imports and kernels, and the first read in a fresh process, for MCAP
and Parquet; with the 1-minute load average before and after. It writes no record.

Usage::

    python benchmarks/bench_read.py            # table
    python benchmarks/bench_read.py --json     # one JSON line
    python benchmarks/bench_read.py --stages   # MCAP read stage by stage (JSON line)
    python benchmarks/bench_read.py --hour     # read-only timing of the predict-hour log (JSON line)
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from greybox.data import AxisLog, mcap_io, read_log, write_log
from greybox.data.units import log_from_columns
from greybox.twin import make_dataset

_CHILD = r"""
import json, sys, time
def peak_kb():
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
from greybox.data import read_log
base = peak_kb()
start = time.perf_counter()
log = read_log(sys.argv[1])
seconds = time.perf_counter() - start
print(json.dumps({"n": len(log), "seconds": seconds, "peak_kb": peak_kb(), "base_kb": base}))
"""


def synthetic_log(duration_s: float = 3600.0, sample_time: float = 0.002, seed: int = 0) -> AxisLog:
    """A back-and-forth stroke of a feed axis with a friction-like current and three extras."""
    rng = np.random.default_rng(seed)
    time = np.arange(int(round(duration_s / sample_time))) * sample_time
    phase = 2 * np.pi * time / 8.0
    position = 200.0 + 150.0 * np.sin(phase) + 0.5 * np.sin(7.3 * phase)  # mm
    velocity = np.gradient(position, sample_time)  # mm/s
    current = 1.2 * np.tanh(velocity / 2.0) + 0.004 * velocity + rng.normal(0.0, 0.05, time.size)  # A
    return AxisLog(
        time=time,
        position=position,
        effort=current,
        velocity=velocity,
        axis="X",
        dataset="bench",
        extras={
            "truth_friction_A": 1.2 * np.tanh(velocity / 2.0),
            "setpoint_position_mm": position + rng.normal(0.0, 1e-3, time.size),
            "motor_temperature_C": 40.0 + 0.001 * time + rng.normal(0.0, 0.02, time.size),
        },
        attrs={"seed": seed, "benchmark": "bench_read"},
    )


def _read_in_subprocess(path: Path) -> dict:
    output = subprocess.run([sys.executable, "-c", _CHILD, str(path)], check=True, capture_output=True, text=True)
    return json.loads(output.stdout.strip().splitlines()[-1])


def run(duration_s: float = 3600.0, sample_time: float = 0.002) -> dict:
    """Write the synthetic log in each format and time a fresh-process read of each."""
    log = synthetic_log(duration_s, sample_time)
    result: dict = {"n_samples": len(log), "n_channels": 3 + len(log.extras)}
    with tempfile.TemporaryDirectory() as folder:
        warm = Path(folder) / "warm.mcap"  # compile and cache the numba kernels once
        write_log(log.select(slice(0, 1000)), warm)
        read_log(warm)
        for fmt in ("mcap", "parquet", "csv"):
            path = Path(folder) / f"bench.{fmt}"
            start = time.perf_counter()
            write_log(log, path)
            result[f"{fmt}_write_s"] = round(time.perf_counter() - start, 2)
            result[f"{fmt}_file_mb"] = round(path.stat().st_size / 1e6, 1)
            child = _read_in_subprocess(path)
            if child["n"] != len(log):
                raise RuntimeError(f"{fmt}: read {child['n']} samples, wrote {len(log)}")
            result[f"{fmt}_read_s"] = round(child["seconds"], 2)
            result[f"{fmt}_peak_mb"] = round(child["peak_kb"] / 1024, 0)
            result[f"{fmt}_base_mb"] = round(child["base_kb"] / 1024, 0)
    return result


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def stages(duration_s: float = 3600.0, sample_time: float = 0.002) -> dict:
    """CPU seconds of each stage of the MCAP read on one thread, and wall/CPU seconds of ``read_log``."""
    log = synthetic_log(duration_s, sample_time)
    result: dict = {"n_samples": len(log)}
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.mcap"
        write_log(log, path)
        read_log(path)  # kernels compiled or loaded, pools made
        wall, cpu = time.perf_counter(), _cpu_seconds()
        read_log(path)
        result["read_log_wall_s"] = round(time.perf_counter() - wall, 3)
        result["read_log_cpu_s"] = round(_cpu_seconds() - cpu, 3)
        channel = next(iter(mcap_io._walked_channels(path).values()))

        def timed(name, function, items):
            started = _cpu_seconds()
            out = [function(*item) for item in items]
            result[f"{name}_cpu_s"] = round(_cpu_seconds() - started, 3)
            return out

        contents = [(item, path) for item in mcap_io._stretches(path) if isinstance(item, bytes)]
        raw = timed("decompress_crc", mcap_io._decompress, contents)
        records = timed("scan", mcap_io._chunk_records, [(data, path) for data in raw])
        selected = timed("select", mcap_io._channel_messages,
                         [(*chunk, channel.id, path) for chunk in records])
        columns = timed("parse", mcap_io._parse_messages,
                        [(chunk[0], offs, lens, 1) for chunk, (offs, lens, _) in zip(records, selected)])
        collector = mcap_io._MessageCollector(path)
        for chunk, (offs, lens, stamps), parsed in zip(records, selected, columns):
            collector.add(chunk[0], offs, lens, stamps, parsed)
        ((stamps, table),) = timed("join", collector.columns, [()])
        timed("convert", lambda: log_from_columns(table, source=path, time=stamps * 1e-9,
                                                  **mcap_io._channel_fields(channel, path)), [()])
    return result


def hour_reads(duration_s: float = 3600.0, reads: int = 5, folder: str | None = None) -> dict:
    """Read-only timing of the one-hour log of ``bench_predict_hour.py``, MCAP and Parquet.

    Parameters
    ----------
    duration_s : float
        Length of the log [s].
    reads : int
        Warm reads whose median is reported.
    folder : str, optional
        Directory to keep the written files in and to take them from when they are there already
        (default: a temporary one, removed).

    Returns
    -------
    dict
        Per format: samples, median / min / max seconds of the warm reads, samples per second at the
        median, and seconds of the first read in a fresh process; cores and load averages.
    """
    result: dict = {"cores": len(os.sched_getaffinity(0)), "load_before": os.getloadavg()[0], "reads": reads}
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(folder or scratch)
        root.mkdir(parents=True, exist_ok=True)
        log = None
        for fmt in ("mcap", "parquet"):
            path = root / f"hour_{int(duration_s)}s.{fmt}"
            if not path.exists():
                log = log or make_dataset("X", "A", 21, duration_s=duration_s, cutting=True)
                write_log(log, path)
            first = _read_in_subprocess(path)
            n = len(read_log(path))  # imports and compiled readers warm
            seconds = []
            for _ in range(reads):
                started = time.perf_counter()
                read_log(path)
                seconds.append(time.perf_counter() - started)
            median = float(np.median(seconds))
            result[fmt] = {"samples": n, "file_mb": round(path.stat().st_size / 1e6, 1), "seconds": round(median, 3),
                           "min_s": round(min(seconds), 3), "max_s": round(max(seconds), 3),
                           "samples_per_s": n / median, "fresh_first_read_s": round(first["seconds"], 3)}
    result["load_after"] = os.getloadavg()[0]
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=3600.0, help="log duration [s] (default 3600)")
    parser.add_argument("--sample-time", type=float, default=0.002, help="sample time [s] (default 0.002)")
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    parser.add_argument("--stages", action="store_true", help="profile the MCAP read stage by stage (JSON line)")
    parser.add_argument("--hour", action="store_true",
                        help="time reading only: the predict-hour log, median of --reads warm reads (JSON line)")
    parser.add_argument("--reads", type=int, default=5, help="warm reads for --hour (default 5)")
    parser.add_argument("--dir", help="for --hour: keep the written logs here, reuse them when present")
    args = parser.parse_args(argv)
    if args.hour:
        print(json.dumps(hour_reads(args.duration, args.reads, args.dir)))
        return 0
    if args.stages:
        print(json.dumps(stages(args.duration, args.sample_time)))
        return 0
    result = run(args.duration, args.sample_time)
    if args.json:
        print(json.dumps(result))
    else:
        print(f"{result['n_samples']} samples, {result['n_channels']} channels")
        print(f"{'format':8} {'read s':>8} {'peak MB':>8} {'base MB':>8} {'file MB':>8} {'write s':>8}")
        for fmt in ("mcap", "parquet", "csv"):
            print(
                f"{fmt:8} {result[fmt + '_read_s']:8.2f} {result[fmt + '_peak_mb']:8.0f} "
                f"{result[fmt + '_base_mb']:8.0f} {result[fmt + '_file_mb']:8.1f} {result[fmt + '_write_s']:8.2f}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
