"""Writing the process table of ``greybox predict``: CSV, Parquet or MCAP, atomically.

The columns are those of :meth:`greybox.predict.process.ProcessResult.columns`
(``time_s``, ``current_measured_A``, ``current_model_A``, ``current_process_A``,
``force_process_N`` with axis metadata, ``position_mm``, ``velocity_mm_s``; for a rotary
axis ``torque_process_Nm``, ``position_deg``, ``velocity_deg_s``).

* CSV: plain, the header row first, then one row per sample, floats as their
  shortest exact text (``pandas.read_csv``, spreadsheets and MATLAB's
  ``readtable`` read it with default settings); the metadata go to the
  sidecar ``<name>.csv.json`` beside it (:mod:`greybox.data.file_metadata`).
* Parquet: float64 columns, zstd, the metadata as JSON under the schema key
  ``greybox``.
* MCAP: one channel ``/process/<axis>`` (``/process`` without a name), schema
  ``greybox.ProcessSample`` (JSON schema), one JSON message per sample at
  ``log_time = publish_time =`` the sample time [ns], holding every column
  but ``time_s``; measured, modelled and process current (and force) can be
  overlaid in an MCAP viewer's plot panel.

The metadata (axis, effort unit, attrs) follow the conventions of
:mod:`greybox.data.csv_io`, :mod:`greybox.data.parquet_io` and
:mod:`greybox.data.mcap_io`, so ``greybox.data.io.read_log`` reads an output
back given a column mapping for the effort, e.g.
``columns={"current_A": "current_process_A"}``.
"""

from __future__ import annotations

import json
import os
import secrets
from pathlib import Path
from typing import Callable, Iterable, Iterator

import numpy as np

from ..atomic import atomic_output, check_output_path
from ..data.file_metadata import sidecar_path, sidecar_text
from ..errors import GreyboxError
from .process import ProcessResult, join_results

__all__ = ["OUTPUT_FORMATS", "PROCESS_SCHEMA_NAME", "output_format", "output_paths", "check_output_path",
           "write_process", "write_process_blocks"]

#: Output formats by file extension.
OUTPUT_FORMATS = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mcap": "mcap"}

#: Schema name of the MCAP messages.
PROCESS_SCHEMA_NAME = "greybox.ProcessSample"

_DESCRIPTIONS = {
    "current_measured_A": "measured motor current [A]",
    "current_model_A": "model current: inertia + friction, trained on air cuts [A]",
    "current_process_A": "process share: measured - model [A]",
    "force_measured_N": "measured drive force [N]",
    "force_model_N": "model force: inertia + friction, trained on air cuts [N]",
    "force_process_N": "process force the drive exerts on the table [N]",
    "torque_measured_Nm": "measured drive torque [Nm]",
    "torque_model_Nm": "model torque: inertia + friction, trained on air cuts [Nm]",
    "torque_process_Nm": "process torque the drive exerts on the rotary axis [Nm]",
    "position_mm": "axis position [mm]",
    "velocity_mm_s": "axis velocity [mm/s]",
    "position_deg": "rotary axis angle [deg]",
    "velocity_deg_s": "rotary axis angular velocity [deg/s]",
}


