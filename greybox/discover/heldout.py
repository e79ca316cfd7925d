"""Held-out evidence: does a term lower the error on training data it was not fitted on?

The null test of :mod:`greybox.discover.evidence` asks whether a candidate
explains more of the residual than it would explain of noise. When the base
model fits the true friction law only approximately (the normal case on a real
drive), the residual holds deterministic misfit, and a scan over many periods
or time constants finds *something* in it that beats noise. Such a fit does
not carry over to other stretches of the log; a missing physical effect does.

:class:`HeldOutTest` cuts the training runs into ``K`` contiguous blocks of
time (:func:`block_labels`). For every block ``k`` the model's linear columns
and the candidate's columns are fitted on the other blocks, the candidate's
shape (period, time constant, Stribeck velocity) chosen again on those blocks
only, and both fits predict block ``k``. The *held-out gain* is the fraction
of the held-out residual sum of squares the candidate removes, pooled over the
blocks::

    gain = sum_k (S0_k - S1_k) / sum_k S0_k

(``S0_k``, ``S1_k`` the held-out sums of squares without and with the
candidate); its uncertainty is the standard error of the per-block gains
``(S0_k - S1_k) / mean_k S0_k``. A term passes when

1. ``gain`` exceeds a margin: the larger of ``min_gain`` (a gain too small to
   be worth a name) and the 95 % quantile of the same statistic on noise like
   the residual (:class:`~greybox.discover.noise.ResidualNoise`), which
   calibrates the margin for the term's flexibility (a scan over thousands of
   periods overfits more than one fixed column);
2. the gain holds across the log, not in one stretch: it is positive on at
   least ``K - 1`` of the ``K`` blocks (blocks differ in what they excite, so
   their gains differ in size; their sign is what a term that does not carry
   over gets wrong);
3. for a periodic effect, what one direction of travel shows predicts the
   other: fitted on the samples moving one way (its columns zero elsewhere,
   the model's columns on all samples), the term lowers the residual of the
   samples moving the other way, for both directions. A ripple along a screw
   repeats in both directions; misfit left after reversals does not.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import scipy.linalg

from ..data.log import AxisLog, split_runs
from ..errors import GreyboxError
from ..identify.projection import Nuisance, PositionScan, added_squares
from ..models.effects import Effect, EffectContext, scan_periods
from .noise import ResidualNoise

__all__ = ["HeldOutGain", "HeldOutTest", "block_labels", "DEFAULT_BLOCKS", "DEFAULT_MIN_GAIN"]

#: Contiguous blocks of time the training runs are cut into.
DEFAULT_BLOCKS = 5
#: Smallest held-out gain worth a name: 2 % of the held-out residual's sum of squares (1 % of its RMS).
DEFAULT_MIN_GAIN = 0.02
#: Replicates of noise like the residual that calibrate each term's margin.
DEFAULT_NULL_REPLICATES = 19
#: Level of the null margin.
_LEVEL = 0.95
#: Ridge on the unit-norm columns' Gram matrix in the held-out fits.
_RIDGE = 1e-4
#: Samples whose direction factor ``|tanh(v / v_e)|`` exceeds this count as moving one way.
_MOVING = 0.5


def block_labels(runs: Sequence[AxisLog], n_blocks: int) -> np.ndarray:
    """Block index of every sample: the runs' samples in order, cut into ``n_blocks`` contiguous stretches.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs (concatenated in order).
    n_blocks : int
        Number of blocks, at least 2.

    Returns
    -------
    ndarray of int, shape (n_samples,)
    """
    n = sum(len(run) for run in runs)
    if not isinstance(n_blocks, (int, np.integer)) or n_blocks < 2:
        raise GreyboxError(f"held-out blocks must be an integer of at least 2, got {n_blocks!r}")
    if n < 20 * n_blocks:
        raise GreyboxError(f"{n} training samples are too few for {n_blocks} held-out blocks")
    return np.minimum((np.arange(n) * n_blocks) // n, n_blocks - 1)


@dataclass
class HeldOutGain:
    """Held-out evidence for one term.

    Attributes
    ----------
    gain : float
        Fraction of the held-out residual sum of squares the term removes, pooled over the blocks.
    uncertainty : float
        Standard error of ``gain`` (from the per-block gains).
    positive_blocks : int
        Blocks on which the gain is positive.
    margin : float
        The gain needed: ``max(min_gain, null_q95)``.
    null_q95 : float or None
        95 % quantile of the gain on noise like the residual (None when not calibrated).
    blocks : list of float
        Per-block gains ``(S0_k - S1_k) / mean S0``.
    shapes : list of float or None
        The term's shape chosen on each block's complement (None without a shape).
    direction_transfer : dict or None
        Periodic effects: ``{"positive_to_negative", "negative_to_positive"}`` gains.
    passes : bool
        All conditions hold.
    reasons : list of str
        One line per condition that fails (empty when it passes).
    """

    gain: float
    uncertainty: float
    positive_blocks: int
    margin: float
    null_q95: float | None
    blocks: list
    shapes: list
    direction_transfer: dict | None = None
    passes: bool = False
    reasons: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-able summary."""
        return {"gain": self.gain, "uncertainty": self.uncertainty, "positive_blocks": self.positive_blocks,
                "margin": self.margin, "null_q95": self.null_q95, "blocks": self.blocks, "shapes": self.shapes,
                "direction_transfer": self.direction_transfer, "passes": self.passes,
                "reasons": list(self.reasons)}


