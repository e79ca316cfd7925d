"""The process table of a log of any length, read, predicted and written block by block.

:func:`stream_process` does for a log that :func:`greybox.data.stream.open_stream` reads block by block
what :func:`~greybox.predict.process.predict_process` followed by
:func:`~greybox.predict.output.write_process` does for a log in memory, with the same table and
metadata, while holding a few blocks of the log at a time: the log is prepared block by block
(:func:`greybox.data.stream.prepared_blocks`), each block predicted from the state the previous one
ended in (:func:`~greybox.predict.process.process_blocks`) and written as it comes
(:func:`~greybox.predict.output.write_process_blocks`); the figures ``greybox predict`` prints are
counted on the way (:class:`~greybox.predict.process.ProcessTally`).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain
from typing import Callable

from threadpoolctl import threadpool_limits

from ..data.axis_config import AxisConfig
from ..data.effort import effort_quantity
from ..data.stream import median_step, prepared_blocks
from ..models.chunked import DEFAULT_CHUNK_S, chunk_slices, samples_per_chunk
from .interval import ProcessInterval
from .output import write_process_blocks
from .process import ProcessTally, check_process_inputs, process_attrs, process_blocks
from .relevel import Relevel

__all__ = ["StreamedProcess", "stream_process"]


@dataclass(frozen=True)
class StreamedProcess:
    """What :func:`stream_process` wrote, and the figures of it.

    Attributes
    ----------
    tally : ProcessTally
        Running figures of the whole table.
    metadata : dict
        ``{"axis", "dataset", "effort_unit", "attrs"}`` as written.
    motion : str
        "linear" or "rotary".
    sample_time : float
        Nominal step [s] (the median step).
    start_s, stop_s : float
        Times of the first and last sample [s].
    n_chunks : int
        Chunks the model ran over.
    """

    tally: ProcessTally
    metadata: dict
    motion: str
    sample_time: float
    start_s: float
    stop_s: float
    n_chunks: int

    @property
    def duration(self) -> float:
        """Time from the first to the last sample [s]."""
        return self.stop_s - self.start_s


def stream_process(model, log, out, *, axis_config: AxisConfig | None = None,
                   interval: ProcessInterval | None = None, chunk_s: float = DEFAULT_CHUNK_S,
                   tolerance: float = 0.25, cutoff_hz: float | None = None, attrs: dict | None = None,
                   overwrite: bool = False, protect=(),
                   progress: Callable[[int, int, float], None] | None = None,
                   relevel: bool = False) -> StreamedProcess:
    """Predict a log block by block and write its process table (CSV, Parquet or MCAP) atomically.

    Parameters
    ----------
    model : CurrentModel
        A fitted model (trained on air cuts) of a registered kind.
    log : ParquetLog or McapLog
        The cutting log (:func:`greybox.data.stream.open_stream`).
    out : str or path-like
        Output table; see :func:`~greybox.predict.output.write_process_blocks`.
    axis_config : AxisConfig, optional
        Drive-train constants; gives the process force.
    interval : ProcessInterval, optional
        Calibrated half-widths; gives the bounds.
    chunk_s : float, default 60.0
        Chunk length [s] of the model.
    tolerance : float, default 0.25
        Time-step tolerance of the log.
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz].
    attrs : dict, optional
        Further entries of the table's ``attrs`` (e.g. the model and log file).
    overwrite : bool, default False
        Replace an existing ``out``.
    protect : iterable of path-like
        Files never to replace (the inputs).
    progress : callable, optional
        Called after each chunk as ``progress(done, chunks, time_s)``.
    relevel : bool, default False
        Scale the model's current per chunk and direction to the log's air moves (:mod:`greybox.predict.relevel`);
        the factors go to the table's ``attrs["relevel"]``.

    Returns
    -------
    StreamedProcess

    Raises
    ------
    LogError, GreyboxError
        As reading, preparing, predicting and writing the log whole would; no output is left then.
    """
    nominal = median_step(log.times, log.path)  # before anything is written: CannotStream falls back here
    start_s, stop_s = log.time_span()
    n_chunks = len(chunk_slices(log.n_samples, samples_per_chunk(nominal, chunk_s)))
    blocks = prepared_blocks(log, tolerance=tolerance, cutoff_hz=cutoff_hz, sample_time=nominal,
                             block_samples=_aligned(log.block_samples, nominal, chunk_s))
    first = next(blocks)
    check_process_inputs([first], axis_config)
    tally = ProcessTally()
    done = [0]

    def step(time_s: float) -> None:
        done[0] += 1
        progress(done[0], n_chunks, time_s)

    level = Relevel(sample_time=nominal) if relevel else None
    results = process_blocks(model, chain([first], blocks), sample_time=nominal, axis_config=axis_config,
                             interval=interval, chunk_s=chunk_s, tally=tally,
                             progress=None if progress is None else step, relevel=level, read_ahead=True)
    described: dict = {}

    def metadata() -> dict:
        table_attrs = process_attrs(model, axis_config=axis_config, interval=interval, chunk_s=chunk_s,
                                    motion=first.motion, effort_unit=first.effort_unit, tally=tally,
                                    effort=effort_quantity(first))
        table_attrs.update(attrs or {})
        if level is not None:
            table_attrs["relevel"] = level.chunks_
        described.update({"axis": first.axis or (axis_config.name if axis_config is not None else ""),
                          "dataset": first.dataset or "", "effort_unit": first.effort_unit, "attrs": table_attrs})
        return described

    # one BLAS thread: its idle threads spin, taking the cores from the kernel sums' own threads
    with threadpool_limits(limits=1, user_api="blas"):
        write_process_blocks(results, out, metadata=metadata, overwrite=overwrite, protect=protect)
    return StreamedProcess(tally=tally, metadata=described, motion=first.motion, sample_time=nominal,
                           start_s=start_s, stop_s=stop_s, n_chunks=n_chunks)


def _aligned(block_samples: int, sample_time: float, chunk_s: float) -> int:
    """``block_samples`` rounded up to whole chunks, so that the blocks cut the log where the chunks do."""
    chunk = samples_per_chunk(sample_time, chunk_s)
    return max(1, -(-block_samples // chunk)) * chunk
