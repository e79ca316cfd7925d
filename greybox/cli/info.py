"""``greybox info``: summarise logs (samples, step, ranges, effort, noise floor) and model files."""

from __future__ import annotations

import argparse
import json
import zipfile
from pathlib import Path, PurePath

import numpy as np

from ..data.effort import EFFORT_UNITS, effort_quantity, effort_text
from ..data.log import AxisLog
from ..json_values import jsonable
from ..models.files import load_model
from ..models.registry import model_kind
from ..provenance import model_quantity
from ._model_text import model_lines
from ._options import add_log_arguments, read_named_runs
from ._provenance import record_lines, region_lines

#: Suffix of greybox model files by convention (any name works; a ZIP archive is taken for a model file too).
MODEL_SUFFIX = ".gbm"


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "info",
        description="Print one line per log: samples, step, duration, position, velocity and effort ranges; "
                    "for a model file (.gbm) its kind, parameters and fit.",
    )
    parser.add_argument("logs", nargs="+", metavar="FILE",
                        help="log files (CSV, Parquet, MCAP, TDMS or MATLAB .mat) or model files (.gbm)")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object per log or model instead of a table")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def summarise(log: AxisLog) -> dict:
    """Return the summary figures of one prepared log.

    Parameters
    ----------
    log : AxisLog
        A log with velocity present.

    Returns
    -------
    dict
        Samples, sample time [ms], duration [s], kind of axis (``motion``),
        position range [mm] and peak speed [mm/min] (keys ``position_min_mm``,
        ``speed_max_mm_min``; ``..._deg``, ``..._deg_min`` for a rotary axis),
        what the effort is (``effort_quantity``: a current, or a motor torque [Nm] of a servo
        trace), its RMS and range (in the log's unit) and, for synthetic logs, the
        RMS of the known noise (the noise floor).
    """
    length = log.units.length
    summary = {
        "file": log.source,
        "axis": log.axis,
        "dataset": log.dataset,
        "samples": len(log),
        "sample_time_ms": 1e3 * log.sample_time,
        "duration_s": log.duration,
        "motion": log.motion,
        f"position_min_{length}": float(log.position.min()),
        f"position_max_{length}": float(log.position.max()),
        f"speed_max_{length}_min": float(60.0 * np.abs(log.velocity).max()) if log.velocity is not None else None,
        "effort_quantity": effort_quantity(log),
        "effort_unit": EFFORT_UNITS[effort_quantity(log)],
        "effort_rms": float(np.sqrt(np.mean(log.effort**2))),
        "effort_min": float(log.effort.min()),
        "effort_max": float(log.effort.max()),
        "extras": sorted(log.extras),
    }
    noise = log.extras.get("truth_noise_A")
    if noise is None and "truth_current_A" in log.extras:
        noise = log.effort - log.extras["truth_current_A"]
    if noise is not None:
        summary["noise_floor_rmse_A"] = float(np.sqrt(np.mean(noise**2)))
    return summary


def display_names(paths) -> list[str]:
    """Shortest trailing parts of the paths that tell the files apart: names, with folders where names repeat.

    Parameters
    ----------
    paths : sequence of str
        File paths.

    Returns
    -------
    list of str
        ``X_A.mcap`` for a name given once; ``run1/X_A.mcap`` and ``run2/X_A.mcap`` (as many
        folders as needed) for names that repeat; the path as given for a file named twice.
    """
    parts = [PurePath(p).parts or (str(p),) for p in paths]
    depth = [1] * len(parts)
    while True:
        names = ["/".join(q[-k:]) for q, k in zip(parts, depth)]
        clashes = [i for i, name in enumerate(names)
                   if names.count(name) > 1 and depth[i] < len(parts[i])]
        if not clashes:
            return names
        for i in clashes:
            depth[i] += 1


def is_model_file(path) -> bool:
    """Whether ``path`` is to be read as a model file: named ``*.gbm``, or a ZIP archive (no log format is one).

    Parameters
    ----------
    path : str or path-like
        A path given to ``greybox info``.
    """
    path = Path(path)
    return path.suffix.lower() == MODEL_SUFFIX or (path.is_file() and zipfile.is_zipfile(path))


