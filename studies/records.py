"""Measured records: every figure a page publishes comes from one JSON file the code can re-make.

A *record* (``docs/results/<name>.json``) holds the figures one measuring command printed, with where and
when they were measured: the command, the git commit of the tree it ran on, the date, the cores, the load
of the machine before and after, and the package versions (:func:`greybox.provenance.provenance`).
:data:`SPECS` names every record: the command that re-makes it, and the repository paths whose change
makes it stale. ``python scripts/record.py NAME`` measures one and writes it; the pages' tables are
rendered from the records (:mod:`studies.result_pages`), never typed.

A record is *stale* when a commit after the one it was measured on changed a path it depends on
(:func:`stale_commits`), and it is refused outright when those paths held uncommitted changes while it was
measured: its figures would belong to no commit.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from greybox.atomic import write_text_atomic
from greybox.errors import GreyboxError
from greybox.provenance import provenance

__all__ = ["MEASURING", "ROOT", "RESULTS", "RecordSpec", "SPECS", "measure", "write_record", "read_record",
           "record_path", "stale_commits", "uncommitted"]

#: Environment variable naming the record being measured, set for its command: the test of the records does
#: not hold the record being re-made to its old figures (the default test run is itself a record).
MEASURING = "GREYBOX_MEASURING_RECORD"
#: The repository's root.
ROOT = Path(__file__).resolve().parents[1]
#: Where the records live.
RESULTS = ROOT / "docs" / "results"

#: What the paper's experiments depend on: the shipped data, the models and everything that fits, tests
#: and reports them.
_REPRODUCTION = ("data", "greybox/data", "greybox/identify", "greybox/models", "greybox/evaluate",
                 "greybox/reproduce", "greybox/base.py", "greybox/metrics.py", "greybox/threads.py",
                 "greybox/provenance.py", "benchmarks/bench_reproduce.py")

#: What a fit of a friction model on a real data set depends on: the models, their laws and identification,
#: the log type and its preparation, the metrics.
_FRICTION_FITS = ("greybox/models", "greybox/identify", "greybox/data", "greybox/base.py", "greybox/threads.py",
                  "greybox/metrics.py")
#: The EMPS record's models: every one of the study but the asymmetric GMS behind a backlash and ``auto``. The
#: backlash search fits an asymmetric GMS per trial width and ``auto`` fits its candidates on three held-out
#: stretches: each takes several times the rest together; the page gives their figures as single runs.
_EMPS_MODELS = ("coulomb_idim_ls", "coulomb_asym_idim_ls", "coulomb", "coulomb_asym", "stribeck", "stribeck_asym",
                "lugre", "lugre_asym", "gms", "gms_asym", "gms_2ms")
#: The ARTS record's models: every one of the study but the two behind a backlash and ``auto``. Each backlash
#: model fits a GMS per trial width (about nine minutes each on the machine alone, three times that beside the
#: other jobs of a session), and ``auto`` more than an hour; the pages give their figures as single runs.
_ARTS_MODELS = ("coulomb", "coulomb_asym", "stribeck", "stribeck_asym", "lugre", "lugre_asym", "gms", "gms_asym")


@dataclass(frozen=True)
class RecordSpec:
    """How one record is made.

    Attributes
    ----------
    name : str
        The record's name: ``docs/results/<name>.json``.
    command : tuple of str
        The command, run from the repository's root with this Python; it prints one JSON object (the
        figures) as the last thing on its standard output.
    depends_on : tuple of str
        Repository paths (files or folders) whose change makes the record stale.
    what : str
        What is measured, one line.
    """

    name: str
    command: tuple
    depends_on: tuple
    what: str


#: Every record the pages cite.
SPECS = {spec.name: spec for spec in (
    RecordSpec("live-speed", ("benchmarks/bench_live.py", "--seconds", "20"),
               ("greybox/live", "greybox/models", "greybox/data", "greybox/predict", "benchmarks/bench_live.py",
                "data"),
               "greybox live's speed: compute per sample, 16 axes' CPU share, publish to estimate through Mosquitto"),
    RecordSpec("predict-hour", ("benchmarks/bench_predict_hour.py", "--json"),
               ("data", "greybox/data", "greybox/models", "greybox/predict", "greybox/threads.py",
                "greybox/cli/predict.py", "benchmarks/bench_predict_hour.py"),
               "GMS+SVR against GMS on a one-hour log: predict, read, train and the kernel sums, in one run"),
    RecordSpec("reproduce", ("benchmarks/bench_reproduce.py", "--records"), _REPRODUCTION,
               "both experiments of the paper on the shipped twin (greybox reproduce), with its wall time"),
    RecordSpec("default-tests", ("benchmarks/bench_test_run.py",),
               ("greybox", "tests", "studies", "data", "pyproject.toml", "benchmarks/bench_test_run.py"),
               "the default test run (pytest -q -n 2, the README's test command): tests passed, skipped, wall time"),
    RecordSpec("monitor-independent",
               ("scripts/monitor_independent.py", "--variants", "spindle,plain,air", "--json", "-"),
               ("greybox/monitor", "greybox/data", "greybox/models", "greybox/identify",
                "scripts/monitor_independent.py"),
               "greybox monitor on the independent simulator's production histories (development split), "
               "scored against their drift truth"),
    RecordSpec("live-low-latency", ("benchmarks/bench_live.py", "--low-latency"),
               ("greybox/live", "greybox/predict", "greybox/models", "greybox/data", "greybox/twin",
                "benchmarks/bench_live.py", "data", "examples/axis_x.toml"),
               "greybox live --latency low: mean cut force against the exact mode on the twin's and the "
               "independent split's cutting logs; publish-to-estimate and publish-to-alarm times through Mosquitto"),
    RecordSpec("process-head-to-head", ("scripts/process_head_to_head.py", "--json", "-"),
               ("greybox/process", "greybox/predict", "greybox/models", "greybox/identify", "greybox/twin",
                "greybox/data", "greybox/windows.py", "greybox/train", "greybox/cli", "studies/process_head_to_head.py",
                "scripts/process_head_to_head.py", "data", "examples/axis_x.toml"),
               "teach-in envelopes of the raw current and the force through a warm-up on the twin's part series: "
               "events found, false alarms of good parts, mean cut force"),
    # -- the real-data benchmarks and speed (issue 43) --
    RecordSpec("emps-benchmark", ("scripts/emps_benchmark.py", "--record", "--quiet", "--models", *_EMPS_MODELS),
               ("scripts/emps_benchmark.py", "studies/emps.py", *_FRICTION_FITS),
               "the EMPS benchmark (real ball-screw drive): relerr of the friction models (none behind a backlash) on "
               "the training and cross-test files, beside the published IDIM-LS"),
    RecordSpec("arts-benchmark", ("scripts/arts_benchmark.py", "--record", "--quiet", "--models", *_ARTS_MODELS),
               ("scripts/arts_benchmark.py", "studies/arts.py", "studies/arts_data.py", "studies/emps.py",
                *_FRICTION_FITS),
               "the ARTS friction device (real, with backlash): RE and relerr of the friction models (none behind a "
               "backlash) on the training, test and 1-2 Hz files, per file, and in the band of the motion"),
    RecordSpec("gms-speed", ("benchmarks/bench_gms.py", "--json"),
               ("benchmarks/bench_gms.py", "benchmarks/gms_loop.c", "tests/friction_reference.py",
                "tests/friction_signals.py", *_FRICTION_FITS),
               "the GMS kernel against plain Python and plain C, and a default GMS identification on 180 s at 500 Hz"),
    RecordSpec("svr-predict", ("benchmarks/bench_svr_predict.py",),
               ("benchmarks/bench_svr_predict.py", "greybox/models/kernel", "greybox/threads.py"),
               "the compiled RBF expansion against scikit-learn's SVR.predict on 200 000 random samples"),
    RecordSpec("read-hour", ("benchmarks/bench_read.py", "--json"),
               ("benchmarks/bench_read.py", "greybox/data"),
               "read_log on a one-hour 500 Hz log in MCAP, Parquet and CSV, each in a fresh process: time and peak"),
    # -- end of the real-data benchmarks and speed (issue 43) --
    RecordSpec("auto-twin", ("benchmarks/bench_auto.py", "--json"),
               ("benchmarks/bench_auto.py", "greybox/train", "greybox/models", "greybox/identify", "greybox/data",
                "greybox/evaluate", "greybox/cli", "greybox/base.py", "greybox/threads.py", "greybox/metrics.py",
                "greybox/provenance.py", "data"),
               "greybox train --model auto on the twin's X_A and X_B: wall time, the choice and its folds; the "
               "chosen model and coulomb:offset on the fastest held-out log X_C"),
    # -- the pages of h43pages1 (issue 43): compensate, validation, discover --
    RecordSpec("compensate-twin", ("scripts/compensate_twin.py",),
               ("scripts/compensate_twin.py", "greybox/control", "greybox/cli/compensate.py", "greybox/cli/_build.py",
                "greybox/train", "greybox/twin",
                *_FRICTION_FITS),
               "greybox compensate on the twin's X axis: RMS and peak tracking error of the PID loop with each "
               "model's friction feed-forward, on the low- and high-stroke references"),
    RecordSpec("intervals-cost", ("benchmarks/bench_intervals.py", "time", "--json"),
               ("benchmarks/bench_intervals.py", "data/X_A.mcap", *_FRICTION_FITS),
               "the cost of the sandwich parameter intervals beside the default GMS fit on data/X_A.mcap"),
    RecordSpec("discover-emps", ("scripts/discovery_study.py", "--section", "emps", "--record"),
               ("scripts/discovery_study.py", "studies/discovery.py", "studies/emps.py", "greybox/discover",
                *_FRICTION_FITS),
               "greybox discover on the real EMPS drive with a Coulomb and a GMS base (each with an offset): the "
               "effects named, the base refinements, the errors before and after on the cross-test"),
    # -- end of the pages of h43pages1 --
    RecordSpec("process-speed", ("benchmarks/bench_process_check.py", "--json"),
               ("greybox/process", "greybox/predict", "greybox/models", "greybox/identify", "greybox/twin",
                "greybox/data", "greybox/windows.py", "greybox/train", "greybox/cli", "greybox/nc",
                "benchmarks/bench_process_check.py", "data", "examples/axis_x.toml"),
               "greybox process check of a 100-part series of one-minute twin parts on one core, against real time"),
    # -- the predict and monitor pages (issue 43) --
    RecordSpec("cutting-validation", ("scripts/cutting_validation.py", "--record"),
               ("scripts/cutting_validation.py", "studies/cutting.py", "studies/cut_recovery.py", "greybox/models",
                "greybox/identify", "greybox/data", "greybox/predict", "greybox/twin", "greybox/base.py",
                "greybox/metrics.py", "greybox/threads.py", "data", "examples/axis_x.toml"),
               "greybox predict on the twin's cutting logs: every model kind fitted on the shipped air cuts X_A + X_B, "
               "the process current and force recovered against the truth at four cut strengths"),
    RecordSpec("monitor-detection",
               ("benchmarks/bench_monitor_detection.py", "--seeds", "30", "--first-seed", "6000", "--days", "45",
                "--json"),
               ("benchmarks/bench_monitor_detection.py", "greybox/monitor", "greybox/twin", "greybox/data",
                "greybox/models", "greybox/identify"),
               "greybox monitor's fingerprint and detector on the ageing twin: days from the onset of each drift kind "
               "to the first alarm and the feature it names, on the held-out seeds 6000-6029"),
    RecordSpec("monitor-fleet", ("benchmarks/bench_monitor_fleet.py", "--logs", "2", "--repeat", "310", "--json"),
               ("benchmarks/bench_monitor_fleet.py", "greybox/fleet", "greybox/monitor", "greybox/predict",
                "greybox/models", "greybox/data", "greybox/twin", "greybox/threads.py"),
               "greybox monitor against greybox predict on two one-hour production days, each on a fresh local Dask "
               "cluster of one worker: samples per second and their ratio"),
    RecordSpec("monitor-query",
               ("benchmarks/bench_monitor_query.py", "--machines", "100", "--axes", "3", "--days", "365",
                "--write-compacted", "--append-days", "1", "--json"),
               ("benchmarks/bench_monitor_query.py", "greybox/monitor"),
               "'which axes changed most this month' (changed_most) on a history of 100 machines x 3 axes x a year, "
               "after filing and compacting the last day"),
    RecordSpec("predict-relevel", ("scripts/predict_relevel.py", "--record"),
               ("scripts/predict_relevel.py", "studies/process_head_to_head.py", "greybox/predict", "greybox/models",
                "greybox/identify", "greybox/data", "greybox/twin", "greybox/train", "greybox/cli",
                "greybox/threads.py", "data", "examples/axis_x.toml"),
               "greybox predict --relevel on the twin's part series, through a warm-up and on a cold machine: error "
               "of each part's mean cut force with and without re-levelling"),
    # -- end of the predict and monitor pages (issue 43) --
    # -- the walk-through of usage.md and predict.md (issue 43, h43pages3) --
    RecordSpec("walkthrough", ("scripts/walkthrough.py", "--figures", "docs/figures"),
               ("scripts/walkthrough.py", "studies/as_printed.py", "greybox/cli", "greybox/train", "greybox/predict",
                "greybox/evaluate",
                "greybox/twin", *_FRICTION_FITS, "greybox/provenance.py", "data", "examples/axis_x.toml"),
               "the walk-through of docs/usage.md and docs/predict.md run as printed: train GMS+SVR on X_A + X_B, "
               "predict the cutting log X_D (seed 7) with and without calibration, a Coulomb model's "
               "training-region note on X_D; the console lines, the table's rows and the pictures"),
    RecordSpec("discover-twin", ("scripts/discover_shipped.py",),
               ("scripts/discover_shipped.py", "studies/as_printed.py", "greybox/discover", "greybox/cli/discover.py",
                *_FRICTION_FITS,
                "data/X_A.mcap", "data/X_C.mcap"),
               "greybox discover with a GMS base on the shipped X axis (train X_A, test X_C): the effects named, "
               "their held-out gains, the test error before and after against the noise floor"),
    RecordSpec("process-example", ("scripts/process_example.py", "--figures", "docs/figures"),
               ("scripts/process_example.py", "studies/as_printed.py", "greybox/process", "greybox/cli",
                "greybox/train", "greybox/predict",
                "greybox/twin", "greybox/windows.py", *_FRICTION_FITS, "data/X_A.mcap", "data/X_C.mcap",
                "examples/axis_x.toml"),
               "the example of docs/process.md as printed: a GMS on X_A + X_C, the twin's 12-part series with the "
               "tool broken in part 12, a re-levelled force envelope taught on parts 1-10 and the series checked"),
    RecordSpec("intervals-example", ("scripts/intervals_example.py",),
               ("scripts/intervals_example.py", "studies/as_printed.py", "greybox/cli", "greybox/train",
                *_FRICTION_FITS, "data/X_A.mcap"),
               "the example of docs/intervals.md as printed: a GMS on X_A, its parameters' 95 % intervals and flags"),
    # -- end of the walk-through (issue 43, h43pages3) --
    # -- the pages of h43pages4 (issue 43): process, discover, arts, emps, synthetic axis, compensate --
    RecordSpec("process-pooling", ("scripts/process_cut_force_pooling.py", "--record"),
               ("scripts/process_cut_force_pooling.py", "studies/process_head_to_head.py", "greybox/process",
                "greybox/predict", "greybox/models", "greybox/identify", "greybox/twin", "greybox/data",
                "greybox/windows.py", "greybox/train", "greybox/cli", "greybox/base.py", "greybox/threads.py", "data",
                "examples/axis_x.toml"),
               "each good part's mean cut force error through the twin's warm-up with the re-levelling factor per "
               "part, pooled over parts, from the warm-up law and with the true friction (development seeds 101 "
               "and 111)"),
    RecordSpec("twin-axes", ("scripts/twin_axes.py",),
               ("scripts/twin_axes.py", "greybox/twin"),
               "the twin's X and Y axes computed from their parameters: initial stiffness, steady sliding friction "
               "at mid travel, position factor in the window and over the travel, friction at the travel's ends"),
    # -- end of the pages of h43pages4 --
    # -- the training region (issue 40, h40region) --
    RecordSpec("operating-region", ("scripts/operating_region.py",),
               ("scripts/operating_region.py", "studies/operating_region.py", "studies/arts.py", "studies/arts_data.py",
                "greybox/data", "greybox/train/logs.py", "data"),
               "the operating region's rules on the development air cuts (grid, window of the reversals) and the "
               "shares outside it of held-out twin, axis_dev and ARTS runs and of made-up small oscillations"),
    # -- end of the training region (issue 40, h40region) --
    # -- issue 40's axis_dev targets on the independent development split (h40axisdev) --
    RecordSpec("axis-dev", ("benchmarks/bench_axis_dev.py", "--part", "force", "--json"),
               ("benchmarks/bench_axis_dev.py", "greybox/train", "greybox/predict", "greybox/evaluate", "greybox/cli",
                *_FRICTION_FITS, "greybox/provenance.py"),
               "axis_dev: the cut force on cut_D of greybox train --model gmssvr on the three air cuts; a GMS on "
               "each air cut alone, its RMSE on the others over its own (or its refusal)"),
    RecordSpec("axis-dev-speed", ("benchmarks/bench_axis_dev.py", "--part", "speed", "--json"),
               ("benchmarks/bench_axis_dev.py", "greybox/train", "greybox/predict", "greybox/evaluate", "greybox/cli",
                *_FRICTION_FITS, "greybox/provenance.py"),
               "axis_dev: greybox train --model auto on the slower air cuts A and C against coulomb:offset on the "
               "fastest, aircut_B, beside the noise floor; the choice's cut force on cut_D"),
    # -- end of issue 40's axis_dev targets (h40axisdev) --
    # -- --model auto on the ARTS harmonic tests (issue 40, h40arts2) --
    RecordSpec("auto-arts", ("benchmarks/bench_auto_arts.py", "--json"),
               ("benchmarks/bench_auto_arts.py", "studies/arts.py", "greybox/train", "greybox/models",
                "greybox/identify", "greybox/data", "greybox/metrics.py", "greybox/threads.py"),
               "--model auto on the ARTS harmonic 0.25 Hz tests (J = 0): wall time, the choice and its folds; the "
               "chosen model and coulomb:offset on the fastest other test"),
    # -- end of --model auto on the ARTS harmonic tests --
    # -- the docs' last typed figures (issue 43, h43docs5) --
    RecordSpec("coarse-block", ("benchmarks/bench_coarse_block.py", "--json"),
               ("benchmarks/bench_coarse_block.py", "greybox/identify/coarse.py", "greybox/identify/initial.py",
                "greybox/identify/static.py", "greybox/data", "greybox/train/logs.py", "studies/arts.py",
                "studies/arts_data.py", "data"),
               "the block size m of the backlash width search (greybox.identify.coarse) on the twin, axis_dev and "
               "ARTS development sets: pre-sliding deflection, travel per sample at the 99th percentile of |v|"),
    RecordSpec("data-files", ("studies/data_files.py", "--json"),
               ("studies/data_files.py", "studies/arts.py", "studies/arts_data.py", "studies/emps.py", "greybox/data"),
               "facts of the real data files: per ARTS file amplitude, frequency, samples and peak speed; the "
               "EMPS samples after the benchmark's steps 1-2 and after its decimation"),
    # -- end of the docs' last typed figures (h43docs5) --
    # -- the example of monitor.md (issue 43, lead) --
    RecordSpec("monitor-example", ("scripts/monitor_example.py", "--figures", "docs/figures"),
               ("scripts/monitor_example.py", "studies/as_printed.py", "greybox/monitor", "greybox/twin",
                "greybox/identify", "greybox/data", "greybox/cli/monitor.py", "greybox/cli/synth.py"),
               "the example of docs/monitor.md run as printed: 45 days of the ageing twin's X axis with a local "
               "defect from day 35, greybox monitor on them; the console lines, the dashboard's size and pictures"),
    RecordSpec("find-cuts-tolerance", ("studies/find_cuts_tolerance.py", "--json"),
               ("studies/find_cuts_tolerance.py", "greybox/monitor/cutting.py", "greybox/monitor/fingerprint.py",
                "greybox/identify/static.py", "greybox/data", "greybox/twin"),
               "--find-cuts at four tolerances on every fourth day of the independent production histories against "
               "their spindle-load column, and on the twin's air-move days"),
    RecordSpec("monitor-calibration", ("studies/monitor_calibration.py", "--json"),
               ("studies/monitor_calibration.py", "greybox/monitor/detect.py",
                "greybox/monitor/stable_twin_shapes.json"),
               "the change detector's calibrated thresholds (28 and 14 baseline days; 0.5 and 1 false alarm per "
               "axis-year; the twin's shapes and normal days) and the skewness and tails of the shipped shapes"),
    # -- end of the example of monitor.md --
)}


def record_path(name: str) -> Path:
    """The file of record ``name``.

    Parameters
    ----------
    name : str
        A name of :data:`SPECS`.

    Returns
    -------
    pathlib.Path
    """
    return RESULTS / f"{name}.json"


def _git(*args: str, root: Path = ROOT) -> str:
    result = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True)
    if result.returncode != 0:
        raise GreyboxError(f"git {' '.join(args)}: {result.stderr.strip() or 'failed'}")
    return result.stdout


def uncommitted(paths, *, root: Path = ROOT) -> list[str]:
    """Paths under ``paths`` with changes not committed (``git status --porcelain``).

    Parameters
    ----------
    paths : sequence of str
        Repository paths.
    root : path-like, default :data:`ROOT`
        The repository.

    Returns
    -------
    list of str
        The changed files, as git names them.
    """
    lines = _git("status", "--porcelain", "--untracked-files=all", "--", *paths, root=root).splitlines()
    return [line[3:] for line in lines if line.strip()]


def stale_commits(record: dict, *, head: str = "HEAD", root: Path = ROOT) -> list[str]:
    """Commits after the record's own that changed a path it depends on.

    Parameters
    ----------
    record : dict
        A record as :func:`read_record` returns it.
    head : str, default "HEAD"
        The commit the pages are checked at.
    root : path-like, default :data:`ROOT`
        The repository.

    Returns
    -------
    list of str
        ``"<short hash> <subject>"`` per commit, newest first; empty when the record is current. A record
        whose commit is not an ancestor of ``head`` is stale as a whole (one entry saying so).
    """
    commit = record["commit"]
    ancestor = subprocess.run(["git", "merge-base", "--is-ancestor", commit, head], cwd=root,
                              capture_output=True).returncode == 0
    if not ancestor:
        return [f"{commit[:9]} is not in the history of {head}"]
    return _git("log", "--format=%h %s", f"{commit}..{head}", "--", *record["depends_on"], root=root).splitlines()


def _load() -> list[float]:
    return [round(value, 2) for value in os.getloadavg()]


def _last_json(text: str, command) -> dict:
    start = text.rfind("\n{") + 1  # the last line that opens an object at its first column; 0: none or the first
    try:
        figures = json.loads(text[start:])
    except json.JSONDecodeError:
        figures = None
    if not isinstance(figures, dict):
        raise GreyboxError(f"{' '.join(command)}: printed no JSON object at the end of its output")
    return figures


def measure(spec: RecordSpec, *, allow_dirty: bool = False, root: Path = ROOT) -> dict:
    """Run a record's command and return the record.

    Parameters
    ----------
    spec : RecordSpec
        The record to make.
    allow_dirty : bool, default False
        Measure although the paths the record depends on hold uncommitted changes (the record then says
        so, and the pages' test refuses it: for trying a change, not for publishing).
    root : path-like, default :data:`ROOT`
        The repository the command runs in.

    Returns
    -------
    dict
        ``name``, ``what``, ``command``, ``commit``, ``uncommitted``, ``date`` (UTC, ISO 8601),
        ``seconds`` (wall time of the command), ``cores``, ``load_before`` and ``load_after`` (1, 5 and 15
        minute load averages), ``versions``, ``depends_on`` and ``figures``.

    Raises
    ------
    GreyboxError
        When the depended-on paths hold uncommitted changes (unless ``allow_dirty``), the command fails,
        or it prints no JSON object.
    """
    changed = uncommitted(spec.depends_on, root=root)
    if changed and not allow_dirty:
        raise GreyboxError(f"record {spec.name}: uncommitted changes in what it measures "
                           f"({', '.join(changed[:5])}{', ...' if len(changed) > 5 else ''}); commit them first")
    command = [sys.executable, *spec.command]
    load_before, started = _load(), time.perf_counter()
    result = subprocess.run(command, cwd=root, stdout=subprocess.PIPE, text=True,
                            env={**os.environ, MEASURING: spec.name})
    seconds = time.perf_counter() - started
    if result.returncode != 0:
        raise GreyboxError(f"record {spec.name}: {' '.join(spec.command)} exited with status {result.returncode}")
    versions = provenance()
    return {
        "name": spec.name,
        "what": spec.what,
        "command": "python " + " ".join(spec.command),
        "commit": _git("rev-parse", "HEAD", root=root).strip(),
        "uncommitted": changed,
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "seconds": round(seconds, 1),
        "cores": versions["cpu_count"],
        "load_before": load_before,
        "load_after": _load(),
        "versions": versions,
        "depends_on": list(spec.depends_on),
        "figures": _last_json(result.stdout, spec.command),
    }


def write_record(record: dict) -> Path:
    """Write a record atomically to ``docs/results/<name>.json``.

    Parameters
    ----------
    record : dict
        As :func:`measure` returns it.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    RESULTS.mkdir(parents=True, exist_ok=True)
    return write_text_atomic(record_path(record["name"]), json.dumps(record, indent=1, sort_keys=True) + "\n")


def read_record(name: str) -> dict:
    """Read record ``name``.

    Parameters
    ----------
    name : str
        A name of :data:`SPECS`.

    Returns
    -------
    dict

    Raises
    ------
    GreyboxError
        When the record has not been made.
    """
    path = record_path(name)
    if not path.is_file():
        raise GreyboxError(f"{path.relative_to(ROOT)}: no such record; make it with python scripts/record.py {name}")
    return json.loads(path.read_text(encoding="utf-8"))