def output_format(path) -> str:
    """Format name of an output file from its extension.

    Parameters
    ----------
    path : path-like
        Output file; only its extension (case-insensitive) is read.

    Raises
    ------
    GreyboxError
        For an extension other than .csv, .parquet, .pq or .mcap.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in OUTPUT_FORMATS:
        raise GreyboxError(f"{path}: unknown output extension '{suffix}'; write .csv, .parquet or .mcap")
    return OUTPUT_FORMATS[suffix]


def output_paths(path) -> list[Path]:
    """Every file :func:`write_process` writes for ``path``: the table, and for CSV its metadata sidecar.

    Parameters
    ----------
    path : path-like
        Output file of the process table (.csv, .parquet, .pq or .mcap).

    Raises
    ------
    GreyboxError
        For an unknown extension (see :func:`output_format`).
    """
    path = Path(path)
    return [path, sidecar_path(path)] if output_format(path) == "csv" else [path]


def _metadata(result: ProcessResult) -> dict:
    return {"axis": result.axis, "dataset": result.dataset, "effort_unit": result.effort_unit, "attrs": result.attrs}


def _csv_rows(columns: dict, stream) -> None:
    text = [values.tolist() for values in columns.values()]
    template = ",".join(["%r"] * len(columns)) + "\n"
    for row in zip(*text):
        stream.write(template % row)


def _write_csv(results: Iterable[ProcessResult], path) -> ProcessResult | None:
    """Write the blocks as one CSV table; return the last block (None for none)."""
    last = None
    with open(path, "w", encoding="utf-8", newline="") as stream:
        for last in results:
            columns = last.columns()
            if stream.tell() == 0:
                stream.write(",".join(columns) + "\n")
            _csv_rows(columns, stream)
    return last


def _arrow_table(result: ProcessResult, metadata: dict | None = None):
    import pyarrow as pa

    return pa.table({name: np.asarray(values, dtype=np.float64) for name, values in result.columns().items()},
                    metadata=None if metadata is None else {b"greybox": json.dumps(metadata).encode()})


def _write_parquet(results: Iterable[ProcessResult], path, metadata: Callable[[], dict]) -> None:
    """Write the blocks as row groups; the metadata (known once every block is through) in the schema.

    The schema metadata of a Parquet file is fixed when its writer starts, so the blocks go to a
    hidden temporary file first and are then copied row group by row group into ``path`` under the
    complete schema.
    """
    import pyarrow.parquet as pq

    # named after ``path`` (the hidden temporary of atomic_output, which names its process): a run killed by
    # SIGKILL leaves it to be removed by the next write of the same output (atomic.remove_stale_temporaries)
    staging = f"{os.path.abspath(path)}.{secrets.token_hex(4)}.blocks.tmp"
    os.close(os.open(staging, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    try:
        writer = None
        try:
            for result in results:
                table = _arrow_table(result)
                if writer is None:
                    writer = pq.ParquetWriter(staging, table.schema, compression="none")  # read back at once
                writer.write_table(table)
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise GreyboxError(f"{path}: nothing to write")
        source = pq.ParquetFile(staging)
        schema = source.schema_arrow.with_metadata({b"greybox": json.dumps(metadata()).encode()})
        with pq.ParquetWriter(str(path), schema, compression="zstd") as final:
            for index in range(source.num_row_groups):
                final.write_table(source.read_row_group(index).replace_schema_metadata(schema.metadata))
    finally:
        os.unlink(staging)


def _schema(fields) -> dict:
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": PROCESS_SCHEMA_NAME,
        "description": "Measured, modelled and process current of one sample of one machine axis "
                       "(greybox predict). The sample time is the message log_time in ns.",
        "type": "object",
        "properties": {name: {"type": "number", "description": _DESCRIPTIONS.get(name, name)} for name in fields},
        "required": list(fields),
    }


def _write_mcap(results: Iterable[ProcessResult], path, metadata: Callable[[], dict]) -> None:
    """Write the result as MCAP; the channel's metadata come first, so the blocks are joined first."""
    from mcap.writer import CompressionType, Writer

    parts = list(results)
    if not parts:
        raise GreyboxError(f"{path}: nothing to write")
    described = metadata()
    result = join_results(parts, described["attrs"]) if len(parts) > 1 else parts[0]
    columns = result.columns()
    time = columns.pop("time_s")
    if time.size and time.min() < 0:
        raise GreyboxError(f"{path}: time reaches {time.min()} s; MCAP time stamps must be non-negative")
    template = "{" + ",".join(json.dumps(name).replace("%", "%%") + ":%r" for name in columns) + "}"
    rows = zip(*(values.tolist() for values in columns.values()))
    stamps = np.rint(time * 1e9).astype(np.uint64).tolist()
    with open(path, "wb") as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        writer.start(profile="", library="greybox")
        schema_id = writer.register_schema(name=PROCESS_SCHEMA_NAME, encoding="jsonschema",
                                           data=json.dumps(_schema(columns), indent=2).encode())
        channel_id = writer.register_channel(
            f"/process/{result.axis}" if result.axis else "/process", "json", schema_id,
            {"axis": result.axis, "dataset": result.dataset, "effort_unit": result.effort_unit,
             "attrs": json.dumps(described["attrs"])})
        for stamp, row in zip(stamps, rows):
            writer.add_message(channel_id, stamp, (template % row).encode(), stamp)
        writer.finish()


def write_process(result: ProcessResult, path, *, overwrite: bool = False, protect=()) -> Path:
    """Write a process table atomically; the format follows the extension.

    Parameters
    ----------
    result : ProcessResult
        What :func:`greybox.predict.process.predict_process` returned.
    path : str or path-like
        Output file (.csv, .parquet/.pq or .mcap). A CSV file's metadata go
        to its sidecar ``<path>.json``, written atomically as well.
    overwrite : bool, default False
        Replace an existing ``path`` (and sidecar).
    protect : iterable of path-like
        Files that must never be replaced (the inputs), whatever ``overwrite``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    GreyboxError
        See :func:`write_process_blocks`.
    """
    return write_process_blocks([result], path, metadata=lambda: _metadata(result), overwrite=overwrite,
                                protect=protect)


def write_process_blocks(results: Iterable[ProcessResult], path, *, metadata: Callable[[], dict],
                         overwrite: bool = False, protect=()) -> Path:
    """Write a process table given block by block, atomically, holding one block at a time (CSV, Parquet).

    Parameters
    ----------
    results : iterable of ProcessResult
        Consecutive blocks of one result (:func:`greybox.predict.process.process_blocks`); taken one at
        a time, so that a generator computes each block as it is written.
    path : str or path-like
        Output file (.csv, .parquet/.pq or .mcap; an MCAP file is written once all blocks are in).
    metadata : callable
        ``metadata()`` gives ``{"axis", "dataset", "effort_unit", "attrs"}`` once every block is through.
    overwrite, protect
        As :func:`write_process`.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    GreyboxError
        For an unknown extension, non-finite values, an existing file (or sidecar) without ``overwrite``,
        a protected file, or a missing directory; nothing is left behind then, and an older ``path`` is kept.
    """
    path = Path(path)
    fmt = output_format(path)
    for target in output_paths(path):
        check_output_path(target, overwrite=overwrite, protect=protect)
    checked = _finite(results, path)
    if fmt == "csv":
        with atomic_output(path) as temporary, atomic_output(sidecar_path(path)) as side:
            if _write_csv(checked, str(temporary)) is None:
                raise GreyboxError(f"{path}: nothing to write")
            side.write_text(sidecar_text(metadata()), encoding="utf-8")
        return path
    with atomic_output(path) as temporary:
        (_write_parquet if fmt == "parquet" else _write_mcap)(checked, str(temporary), metadata)
    return path


def _finite(results: Iterable[ProcessResult], path) -> Iterator[ProcessResult]:
    """The blocks, each checked for non-finite values (the message counts samples from the first block)."""
    offset = 0
    for result in results:
        for name, values in result.columns().items():
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                raise GreyboxError(f"{path}: column '{name}' is not finite at sample {offset + bad[0]}")
        offset += len(result.time)
        yield result
