"""Logs of any length, read and prepared block by block in bounded memory.

A log of an hour at 500 Hz holds 1.8 million samples; a plant keeps logs of a shift or a day. For a
Parquet log of one linear axis with a time column, :func:`prepared_blocks` gives the same prepared run
as :func:`greybox.data.io.read_log` followed by :func:`greybox.data.prepare.prepare`, in consecutive
blocks, while holding only a few blocks at a time. It reads the file three times:

1. the time column: finite and strictly increasing (the error names the sample), and the time steps
   counted by the upper 32 bits of their floating-point pattern (for positive numbers the order of the
   patterns is the order of the numbers);
2. the time column again: the steps in the one or two counts that hold the middle of the sorted steps,
   counted by value, which gives the exact median step, the nominal sample time that the whole-log
   preparation takes (:attr:`greybox.data.log.AxisLog.sample_time`);
3. every column, block by block: steps within the tolerance of the nominal step, finite values, the
   velocity's unit (:func:`~greybox.data.validate.check_velocity_units`, block by block), and the
   derivatives of :func:`~greybox.data.prepare.derive` over the block with
   :func:`~greybox.data.prepare.derivative_margin` samples of its neighbours on each side, so that the
   forward-backward filter sees enough of the log to give, inside the block, the whole-log result.

Other logs (CSV, MCAP, TDMS, MATLAB, rotary axes, logs without a time column, logs to be resampled)
are read whole: :func:`open_stream` says which are streamed.
"""

from __future__ import annotations

import os
from typing import Iterable, Iterator, Mapping

import numpy as np

from ..errors import LogError
from .blocks import concatenate, reblock
from .log import AxisLog
from .parquet_io import column_arrays, schema_fields, unreadable
from .prepare import derivative_margin, derive
from .units import NO_TIME_COLUMN, log_from_columns, resolve_columns, select_axis
from .validate import check_finite, check_increasing, check_time, check_time_units, check_velocity_units

__all__ = ["DEFAULT_BLOCK_SAMPLES", "STREAM_SUFFIXES", "ParquetLog", "median_step", "open_stream",
           "prepared_blocks"]

#: Samples per block (4 min 22 s at 2 ms).
DEFAULT_BLOCK_SAMPLES = 1 << 15

#: File extensions of the logs read block by block.
STREAM_SUFFIXES = (".parquet", ".pq", ".mcap")

#: Distinct time steps counted one by one; beyond, the steps are counted by their upper bits (two passes).
_MAX_DISTINCT_STEPS = 1 << 16

#: Bytes read from the file at a time.
_READ_BUFFER_BYTES = 1 << 20


def open_stream(path, *, columns: Mapping[str, str] | None = None, topic: str | None = None,
                axis: str | None = None, sample_time: float | None = None, resample: float | None = None,
                block_samples: int = DEFAULT_BLOCK_SAMPLES):
    """A :class:`ParquetLog` or :class:`~greybox.data.mcap_io.McapLog` of a log read block by block; None when
    the log is to be read whole.

    Read whole: formats other than Parquet and MCAP, logs to be given a sample time or resampled, a
    Parquet log with a topic (to be refused where it is read), a path that is not a non-empty file (the
    error is given where it is read), and rotary axes (a modulo axis is unwrapped
    over the whole log).

    Parameters
    ----------
    path : str or path-like
        Log file.
    columns : mapping of str to str, optional
        Column (field) mapping.
    topic : str, optional
        MCAP channel.
    axis : str, optional
        Axis to read from a log of several.
    sample_time : float, optional
        The ``--sample-time`` of a log without time column.
    resample : float, optional
        The ``--resample`` step.
    block_samples : int, default :data:`DEFAULT_BLOCK_SAMPLES`
        Samples per block.

    Raises
    ------
    LogError
        For a file that cannot be read as the log it claims to be.
    """
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in STREAM_SUFFIXES or sample_time is not None or resample is not None or \
            (topic is not None and suffix != ".mcap"):
        return None
    if not os.path.isfile(path) or os.path.getsize(path) == 0:
        return None  # missing, a directory or empty: read_log names the problem
    if suffix == ".mcap":
        from .mcap_io import McapLog

        log = McapLog(path, columns=columns, topic=topic, axis=axis, block_samples=block_samples)
    else:
        log = ParquetLog(path, columns=columns, axis=axis, block_samples=block_samples)
    return log if log.motion == "linear" else None