def describe_model(path, model) -> dict:
    """The summary of a loaded model file: kind, axis kind, effort unit, step, parameters and fit figures.

    Parameters
    ----------
    path : str or path-like
        The model file.
    model : CurrentModel
        The fitted model loaded from it.

    Returns
    -------
    dict
        ``file``, ``kind``, ``motion``, ``effort_unit``, ``sample_time_ms``, ``parameters`` (``{name:
        {"value", "unit"}}``, with ``lower_95``, ``upper_95`` and ``flag`` when the file holds intervals),
        ``fit`` (the model's ``fit_summary``), ``notes`` (what the fit could not settle) and ``selection``
        (the table ``--model auto`` chose from, or None), NumPy values as lists and numbers, NaN as None.
    """
    return {"file": str(path), "kind": model_kind(model), "motion": getattr(model, "motion_", "linear"),
            "effort_unit": model.effort_unit_, "sample_time_ms": 1e3 * float(model.sample_time_),
            "parameters": {row.name: {"value": jsonable(row.value), "unit": row.unit,
                                      **({} if row.lower is None else {"lower_95": jsonable(row.lower),
                                                                        "upper_95": jsonable(row.upper),
                                                                        "flag": row.flag})}
                           for row in model.parameter_table()},
            "fit": jsonable(model.fit_summary()), "notes": model.fit_notes(),
            "selection": jsonable(getattr(model, "selection_", None))}


def _print_model(name: str, summary: dict, model, records: dict) -> None:
    quantity = model_quantity(records, model)
    print(f"model {name}: {summary['kind']}, {summary['motion']} axis, effort in "
          f"{effort_text(quantity)}, step {summary['sample_time_ms']:g} ms")
    print("\n".join(model_lines(model, quantity=quantity)))


def run(args: argparse.Namespace) -> int:
    shown = dict(zip(args.logs, display_names(list(args.logs))))
    kinds = {path: is_model_file(path) for path in args.logs}
    models = [(path, *load_model(path, records=True)) for path in args.logs if kinds[path]]  # all checked first
    logs = [path for path in args.logs if not kinds[path]]
    for path, model, records in models:
        quantity = model_quantity(records, model)
        summary = {**describe_model(path, model), "effort": {"quantity": quantity, "unit": EFFORT_UNITS[quantity]},
                   **({"records": records} if records else {})}
        if args.json:
            print(json.dumps(summary))
        else:
            _print_model(shown[path], summary, model, records)
            for line in record_lines(records) or region_lines(model):
                print(line)
    if logs:
        _print_logs(args, logs, [shown[path] for path in logs])
    return 0


def _print_logs(args: argparse.Namespace, paths, shown) -> None:
    runs, names = read_named_runs(args, paths, shown)
    summaries = [summarise(log) for log in runs]
    if args.json:
        for summary in summaries:
            print(json.dumps(summary))
        return
    width = max([28, *map(len, names)])
    lengths = {log.units.length for log in runs}
    length = lengths.pop() if len(lengths) == 1 else "mm|deg"
    header = f"{'file':<{width}} {'axis':>4} {'set':>4} {'samples':>9} {'dt ms':>6} {'dur s':>8} " \
             f"{'position ' + length:>19} {'vmax ' + length + '/min':>12} {'RMS effort':>12} {'noise':>8}"
    print(header)
    for name, s, log in zip(names, summaries, runs):
        unit = log.units.length
        noise = f"{s['noise_floor_rmse_A']:.4f}" if "noise_floor_rmse_A" in s else "-"
        vmax = s[f"speed_max_{unit}_min"]
        vmax = f"{vmax:.0f}" if vmax is not None else "-"
        print(
            f"{name:<{width}} {s['axis']:>4} {s['dataset']:>4} {s['samples']:>9d} {s['sample_time_ms']:>6.2f} "
            f"{s['duration_s']:>8.1f} {s[f'position_min_{unit}']:>9.2f}..{s[f'position_max_{unit}']:<8.2f} "
            f"{vmax:>12} {s['effort_rms']:>10.4f} {s['effort_unit']:<2} {noise:>8}"
        )
