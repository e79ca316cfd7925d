"""Calibrated intervals of the process current: split-conformal per operating regime.

On a cutting log the process current ``measured - model`` misses the true
process current by the model's air-cut error on that sample, noise included:

    I_process_estimated - I_process_true = I_air_measured - I_model.

Residuals of the model on air cuts it was *not* trained on are draws of that
error, so their quantiles bound it (split conformal prediction): with ``n``
calibration residuals, the ``ceil((n + 1) c)``-th smallest ``|r|`` is a
half-width that covers a new sample's error with probability at least ``c``
when the samples are exchangeable. The error is larger at reversals and
while the axis accelerates than at constant feed, so the half-width is taken
per regime: every sample falls in exactly one class, in this order,
``reversal``, ``acceleration``, ``constant_feed``, ``other`` (slow motion,
standstill, feeds shorter than a regime's minimum), with the regime
thresholds of the calibration logs (:mod:`greybox.evaluate.regimes`).

Neighbouring samples are not independent, so the guarantee holds for the
share of samples covered over a long log rather than sample by sample, and
only while the cutting log moves like the calibration logs: calibrate on air
cuts that cover the cutting programme's positions, speeds and reversals.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Sequence

import numpy as np

from ..data.log import AxisLog, as_log_list
from ..data.quantities import MOTIONS
from ..errors import GreyboxError
from ..evaluate.regimes import RegimeThresholds, regime_masks
from ..models.chunked import predict_chunked

__all__ = ["DEFAULT_COVERAGE", "INTERVAL_CLASSES", "MIN_CLASS_SAMPLES", "ProcessInterval", "interval_classes",
           "calibrate_interval"]

#: Nominal coverage of the bounds when calibration logs are given without a coverage.
DEFAULT_COVERAGE = 0.95

#: The classes of samples that get their own half-width, in the order a sample is assigned.
INTERVAL_CLASSES = ("reversal", "acceleration", "constant_feed", "other")

#: Fewest calibration samples of a class for a half-width of its own; a smaller class takes that of all.
MIN_CLASS_SAMPLES = 200


def interval_classes(log: AxisLog, thresholds: RegimeThresholds) -> np.ndarray:
    """Index into :data:`INTERVAL_CLASSES` of every sample of one prepared run.

    Parameters
    ----------
    log : AxisLog
        Prepared run.
    thresholds : RegimeThresholds
        Regime thresholds (those of the calibration logs) that define the classes.

    Returns
    -------
    ndarray of int64, shape (n,)
        Class index of every sample; a sample in several regimes takes the first class listed.
    """
    masks = regime_masks(log, thresholds)
    out = np.full(len(log), len(INTERVAL_CLASSES) - 1, dtype=np.int64)
    for index in reversed(range(len(INTERVAL_CLASSES) - 1)):  # the first class listed wins
        out[masks[INTERVAL_CLASSES[index]]] = index
    return out


def _conformal_half_width(errors: np.ndarray, coverage: float) -> float:
    """``ceil((n + 1) c)``-th smallest ``|error|``; the largest if that rank exceeds ``n``."""
    magnitudes = np.sort(np.abs(errors))
    rank = math.ceil((magnitudes.size + 1) * coverage)
    return float(magnitudes[min(rank, magnitudes.size) - 1])


@dataclass(frozen=True)
class ProcessInterval:
    """Half-widths [A] of the interval of the process current, per class of samples.

    Attributes
    ----------
    coverage : float
        Nominal coverage, in (0, 1).
    half_width_A : dict of str to float
        Half-width [A] (or [N] for a force log) per name of :data:`INTERVAL_CLASSES`.
    samples : dict of str to int
        Calibration samples per class; a class with fewer than
        :data:`MIN_CLASS_SAMPLES` took the half-width of all samples.
    thresholds : RegimeThresholds
        Regime thresholds of the calibration logs.
    sources : tuple of str
        Calibration logs.
    motion : str, default "linear"
        Kind of axis of the calibration logs: the thresholds are in mm/s, or deg/s for ``"rotary"``.
    """

    coverage: float
    half_width_A: dict
    samples: dict
    thresholds: RegimeThresholds
    sources: tuple = ()
    motion: str = "linear"

    def half_widths(self, log: AxisLog) -> np.ndarray:
        """Half-width [A] at every sample of one prepared run.

        Parameters
        ----------
        log : AxisLog
            Prepared run; its samples are classed with the calibration thresholds.

        Returns
        -------
        ndarray, shape (n,)
            Half-width [A] (or [N] for a force log) of the class of every sample.
        """
        table = np.array([self.half_width_A[name] for name in INTERVAL_CLASSES])
        return table[interval_classes(log, self.thresholds)]

    def to_dict(self) -> dict:
        """JSON-able description (for output metadata)."""
        relabel = MOTIONS[self.motion].relabel  # thresholds named in mm/s; deg/s on a rotary axis
        return {"coverage": self.coverage, "method": "split conformal per regime",
                "half_width": dict(self.half_width_A), "calibration_samples": dict(self.samples),
                "thresholds": {relabel(name): value for name, value in asdict(self.thresholds).items()},
                "calibration_logs": list(self.sources)}


def calibrate_interval(model, logs: AxisLog | Sequence[AxisLog], *, coverage: float = DEFAULT_COVERAGE,
                       chunk_s: float = 60.0) -> ProcessInterval:
    """Half-widths of the process-current interval from a model's residuals on held-out air cuts.

    Parameters
    ----------
    model : CurrentModel
        The fitted model.
    logs : AxisLog or sequence of AxisLog
        Prepared air-cut runs the model was not trained on.
    coverage : float, default 0.95
        Nominal coverage, in (0, 1).
    chunk_s : float, default 60.0
        Chunk length [s] of the prediction (:func:`~greybox.models.chunked.predict_chunked`).

    Returns
    -------
    ProcessInterval

    Raises
    ------
    GreyboxError
        For a coverage outside (0, 1), or fewer calibration samples than
        :data:`MIN_CLASS_SAMPLES`.
    """
    if not 0.0 < coverage < 1.0:
        raise GreyboxError(f"interval coverage must be a fraction in (0, 1), got {coverage}")
    runs = as_log_list(logs)
    if sum(len(run) for run in runs) < MIN_CLASS_SAMPLES:
        raise GreyboxError(f"calibration: {sum(len(run) for run in runs)} air-cut samples, fewer than the "
                           f"{MIN_CLASS_SAMPLES} an interval needs")
    thresholds = RegimeThresholds.from_logs(runs)
    errors = np.concatenate([run.effort for run in runs]) - predict_chunked(model, runs, chunk_s=chunk_s)
    classes = np.concatenate([interval_classes(run, thresholds) for run in runs])
    overall = _conformal_half_width(errors, coverage)
    half, samples = {}, {}
    for index, name in enumerate(INTERVAL_CLASSES):
        chosen = errors[classes == index]
        samples[name] = int(chosen.size)
        half[name] = _conformal_half_width(chosen, coverage) if chosen.size >= MIN_CLASS_SAMPLES else overall
    return ProcessInterval(coverage=float(coverage), half_width_A=half, samples=samples, thresholds=thresholds,
                           sources=tuple(run.source or "" for run in runs), motion=runs[0].motion)