class ParquetLog:
    """A Parquet axis log read in blocks of rows, converted as :func:`greybox.data.io.read_log` converts it.

    Parameters
    ----------
    path : str or path-like
        Parquet file with a time column.
    columns : mapping of str to str, optional
        ``{canonical_name: column}`` for columns not named by the convention.
    axis : str, optional
        Axis to read from a file holding several (columns ``<axis>_<quantity>_<unit>``).
    block_samples : int, default :data:`DEFAULT_BLOCK_SAMPLES`
        Rows per block.

    Attributes
    ----------
    n_samples : int
        Rows in the file.
    motion : str
        "linear" or "rotary", from the units of the columns.
    axis : str
        The log's axis name (the ``axis`` read, else the file's metadata; "" if neither names one).

    Raises
    ------
    LogError
        For a file that is not Parquet, holds no rows, lacks required columns or a time column.
    """

    def __init__(self, path, *, columns: Mapping[str, str] | None = None, axis: str | None = None,
                 block_samples: int = DEFAULT_BLOCK_SAMPLES):
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.path = os.fspath(path)
        self.columns = dict(columns) if columns else None
        self._select = axis
        self.block_samples = int(block_samples)
        try:
            # column chunks read through a small buffer: a row group need not fit in memory at once
            self._file = pq.ParquetFile(self.path, pre_buffer=False, buffer_size=_READ_BUFFER_BYTES)
        except (pa.ArrowException, OSError) as exc:
            raise unreadable(self.path, exc) from None
        self.n_samples = self._file.metadata.num_rows
        if self.n_samples == 0:
            raise LogError(self.path, "no data rows")
        self._metadata = schema_fields(self._file.schema_arrow, self.path, axis)
        names = self._file.schema_arrow.names
        shapes = {name: np.empty(0) for name in names}
        selected = select_axis(shapes, axis, source=self.path, columns=self.columns) if axis is not None else shapes
        found, self.motion = resolve_columns(
            [name for name in selected if name and not str(name).startswith("Unnamed: ")], source=self.path,
            columns=self.columns, effort_unit=self._metadata.get("effort_unit"))
        if "time" not in found:
            raise LogError(self.path, *NO_TIME_COLUMN)
        self._time_column, self._time_factor = found["time"]
        self.axis = axis if axis is not None else str(self._metadata.get("axis", ""))

    def times(self) -> Iterator[np.ndarray]:
        """The time column [s], block by block."""
        for batch in self._file.iter_batches(batch_size=self.block_samples, columns=[self._time_column]):
            values = np.asarray(batch.column(0).to_numpy(zero_copy_only=False), dtype=np.float64)
            yield values * self._time_factor if self._time_factor != 1.0 else values

    def blocks(self, block_samples: int | None = None) -> Iterator[AxisLog]:
        """The log, block by block (the last may be shorter), converted but not validated.

        Parameters
        ----------
        block_samples : int, optional
            Samples per block; default :attr:`block_samples`.
        """
        size = self.block_samples if block_samples is None else int(block_samples)
        yield from reblock((self._convert(batch) for batch in self._file.iter_batches(batch_size=size)), size)

    def time_span(self) -> tuple[float, float]:
        """Times of the first and the last sample [s]."""
        groups = self._file.metadata.num_row_groups
        first = self._file.read_row_group(0, columns=[self._time_column]).column(0)
        last = self._file.read_row_group(groups - 1, columns=[self._time_column]).column(0)
        return (float(first[0].as_py()) * self._time_factor, float(last[-1].as_py()) * self._time_factor)

    def _convert(self, batch) -> AxisLog:
        return log_from_columns(column_arrays(batch.schema.names, batch.columns), source=self.path,
                                columns=self.columns, select=self._select, **self._metadata)



def _steps(times: Iterable[np.ndarray], source) -> Iterator[np.ndarray]:
    """The time steps [s] of consecutive blocks of time stamps, checked strictly increasing and finite."""
    last = None
    index = 0
    for time in times:
        joined = time if last is None else np.concatenate(([last], time))
        start = index if last is None else index - 1
        if len(joined) < 2 and last is None:
            last, index = (float(time[-1]) if len(time) else None), index + len(time)
            continue
        yield check_increasing(joined, source=source, start=start)
        last = float(joined[-1])
        index += len(time)
    if index < 2:
        check_increasing(np.full(index, 0.0), source=source)  # the message for a log of 0 or 1 samples


def _add_counts(keys, counts, values):
    """``keys`` and ``counts`` with the distinct ``values`` counted in."""
    new_keys, new_counts = np.unique(values, return_counts=True)
    if keys is None:
        return new_keys, new_counts
    merged, inverse = np.unique(np.concatenate((keys, new_keys)), return_inverse=True)
    return merged, np.bincount(inverse, weights=np.concatenate((counts, new_counts))).astype(np.int64)


def _value_at(keys, counts, rank: int):
    """The ``rank``-th (0-based) of the sorted values counted in ``keys``/``counts``; and its bucket start."""
    ends = np.cumsum(counts)
    position = int(np.searchsorted(ends, rank, side="right"))
    before = int(ends[position - 1]) if position else 0
    return keys[position], rank - before


