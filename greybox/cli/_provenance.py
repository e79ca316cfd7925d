"""The lines ``greybox info`` prints of a model file's training record (:mod:`greybox.train.record`), and the
warning of predict and evaluate when a log is prepared otherwise than the training logs (:mod:`greybox.provenance`)."""

from __future__ import annotations

import argparse
import sys

from ..data.prepare import MAX_GAP_STEPS
from ..provenance import TRAINING_RECORD, preparation_warning

__all__ = ["record_lines", "region_lines", "warn_preparation"]


def _read_options(args: argparse.Namespace) -> dict:
    """The preparation options in ``args`` (:func:`greybox.provenance.preparation_of`), defaults where absent."""
    return {"resample": getattr(args, "resample", None), "max_gap": getattr(args, "max_gap", MAX_GAP_STEPS),
            "time_tolerance": args.time_tolerance, "cutoff_hz": getattr(args, "cutoff_hz", None)}


def warn_preparation(records: dict, args: argparse.Namespace, runs, log_name: str, model_name: str,
                     stream=None) -> str | None:
    """Print one ``warning:`` line when ``runs`` are prepared otherwise than the model's training logs.

    Parameters
    ----------
    records : dict
        The model file's records (a file without a training record warns of nothing).
    args : argparse.Namespace
        Parsed log options.
    runs : list of AxisLog or None
        The prepared runs of the log; None when the log is streamed (then the options alone are compared,
        at the training logs' sample time).
    log_name, model_name : str
        Names for the message.
    stream : file-like, optional
        Where to print; default stderr.

    Returns
    -------
    str or None
        The line printed (:func:`greybox.provenance.preparation_warning`).
    """
    line = preparation_warning(records, _read_options(args), runs, log_name, model_name)
    if line is not None:
        print(line, file=stream or sys.stderr)
    return line


def record_lines(records: dict) -> list[str]:
    """The lines ``greybox info`` prints of a model file's training record (none for a file without one).

    Parameters
    ----------
    records : dict
        The model file's records.
    """
    record = records.get(TRAINING_RECORD)
    if record is None:
        return []
    prep = record["preparation"]
    total = record["training_error"]
    cutoff = "default" if prep["cutoff_hz"] is None else f"{prep['cutoff_hz']:g} Hz"
    resample = "no --resample" if prep["resample_s"] is None else f"--resample {prep['resample_s']:g}"
    re = "" if total["re_percent"] is None else f", RE {total['re_percent']:.3f} %"
    quantity = total.get("quantity")
    lines = ["training:",
             "  files          = " + ", ".join(f"{entry['name']} ({entry['bytes']} bytes, sha256 "
                                               f"{entry['sha256'][:12]}...)" for entry in record["files"]),
             f"  preparation    = step {prep['sample_time_s'] * 1e3:g} ms, cut-off {cutoff}, {resample}, "
             f"max gap {prep['max_gap_steps']:g} steps, time tolerance {prep['time_tolerance']:g}, derived "
             f"{', '.join(prep['derived']) or 'nothing'}",
             *([f"  axis           = {record['axis']}"] if "axis" in record else []),
             *([f"  effort         = {quantity} [{total['unit']}]"] if quantity else []),
             f"  training error = RMSE {total['rmse']:.4g} {total['unit']}{re} over {total['samples']} samples "
             f"({len(record['runs'])} run(s))"]
    for name, (low, high) in record["ranges"].items():
        lines.append(f"  {name + ' range':<14} = {low:.6g} .. {high:.6g}")
    return lines


def region_lines(model) -> list[str]:
    """The training region a model file holds without a training record (files written before it): the
    ranges of position and velocity the model was fitted on, in its units; none for older files still.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    """
    units = model.units_
    ranges = [(f"position range [{units.length}]", getattr(model, "position_range_mm_", None)),
              (f"velocity range [{units.velocity_unit}]", getattr(model, "velocity_range_mm_s_", None))]
    shown = [f"  {name} = {low:.6g} .. {high:.6g}" for name, pair in ranges if pair is not None
             for low, high in [pair]]
    return ["training region:", *shown] if shown else []