def _solve(design: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Least-squares coefficients, the columns scaled to unit norm and lightly ridge-regularised.

    The ridge (:data:`_RIDGE` on the unit diagonal) damps only directions the
    columns hardly span: nearly collinear columns would otherwise cancel on the
    fitted blocks with huge opposite coefficients that do not cancel on the
    held-out one.
    """
    norms = np.linalg.norm(design, axis=0)
    norms = np.where(norms > 0.0, norms, 1.0)
    scaled = design / norms
    gram = scaled.T @ scaled + _RIDGE * np.eye(scaled.shape[1])
    coefficients = scipy.linalg.solve(gram, scaled.T @ target, assume_a="pos")
    return coefficients / (norms[:, None] if coefficients.ndim == 2 else norms)


class HeldOutTest:
    """Blocked cross-validation of candidate terms on top of a model's linear columns.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs.
    columns : ndarray, shape (n, q)
        The model's linear columns (refitted with every term), over all runs.
    target : ndarray, shape (n,)
        The effort minus the model's fixed part.
    context : EffectContext
        Scales of the effect regressors.
    n_blocks : int, default 5
        Blocks of time (:func:`block_labels`).
    min_gain : float, default 0.02
        Smallest held-out gain worth a name (fraction of the held-out sum of squares).
    n_null : int, default 19
        Replicates of noise like the residual for each term's margin (0: margin = ``min_gain``).
    rng : numpy.random.Generator, optional
        Source of the null replicates.
    """

    def __init__(self, runs: Sequence[AxisLog], columns: np.ndarray, target: np.ndarray, context: EffectContext, *,
                 n_blocks: int = DEFAULT_BLOCKS, min_gain: float = DEFAULT_MIN_GAIN,
                 n_null: int = DEFAULT_NULL_REPLICATES, rng: np.random.Generator | None = None):
        if not 0.0 <= min_gain < 1.0:
            raise GreyboxError(f"min_gain must be in [0, 1), got {min_gain!r}")
        self.runs = list(runs)
        self.columns = np.asarray(columns, dtype=float)
        self.target = np.asarray(target, dtype=float)
        self.context = context
        self.labels = block_labels(self.runs, n_blocks)
        self.n_blocks = n_blocks
        self.min_gain = float(min_gain)
        self.n_null = int(n_null)
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self._folds = []
        for k in range(n_blocks):
            train = self.labels != k
            nuisance = Nuisance(self.columns[train])
            self._folds.append((train, ~train, nuisance))
        self._null = None

    # ------------------------------------------------------------------ noise like the residual
    def _null_targets(self) -> np.ndarray:
        if self._null is None:
            if self.n_null == 0:
                self._null = np.empty((self.target.size, 0))
            else:
                residual = Nuisance(self.columns).project(self.target[:, None]).ravel()
                noise = ResidualNoise.fit(split_runs(self.runs, residual), [run.sample_time for run in self.runs])
                self._null = np.vstack(noise.simulate(self.n_null, self.rng))
        return self._null

    # ------------------------------------------------------------------ the statistic
    def _fold_gains(self, build: Callable[[float | None], np.ndarray], chooser, shapes: Sequence,
                    targets: np.ndarray):
        """Held-out sums of squares without and with the term, per fold and target, and the chosen shapes.

        ``chooser(train_rows, nuisance, targets_perp)`` gives the index into ``shapes`` for every target.
        """
        n_targets = targets.shape[1]
        without = np.empty((self.n_blocks, n_targets))
        with_term = np.empty((self.n_blocks, n_targets))
        chosen = np.empty((self.n_blocks, n_targets), dtype=np.int64)
        for k, (train, held, nuisance) in enumerate(self._folds):
            base_coefficients = _solve(self.columns[train], targets[train])
            base_residual = targets[held] - self.columns[held] @ base_coefficients
            without[k] = np.sum(base_residual ** 2, axis=0)
            chosen[k] = chooser(train, nuisance, nuisance.project(targets[train]))
            for index in np.unique(chosen[k]):
                which = np.flatnonzero(chosen[k] == index)
                design = np.hstack((self.columns, build(shapes[index])))
                coefficients = _solve(design[train], targets[train][:, which])
                residual = targets[held][:, which] - design[held] @ coefficients
                with_term[k, which] = np.sum(residual ** 2, axis=0)
        return without, with_term, chosen

    def _chooser(self, term: Effect, grid: np.ndarray, frequency_step: float | None):
        """``choose(train_rows, nuisance, targets_perp) -> index into grid`` per target."""
        if grid.size == 0:
            raise GreyboxError(f"effect {term.name!r}: no shape left to scan")
        if term.shape.scale == "frequency":
            position = np.concatenate([run.position for run in self.runs])
            weight = np.concatenate([term.weight(run, self.context) for run in self.runs])

            def choose(train, nuisance, perp):
                scan = PositionScan(position[train], weight[train], nuisance, perp, frequency_step,
                                    1.0 / float(np.min(grid)))
                return np.argmax(scan.reductions(grid), axis=0)
            return choose
        stacked = [np.concatenate([term.columns(run, self.context, g) for run in self.runs]) for g in grid]

        def choose(train, nuisance, perp):
            return np.argmax(np.vstack([added_squares(columns[train], perp, nuisance) for columns in stacked]),
                             axis=0)
        return choose

    def _grid(self, term: Effect, excluded_periods: Sequence[float]) -> tuple[float | None, np.ndarray]:
        """Frequency step (periodic effects, else None) and the shapes a fold may choose from."""
        if term.shape.scale == "frequency":
            return scan_periods(self.runs, self.context, excluded_periods)
        return None, term.shape_grid(self.runs, self.context)

    def best_shape(self, term: Effect, excluded_periods: Sequence[float] = ()) -> float:
        """The shape of ``term`` that explains most of the residual over all training data (as a step's scan).

        Parameters
        ----------
        term : Effect
            An effect with a shape parameter (period, time constant or Stribeck velocity).
        excluded_periods : sequence of float, default ()
            Periodic effects: periods [mm] in the model already, left out of the scan (:func:`scan_periods`).
        """
        step, grid = self._grid(term, excluded_periods)
        nuisance = Nuisance(self.columns)
        everything = np.ones(self.target.size, dtype=bool)
        index = self._chooser(term, grid, step)(everything, nuisance, nuisance.project(self.target[:, None]))
        return float(grid[index[0]])

    @staticmethod
    def _summary(without: np.ndarray, with_term: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pooled gain, its standard error and the per-block gains, per target column."""
        mean_without = np.mean(without, axis=0)
        per_block = (without - with_term) / np.where(mean_without > 0.0, mean_without, 1.0)
        gain = np.mean(per_block, axis=0)
        error = np.std(per_block, axis=0, ddof=1) / np.sqrt(without.shape[0])
        return gain, error, per_block

    def evaluate(self, term: Effect | None, shape: float | None = None, *, excluded_periods: Sequence[float] = (),
                 columns: np.ndarray | None = None) -> HeldOutGain:
        """Held-out evidence for one term.

        Parameters
        ----------
        term : Effect or None
            The library effect (or refinement); None with ``columns``.
        shape : float, optional
            Its shape found on all training data (periodic effects: the period
            whose direction transfer is checked).
        excluded_periods : sequence of float, optional
            Periodic effects: periods [mm] in the model already, not scanned (:func:`scan_periods`).
        columns : ndarray, shape (n, p), optional
            Fixed columns to test instead of an effect's.

        Returns
        -------
        HeldOutGain
        """
        periodic = term is not None and term.shape is not None and term.shape.scale == "frequency"
        if columns is not None or term.shape is None:
            fixed = (np.asarray(columns, dtype=float) if columns is not None
                     else np.concatenate([term.columns(run, self.context) for run in self.runs]))
            shapes = [None]

            def build(s):
                return fixed

            def chooser(train, nuisance, perp):
                return np.zeros(perp.shape[1], dtype=np.int64)
        else:
            step, grid = self._grid(term, excluded_periods)
            shapes = [float(g) for g in grid]

            def build(s):
                return np.concatenate([term.columns(run, self.context, s) for run in self.runs])
            chooser = self._chooser(term, grid, step)
        targets = np.column_stack((self.target, self._null_targets()))
        without, with_term, chosen = self._fold_gains(build, chooser, shapes, targets)
        gain, error, per_block = self._summary(without, with_term)
        null_q95 = float(np.quantile(gain[1:], _LEVEL)) if targets.shape[1] > 1 else None
        margin = max(self.min_gain, null_q95 if null_q95 is not None else -np.inf)
        positive = int(np.sum(per_block[:, 0] > 0.0))
        result = HeldOutGain(gain=float(gain[0]), uncertainty=float(error[0]), positive_blocks=positive,
                             margin=float(margin),
                             null_q95=null_q95, blocks=[float(v) for v in per_block[:, 0]],
                             shapes=[shapes[index] for index in chosen[:, 0]])
        if not result.gain > margin:
            result.reasons.append(f"held-out gain {100 * result.gain:.2f} % not above the margin "
                                  f"{100 * margin:.2f} %")
        if positive < self.n_blocks - 1:
            result.reasons.append(f"the gain is positive on {positive} of {self.n_blocks} held-out blocks only")
        if periodic and shape is not None:
            result.direction_transfer = self._direction_transfer(build(float(shape)))
            for label, value in result.direction_transfer.items():
                if not value > 0.0:
                    result.reasons.append(f"fitted on one direction it does not predict the other "
                                          f"({label.replace('_', ' ')}: {100 * value:.2f} %)")
        result.passes = not result.reasons
        return result

    def _direction_transfer(self, term_columns: np.ndarray) -> dict:
        """Gain on the samples moving one way of the term fitted on the samples moving the other way."""
        direction = np.concatenate([self.context.direction(run) for run in self.runs])
        base = _solve(self.columns, self.target)
        residual = self.target - self.columns @ base
        out = {}
        for label, source, sink in (("positive_to_negative", direction > _MOVING, direction < -_MOVING),
                                    ("negative_to_positive", direction < -_MOVING, direction > _MOVING)):
            if not np.any(source) or not np.any(sink):
                out[label] = 0.0
                continue
            design = np.hstack((self.columns, term_columns * source[:, None]))
            coefficients = _solve(design, self.target)
            predicted = term_columns[sink] @ coefficients[self.columns.shape[1]:]
            before = float(residual[sink] @ residual[sink])
            after = residual[sink] - predicted
            out[label] = float(1.0 - (after @ after) / before) if before > 0.0 else 0.0
        return out
