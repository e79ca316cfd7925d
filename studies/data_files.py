"""Facts of the real data files the pages cite, computed from the files (no fit).

ARTS friction damper (``../shared/data/real/ARTS_friction_damper``): per ``test<k>.npy`` file the
amplitude (half the span of the displacement) [mm], the excitation frequency (the peak of the displacement's
spectrum, mean removed) [Hz], the samples, the sample rate [Hz] and the peak speed [mm/s]. EMPS
(``../shared/data/real/EMPS``): the samples of each file after the benchmark's steps 1-2 (the 1 kHz log from
its 50th sample on) and after its decimation by 10.

The record ``data-files`` (``python scripts/record.py data-files``) runs it; docs/arts-benchmark.md and
docs/emps-benchmark.md render it.

Usage::

    python studies/data_files.py          # the ARTS table and the EMPS counts
    python studies/data_files.py --json   # one JSON line
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from studies import emps  # noqa: E402
from studies.arts import benchmark_log as arts_log  # noqa: E402

REAL = ROOT.parent / "shared" / "data" / "real"
ARTS = REAL / "ARTS_friction_damper"
EMPS = REAL / "EMPS"


def arts_file(path: Path) -> dict:
    """Amplitude [mm], frequency [Hz], samples, sample rate [Hz] and peak speed [mm/s] of one ARTS file."""
    log = arts_log(path)
    position = np.asarray(log.position, dtype=float)
    spectrum = np.abs(np.fft.rfft(position - position.mean()))
    frequencies = np.fft.rfftfreq(len(position), log.sample_time)
    peak = 1 + int(np.argmax(spectrum[1:]))
    return {"amplitude_mm": float(np.ptp(position) / 2.0), "frequency_hz": float(frequencies[peak]),
            "samples": len(log), "sample_rate_hz": float(1.0 / log.sample_time),
            "peak_speed_mm_s": float(np.max(np.abs(log.velocity)))}


def emps_file(path: Path) -> dict:
    """Samples of one EMPS file after the benchmark's steps 1-2 and after its decimation."""
    log = emps.benchmark_log(path)
    return {"samples_1khz": len(log), "samples_decimated": len(emps.decimate_benchmark(log.effort)),
            "decimation": emps.DECIMATION}


def measure() -> dict:
    """The facts of every file, JSON-ready."""
    arts = sorted(ARTS.glob("test*.npy"), key=lambda path: int(path.stem[4:]))
    return {"arts": {path.stem: arts_file(path) for path in arts},
            "emps": {name: emps_file(EMPS / name) for name in (emps.TRAIN_FILE, emps.TEST_FILE)}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    result = measure()
    if args.json:
        print(json.dumps(result))
        return 0
    for name, row in result["arts"].items():
        print(f"{name}: {row['amplitude_mm']:.1f} mm, {row['frequency_hz']:g} Hz, {row['samples']} samples, "
              f"{row['peak_speed_mm_s']:.0f} mm/s")
    for name, row in result["emps"].items():
        print(f"{name}: {row['samples_1khz']} samples at 1 kHz, {row['samples_decimated']} decimated")
    return 0


if __name__ == "__main__":
    sys.exit(main())
