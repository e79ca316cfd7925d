"""Prediction of long runs in chunks of bounded length, carrying the model state across chunks.

A run of an hour at 2 ms has 1.8 million samples. The dynamic models keep a
state from one sample to the next (the LuGre bristle deflection, the GMS
element deflections and stick/slip modes), and the grey-box model builds an
input matrix of ``2 + N`` columns per sample for its kernel expansion. Here a
run is cut into consecutive chunks of ``chunk_s`` seconds; each chunk starts
from the state the previous one ended in, so the result equals the one-shot
:meth:`~greybox.models.estimator.CurrentModel.predict` of the whole run, while the
model's working memory grows with the chunk length only.

Every chunk is integrated at the step of the whole run (its median time step),
not at the chunk's own median step, so that the chunking does not change the
result even for a log with jittered time stamps.

The state carried between chunks is the model's own
(:meth:`~greybox.base.ModelProtocol.initial_state`,
:meth:`~greybox.models.estimator.CurrentModel.predict_chunk`): none for the memoryless
models, the bristle deflection of LuGre, the element states of GMS (also the
frozen GMS stage of GMS+SVR), and for the models of ``greybox discover`` the
state of their base plus the start time of the run.
"""

from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

from ..data.log import AxisLog
from ..errors import ParameterError
from .estimator import check_runs

__all__ = ["DEFAULT_CHUNK_S", "samples_per_chunk", "chunk_slices", "iter_chunks", "predict_chunked"]

#: Default chunk length [s] (30 000 samples at 2 ms).
DEFAULT_CHUNK_S = 60.0


def chunk_slices(n_samples: int, chunk_samples: int) -> list[slice]:
    """Consecutive slices of at most ``chunk_samples`` samples covering ``n_samples``.

    A last chunk shorter than two samples is merged into the one before it, so
    that every chunk holds at least one time step (a run of fewer than two
    samples gives one slice).

    Parameters
    ----------
    n_samples : int
        Length of the run.
    chunk_samples : int
        Samples per chunk, at least 2.

    Returns
    -------
    list of slice
    """
    if chunk_samples < 2:
        raise ParameterError(f"a chunk must hold at least 2 samples, got {chunk_samples}")
    starts = list(range(0, n_samples, chunk_samples)) or [0]
    if len(starts) > 1 and n_samples - starts[-1] < 2:
        starts.pop()
    stops = starts[1:] + [n_samples]
    return [slice(a, b) for a, b in zip(starts, stops)]


def samples_per_chunk(sample_time: float, chunk_s: float) -> int:
    """Samples in a chunk of ``chunk_s`` seconds at step ``sample_time`` [s] (nearest whole number, at least 2).

    Parameters
    ----------
    sample_time : float
        Sample time of the run [s], positive.
    chunk_s : float
        Chunk length [s].

    Raises
    ------
    ParameterError
        Unless ``chunk_s`` is a positive number of seconds.
    """
    if not (np.isfinite(chunk_s) and chunk_s > 0.0):
        raise ParameterError(f"chunk length must be a positive number of seconds, got {chunk_s}")
    return max(2, int(round(chunk_s / sample_time)))


def iter_chunks(model, log: AxisLog, *, chunk_s: float = DEFAULT_CHUNK_S) -> Iterator[tuple[slice, np.ndarray]]:
    """Predict one run chunk by chunk; yield each chunk's samples and prediction.

    Parameters
    ----------
    model : CurrentModel
        A fitted model of a registered kind.
    log : AxisLog
        One prepared run.
    chunk_s : float, default 60.0
        Chunk length [s]; rounded to a whole number of samples (at least 2).

    Yields
    ------
    samples : slice
        The chunk's samples in ``log``.
    current : ndarray
        Predicted current of the chunk [A, or N].
    """
    (run,) = check_runs(log)
    step = run.sample_time
    state = model.initial_state()
    for samples in chunk_slices(len(run), samples_per_chunk(step, chunk_s)):
        current, state = model.predict_chunk(run.select(samples), state, sample_time=step)
        yield samples, current


def predict_chunked(model, logs: AxisLog | Iterable[AxisLog], *, chunk_s: float = DEFAULT_CHUNK_S) -> np.ndarray:
    """Predicted current of one or several runs, each computed in chunks.

    Equal to ``model.predict(logs)`` (the state restarts at each run and is
    carried across the chunks within a run), with working memory bounded by
    the chunk length.

    Parameters
    ----------
    model : CurrentModel
        A fitted model of a registered kind.
    logs : AxisLog or list of AxisLog
        Prepared runs.
    chunk_s : float, default 60.0
        Chunk length [s].

    Returns
    -------
    ndarray, shape (n_samples,)
        The prediction of each run, concatenated in order [A, or N].
    """
    runs = check_runs(logs)
    out = np.empty(sum(len(run) for run in runs))
    offset = 0
    for run in runs:
        for samples, current in iter_chunks(model, run, chunk_s=chunk_s):
            out[offset + samples.start:offset + samples.stop] = current
        offset += len(run)
    return out
