"""Prediction of long runs in chunks of bounded length, carrying the model state across chunks.

A run of an hour at 2 ms has 1.8 million samples. The dynamic models keep a
state from one sample to the next (the LuGre bristle deflection, the GMS
element deflections and stick/slip modes), and the grey-box model builds an
input matrix of ``2 + N`` columns per sample for its kernel expansion. Here a
run is cut into consecutive chunks of ``chunk_s`` seconds; each chunk starts
from the state the previous one ended in, so the result equals the one-shot
:meth:`~greybox.models.base.CurrentModel.predict` of the whole run, while the
model's working memory grows with the chunk length only.

Every chunk is integrated at the step of the whole run (its median time step),
not at the chunk's own median step, so that the chunking does not change the
result even for a log with jittered time stamps.

State carried per model kind (see :func:`initial_state`):

========== =====================================================================
kind       state between chunks
========== =====================================================================
coulomb    none (memoryless)
stribeck   none (memoryless)
svr        none (memoryless: ``f(p, v)``)
lugre      bristle deflection ``z`` [mm] (float)
gms        :class:`~greybox.friction.gms.GMSState` (deflections [mm], modes)
gmssvr     :class:`~greybox.friction.gms.GMSState` of the frozen GMS stage
augmented  ``(state of the base model, start time of the run [s])``: the model
           of ``greybox discover``, whose effects may depend on the time since
           the start of the run
========== =====================================================================
"""

from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np
from sklearn.utils.validation import check_is_fitted

from ..data.log import AxisLog
from ..errors import LogError, ParameterError
from ..friction.gms import GMSState, gms_states
from ..friction.lugre import simulate_lugre
from .base import check_runs
from .rbf import rbf_expansion
from .registry import model_kind

__all__ = ["DEFAULT_CHUNK_S", "MEMORYLESS_KINDS", "samples_per_chunk", "chunk_slices", "initial_state",
           "predict_chunk", "iter_chunks", "predict_chunked"]

#: Default chunk length [s] (30 000 samples at 2 ms).
DEFAULT_CHUNK_S = 60.0

#: Model kinds whose prediction depends on the present sample only.
MEMORYLESS_KINDS = ("coulomb", "stribeck", "svr")


def _kind(model) -> str:
    try:
        kind = model_kind(model)
    except KeyError as exc:
        raise ParameterError(f"no chunked prediction for {type(model).__name__}: {exc.args[0]}") from None
    check_is_fitted(model)
    return kind


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

    Raises
    ------
    ParameterError
        Unless ``chunk_s`` is a positive number of seconds.
    """
    if not (np.isfinite(chunk_s) and chunk_s > 0.0):
        raise ParameterError(f"chunk length must be a positive number of seconds, got {chunk_s}")
    return max(2, int(round(chunk_s / sample_time)))


def initial_state(model):
    """State of ``model`` before the first sample of a run (the state every run starts from).

    Parameters
    ----------
    model : CurrentModel
        A fitted model of a registered kind.

    Returns
    -------
    None, float, GMSState or tuple
        ``None`` for memoryless models, the bristle deflection ``0.0`` [mm]
        for LuGre, all elements at rest for GMS and GMS+SVR; for an augmented
        model ``(initial state of its base model, None)``, the run's start
        time being taken from the first chunk.
    """
    kind = _kind(model)
    if kind == "augmented":
        return initial_state(model.base_), None
    if kind == "lugre":
        return 0.0
    if kind == "gms":
        return GMSState.at_rest(len(model.alpha_))
    if kind == "gmssvr":
        return GMSState.at_rest(len(model.gms_.alpha_))
    return None


def _lugre_current(model, run: AxisLog, step: float, z0: float):
    friction, _, z_end = simulate_lugre(run.velocity, step, sigma0=model.sigma0_, sigma1=model.sigma1_,
                                        sigma2=model.viscous_, coulomb=model.coulomb_, static=model.static_,
                                        v_s=model.v_s_, z0=z0)
    return model.J_ * run.acceleration + friction + model.offset_, float(z_end)


def _gmssvr_current(model, run: AxisLog, step: float, state):
    gms = model.gms_
    gms_current, end = gms.predict_chunk(run, state, sample_time=step)
    z, _, _, _ = gms_states(run.velocity, step, alpha=gms.alpha_, C=gms.C_, s_0=gms.s0_, s_inf=gms.s_inf_,
                            v_s=gms.v_s_, state=state)
    inputs = np.column_stack((run.position, gms_current, z))
    current = rbf_expansion((inputs - model.input_mean_) / model.input_scale_, model.support_vectors_,
                            model.dual_coef_, model.intercept_, model.gamma_)
    if model.target == "residual":
        current = current + gms_current
    elif model.target != "current":
        raise ParameterError(f"GMS+SVR model with unknown target {model.target!r}")
    return current, end


def _augmented_current(model, run: AxisLog, step: float, state):
    base_state, run_start_s = state
    if run_start_s is None:
        run_start_s = float(run.time[0])
    base_current, base_end = predict_chunk(model.base_, run, base_state, sample_time=step)
    return base_current + model.added_current(run, run_start_s=run_start_s), (base_end, run_start_s)


def predict_chunk(model, log: AxisLog, state=None, *, sample_time: float | None = None):
    """Predict one chunk of a run from a given state.

    Parameters
    ----------
    model : CurrentModel
        A fitted model of a registered kind (coulomb, stribeck, lugre, gms,
        svr, gmssvr, augmented).
    log : AxisLog
        Prepared chunk: consecutive samples of one run, at least two.
    state : None, float, GMSState or tuple, optional
        State before the chunk's first sample, as returned for the previous
        chunk; default :func:`initial_state` (the start of a run).
    sample_time : float, optional
        Integration step [s] of the dynamic models; default the chunk's own
        median step. Pass the step of the whole run so that every chunk of a
        run uses the same one.

    Returns
    -------
    current : ndarray, shape (n,)
        Predicted current ``J a + friction + offset`` (or the grey-box
        output) [A, or N for force logs].
    state : None, float, GMSState or tuple
        State after the chunk's last sample: the ``state`` of the next chunk.

    Raises
    ------
    LogError
        If the chunk is not prepared, too short, not finite, or carries
        another effort unit than the model was fitted on.
    ParameterError
        For a model class that is not registered, or a state of the wrong shape.
    """
    kind = _kind(model)
    if kind in MEMORYLESS_KINDS:
        return model.predict(log), None
    (run,) = check_runs(log)
    if run.effort_unit != model.effort_unit_:
        raise LogError(run.source or None,
                       f"log carries effort in {run.effort_unit}, the model was fitted on {model.effort_unit_}")
    step = run.sample_time if sample_time is None else float(sample_time)
    if state is None:
        state = initial_state(model)
    if kind == "lugre":
        return _lugre_current(model, run, step, float(state))
    if kind == "gms":
        return model.predict_chunk(run, state, sample_time=step)
    if kind == "augmented":
        return _augmented_current(model, run, step, state)
    return _gmssvr_current(model, run, step, state)


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
    state = initial_state(model)
    for samples in chunk_slices(len(run), samples_per_chunk(step, chunk_s)):
        current, state = predict_chunk(model, run.select(samples), state, sample_time=step)
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