def median_step(times, source=None) -> float:
    """The median of the time steps of a log given block by block, exactly as :func:`numpy.median` gives it.

    The steps are counted by value while they take few distinct values (a uniform log: one pass over the
    time stamps); otherwise by the upper 32 bits of their floating-point pattern, and a second pass counts
    by value the steps of the one or two counts that hold the middle of the sorted steps.

    Parameters
    ----------
    times : callable
        ``times()`` gives an iterator over the time stamps [s] block by block; it is called once or twice.
    source : str, optional
        Log named in error messages.

    Returns
    -------
    float
        Median step [s].

    Raises
    ------
    LogError
        For fewer than 2 samples, or times not finite and strictly increasing (the message names the sample).
    """
    keys = counts = None
    n_steps = 0
    shift = np.uint64(0)  # 0: counted by value; 32: by the upper bits
    for steps in _steps(times(), source):
        keys, counts = _add_counts(keys, counts, steps.view(np.uint64) >> shift)
        n_steps += steps.size
        if not shift and keys.size > _MAX_DISTINCT_STEPS:
            shift = np.uint64(32)
            keys, counts = _add_counts(None, None, np.repeat(keys >> shift, counts))
    middle = sorted({(n_steps - 1) // 2, n_steps // 2})
    if not shift:
        values = [_value_at(keys, counts, rank)[0].view(np.float64) for rank in middle]
        return float(values[0]) if len(values) == 1 else float(np.mean(values))
    buckets = [_value_at(keys, counts, rank) for rank in middle]
    wanted = np.array(sorted({bucket for bucket, _ in buckets}), dtype=np.uint64)
    exact_keys = exact_counts = None
    for steps in _steps(times(), source):
        inside = steps[np.isin(steps.view(np.uint64) >> shift, wanted)]
        if inside.size:
            exact_keys, exact_counts = _add_counts(exact_keys, exact_counts, inside)
    offset = int(np.sum(counts[:int(np.searchsorted(keys, wanted[0]))]))  # steps below the first wanted count
    values = [_value_at(exact_keys, exact_counts, rank - offset)[0] for rank in middle]
    return float(values[0]) if len(values) == 1 else float(np.mean(values))


def prepared_blocks(log, *, tolerance: float = 0.25, cutoff_hz: float | None = None,
                    sample_time: float | None = None, block_samples: int | None = None) -> Iterator[AxisLog]:
    """The prepared run of a log, block by block: what :func:`greybox.data.prepare.prepare` gives for it whole.

    Parameters
    ----------
    log : ParquetLog or McapLog
        The log (:func:`open_stream`).
    tolerance : float, default 0.25
        Time-step tolerance (see :func:`~greybox.data.validate.check_time`).
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz]; default :func:`~greybox.data.prepare.default_cutoff`.
    sample_time : float, optional
        The log's median step [s] if known (:func:`median_step`); computed otherwise.
    block_samples : int, optional
        Samples per block (default the log's); at least the filter's margin on each side.

    Yields
    ------
    AxisLog
        Consecutive prepared blocks (velocity and acceleration present).

    Raises
    ------
    LogError
        As :func:`greybox.data.io.read_log` and :func:`greybox.data.prepare.prepare` would for the whole log.
    """
    source = log.path
    nominal = median_step(log.times, source) if sample_time is None else float(sample_time)
    if sample_time is None:
        check_time_units(np.array([0.0, nominal]), source=source)
    margin = derivative_margin(nominal, cutoff_hz=cutoff_hz)
    tail: AxisLog | None = None  # the last `margin` samples before the current block
    current: AxisLog | None = None
    read = 0  # samples read before `block`
    for block in log.blocks(max(log.block_samples if block_samples is None else block_samples, margin)):
        if read:  # the step from the previous block's last sample counts too
            check_time(np.concatenate(([current.time[-1]], block.time)), source=source, tolerance=tolerance,
                       nominal=nominal, start=read - 1)
        elif len(block) >= 2:
            check_time(block.time, source=source, tolerance=tolerance, nominal=nominal)
        check_finite(block, start=read)
        check_velocity_units(block)
        if current is not None:
            yield _prepared(current, tail, block, margin, nominal, tolerance, cutoff_hz)
            tail = concatenate([tail, current] if tail is not None else [current])
            tail = tail.select(slice(max(0, len(tail) - margin), None))
        current = block
        read += len(block)
    yield _prepared(current, tail, None, margin, nominal, tolerance, cutoff_hz)


def _prepared(block: AxisLog, before: AxisLog | None, after: AxisLog | None, margin: int, nominal: float,
              tolerance: float, cutoff_hz) -> AxisLog:
    """``block`` prepared with up to ``margin`` samples of the log on each side."""
    pieces = ([before] if before is not None else []) + [block]
    if after is not None:
        pieces.append(after.select(slice(0, margin)))
    window = derive(concatenate(pieces), cutoff_hz=cutoff_hz, tolerance=tolerance, sample_time=nominal)
    first = len(before) if before is not None else 0
    return window.select(slice(first, first + len(block)))
