"""Evidence for candidate effects, calibrated against data in which nothing is missing.

One step of the discovery workflow asks: does any library effect explain
part of the present model's residual better than chance? For every candidate
the statistic is the fraction of the residual's sum of squares it explains
when fitted together with the model's own linear parameters (the nuisance,
:mod:`greybox.identify.projection`), maximised over its shape parameter
(periods from a least-squares scan in position, time constants and Stribeck
velocities over logarithmic grids). A generic *structure* candidate, the
indicator columns of :func:`greybox.discover.locate.structure_basis`, asks
whether anything at all is left.

Null calibration
----------------
Data with nothing missing are the fitted model's prediction plus noise like
the measured residual (:class:`greybox.discover.noise.ResidualNoise`: AR
process with the residual's autocorrelation and local level, its coefficients
drawn from their sampling distribution). The noise is fitted to the model's
residual; if candidates pass, it is fitted once more to the residual left
after them (and after the structure columns, if those pass), so that
structure in the residual does not make the noise look louder than it is.
Refitting the model to simulated data leaves the simulated noise projected
off the nuisance, so every null replicate costs one projection, not a model
fit; this is exact for parameters that enter linearly and the linearisation
of the others. The same scans run on every replicate.

Each candidate's statistic is standardised by its own null distribution,
``z = (log f - log q50) / (log q90 - log q50)``, so that flexible
candidates (a scan over thousands of periods) are not favoured, and the
family-wise null of the largest ``z`` over all candidates (the structure
included) gives each candidate's adjusted p-value ``(1 + #{T_b >= z}) / (B + 1)``.
The quantiles that standardise a value are those of the other ``B`` values
(the observed one among them for a replicate), so the observed statistic and
the replicates are exchangeable when nothing is missing, and the chance that
any candidate passes at level ``alpha`` is then at most ``alpha``.

Telling effects apart
---------------------
The winner is the passing library effect that explains the most beyond
chance (explained fraction minus its null's 95 % quantile). For every
other passing effect, two partial tests against the same null replicates
ask whether the winner explains significantly more once the other is fitted,
and the other way round. If neither does, the data cannot tell the two
apart and both are reported; if only the other does, it becomes the winner.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import scipy.sparse
from threadpoolctl import threadpool_limits

from ..base import LinearPart
from ..data.log import AxisLog, split_runs
from ..identify.projection import Nuisance, PositionScan, added_squares
from ..json_values import jsonable
from ..models.effects import Effect, EffectContext, effect, scan_periods
from .locate import structure_basis
from .noise import ResidualNoise

__all__ = ["CandidateScore", "StepEvidence", "score_step", "STRUCTURE"]

#: Name of the generic structure candidate.
STRUCTURE = "structure"
#: Null fractions at or below this count as zero: the candidate is absorbed by the model.
_ABSORBED = 1e-12


@dataclass
class CandidateScore:
    """Evidence for one candidate at one step.

    Attributes
    ----------
    name : str
        Effect name, or ``"structure"``.
    explained_fraction : float
        Fraction of the residual's sum of squares the candidate explains (at its best shape).
    shape : float or None
        Best shape parameter (period [mm], time constant [s], Stribeck velocity [mm/s]).
    shape_name : str or None
        Its name with unit, e.g. ``"period_mm"``.
    z : float
        Standardised evidence (``-inf`` when absorbed).
    p_value : float
        Family-wise adjusted p-value.
    passes : bool
        ``p_value <= alpha``.
    absorbed : bool
        The model's own parameters already span the candidate (its null is zero).
    null_median, null_q95 : float
        Median and 95 % quantile of the candidate's null explained fraction.
    threshold_fraction : float
        Explained fraction at which the candidate would pass (inf when absorbed).
    scan : dict or None
        ``{"shape": grid, "explained_fraction": curve}`` of the observed residual.
    """

    name: str
    explained_fraction: float
    shape: float | None
    shape_name: str | None
    z: float
    p_value: float
    passes: bool
    absorbed: bool
    null_median: float
    null_q95: float
    threshold_fraction: float = np.inf
    scan: dict | None = None

    def to_dict(self) -> dict:
        """JSON-able summary (without the scan curve)."""
        out = {"explained_fraction": self.explained_fraction, "z": jsonable(self.z), "p_value": self.p_value,
               "passes": self.passes, "absorbed": self.absorbed, "null_median": self.null_median,
               "null_q95": self.null_q95, "threshold_fraction": jsonable(self.threshold_fraction)}
        if self.shape_name is not None:
            out[self.shape_name] = self.shape
        return out


@dataclass
class StepEvidence:
    """Evidence of one step: every candidate, the structure test and the winner.

    Attributes
    ----------
    candidates : dict of str to CandidateScore
        Library candidates, by name.
    structure : CandidateScore
        The generic structure candidate.
    families : dict
        Per structure family: ``{"explained_fraction", "p_value"}`` (each
        against its own null, not adjusted): where the structure is.
    alpha : float
        Level of the tests.
    threshold_z : float
        Smallest ``z`` that passes.
    n_null : int
        Number of null replicates.
    noise : dict
        The noise model of the null (AR order, lag-1 correlation, RMS [A]).
    winner : str or None
        The effect to add, if any passes.
    indistinguishable : list of str
        Passing effects the data cannot tell apart from the winner.
    comparisons : list of dict
        The partial tests behind ``winner`` and ``indistinguishable``.
    """

    candidates: dict
    structure: CandidateScore
    families: dict
    alpha: float
    threshold_z: float
    n_null: int
    noise: dict
    winner: str | None = None
    indistinguishable: list = field(default_factory=list)
    comparisons: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-able summary."""
        return {
            "alpha": self.alpha, "threshold_z": jsonable(self.threshold_z), "n_null": self.n_null,
            "noise": self.noise, "winner": self.winner, "indistinguishable": list(self.indistinguishable),
            "comparisons": self.comparisons,
            "candidates": {name: score.to_dict() for name, score in self.candidates.items()},
            "structure": {**self.structure.to_dict(), "families": self.families},
        }


class _Candidate:
    """Scans one library effect over its shape grid against a set of targets."""

    def __init__(self, term: Effect, runs: Sequence[AxisLog], context: EffectContext,
                 excluded_periods: Sequence[float]):
        self.term = term
        self.runs = runs
        self.context = context
        self.periodic = term.shape is not None and term.shape.scale == "frequency"
        self.grid = None if self.periodic else term.shape_grid(runs, context)
        if self.periodic:
            self.frequency_step, self.grid = scan_periods(runs, context, excluded_periods)

    def columns(self, shape) -> np.ndarray:
        return np.concatenate([self.term.columns(run, self.context, shape) for run in self.runs])

    def reductions(self, nuisance: Nuisance, targets_perp: np.ndarray) -> np.ndarray:
        """Reduction of each target's sum of squares, shape (n_shapes, m) (n_shapes = 1 without a shape)."""
        if self.grid is None:
            return added_squares(self.columns(None), targets_perp, nuisance)[None, :]
        if self.grid.size == 0:
            return np.zeros((1, targets_perp.shape[1]))
        if self.periodic:
            position = np.concatenate([run.position for run in self.runs])
            weight = np.concatenate([self.term.weight(run, self.context) for run in self.runs])
            scan = PositionScan(position, weight, nuisance, targets_perp, self.frequency_step,
                                1.0 / float(np.min(self.grid)))
            return scan.reductions(self.grid)
        return np.vstack([added_squares(self.columns(shape), targets_perp, nuisance) for shape in self.grid])


def _structure_matrix(families: dict) -> scipy.sparse.csr_matrix:
    return scipy.sparse.hstack(list(families.values()), format="csr")


def _saturated_residual(residual_perp, nuisance, blocks) -> np.ndarray:
    """Residual left after fitting the column ``blocks`` (dense or sparse) with the nuisance.

    Columns (almost) inside the nuisance span are left out.
    """
    matrix = scipy.sparse.hstack([b if scipy.sparse.issparse(b) else scipy.sparse.csr_matrix(b)
                                  for b in blocks], format="csc")
    original = np.asarray(matrix.multiply(matrix).sum(axis=0)).ravel()
    inside = nuisance.coordinates(matrix)
    gram = np.asarray((matrix.T @ matrix).todense()) - inside.T @ inside
    keep = np.diag(gram) > 1e-12 * np.maximum(original, np.finfo(float).tiny)
    matrix, gram = matrix[:, keep], gram[np.ix_(keep, keep)]
    norms = np.sqrt(np.diag(gram))
    scaled = gram / norms[:, None] / norms[None, :]
    cross = np.asarray(matrix.T @ residual_perp).ravel() / norms
    coefficients = np.linalg.lstsq(scaled, cross, rcond=1e-10)[0] / norms
    fitted = matrix @ coefficients
    return residual_perp.ravel() - nuisance.project(fitted[:, None]).ravel()


def _leave_one_out_quantile(ordered: np.ndarray, rank: np.ndarray, level: float) -> np.ndarray:
    """Quantile (linear interpolation) of ``ordered`` without the element at each sorted position ``rank``."""
    h = (ordered.size - 2) * level
    j = int(np.floor(h))
    below = np.where(j < rank, ordered[j], ordered[min(j + 1, ordered.size - 1)])
    above = np.where(j + 1 < rank, ordered[min(j + 1, ordered.size - 1)], ordered[min(j + 2, ordered.size - 1)])
    return below + (h - j) * (above - below)


def _standardise(observed: float, null: np.ndarray):
    """``(z_observed, z_null, absorbed, median, q95, to_fraction)`` of one candidate.

    Each value (the observed one and every replicate) is standardised by the
    median and 90 % quantile of *the others*, so that the observed statistic
    and the replicates are treated alike and the family-wise test stays exact.
    ``to_fraction(z)`` maps a standardised value of the observed residual back
    to an explained fraction.
    """
    q50, q90, q95 = np.quantile(null, [0.5, 0.9, 0.95])
    if q90 <= _ABSORBED:
        return -np.inf, np.full(null.size, -np.inf), True, float(q50), float(q95), lambda z: np.inf
    values = np.log(np.maximum(np.concatenate(([observed], null)), 1e-300))
    order = np.argsort(values, kind="stable")
    rank = np.empty(values.size, dtype=np.int64)
    rank[order] = np.arange(values.size)
    ordered = values[order]
    low = np.maximum(_leave_one_out_quantile(ordered, rank, 0.5), np.log(_ABSORBED))
    scale = np.maximum(_leave_one_out_quantile(ordered, rank, 0.9) - low, 1e-6)
    z = (values - low) / scale
    return (float(z[0]), z[1:], False, float(q50), float(q95),
            lambda value: float(np.exp(low[0] + value * scale[0])))


def _p_value(observed, null) -> float:
    return float((1 + np.sum(null >= observed)) / (null.size + 1))


def score_step(runs: Sequence[AxisLog], part: LinearPart, context: EffectContext, names: Sequence[str], *,
               rng: np.random.Generator, n_null: int = 99, alpha: float = 0.05,
               excluded_periods: dict | None = None, level_window_s: float = 1.0) -> StepEvidence:
    """Score candidate effects against the residual of a model, with a simulated null.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs (their effort is the target).
    part : LinearPart
        The present model over the runs (:meth:`AugmentedModel.linear_part`):
        its columns are refitted with every candidate.
    context : EffectContext
        Scales of the effect regressors.
    names : sequence of str
        Library effects to score.
    rng : numpy.random.Generator
        Source of the null replicates.
    n_null : int, default 99
        Number of null replicates ``B``; the smallest p-value is ``1 / (B + 1)``.
    alpha : float, default 0.05
        Level of the family-wise test.
    excluded_periods : dict, optional
        Effect name -> periods [mm] already in the model, not to be scanned again.
    level_window_s : float, default 1.0
        Window of the noise's local level [s].

    Returns
    -------
    StepEvidence
    """
    with threadpool_limits(limits=1, user_api="blas"):  # tall-and-thin products: no gain from threads
        return _score_step(runs, part, context, names, rng=rng, n_null=n_null, alpha=alpha,
                           excluded_periods=excluded_periods or {}, level_window_s=level_window_s)


def _score_step(runs, part, context, names, *, rng, n_null, alpha, excluded_periods, level_window_s):
    target = np.concatenate([run.effort for run in runs]) - part.fixed
    nuisance = Nuisance(part.columns)
    residual_perp = nuisance.project(target[:, None])
    observed_total = float(np.sum(residual_perp ** 2))
    candidates = {name: _Candidate(effect(name), runs, context, excluded_periods.get(name, ())) for name in names}

    # observed residual: scans and best shapes
    observed, best, scans = {}, {}, {}
    for name, candidate in candidates.items():
        fractions = candidate.reductions(nuisance, residual_perp)[:, 0] / observed_total
        index = int(np.argmax(fractions))
        observed[name] = float(fractions[index])
        best[name] = None if candidate.grid is None or candidate.grid.size == 0 else float(candidate.grid[index])
        if candidate.grid is not None and candidate.grid.size:
            scans[name] = {"shape": candidate.grid, "explained_fraction": fractions}
    families = structure_basis(runs)
    structure = _structure_matrix(families)
    observed[STRUCTURE] = float(added_squares(structure, residual_perp, nuisance)[0] / observed_total)
    family_observed = {f: float(added_squares(m, residual_perp, nuisance)[0] / observed_total)
                       for f, m in families.items()}

    # null replicates: noise like the residual; refined once without the effects that pass
    best_columns = {name: candidates[name].columns(best[name]) for name in candidates
                    if candidates[name].grid is None or candidates[name].grid.size}
    noise_residual, refined = residual_perp.ravel(), False
    while True:
        noise = ResidualNoise.fit(split_runs(runs, noise_residual), [run.sample_time for run in runs],
                                  level_window_s=level_window_s)
        null_perp = nuisance.project(np.vstack(noise.simulate(n_null, rng)))
        step = _evaluate(candidates, observed, best, scans, families, structure, family_observed, nuisance,
                         null_perp, alpha, n_null, {**noise.describe(), "refined": refined})
        passing = [best_columns[s.name] for s in step.candidates.values() if s.passes and s.name in best_columns]
        passing += [structure] if step.structure.passes else []
        if refined or not passing:
            break
        noise_residual, refined = _saturated_residual(residual_perp, nuisance, passing), True
    _choose(step, best_columns, part.columns, np.hstack((residual_perp, null_perp)), alpha)
    return step


def _evaluate(candidates, observed, best, scans, families, structure, family_observed, nuisance, null_perp,
              alpha, n_null, noise) -> StepEvidence:
    """Null statistics of every candidate on the replicates, standardised and family-wise calibrated."""
    null_total = np.sum(null_perp ** 2, axis=0)
    null = {name: np.max(c.reductions(nuisance, null_perp), axis=0) / null_total for name, c in candidates.items()}
    null[STRUCTURE] = added_squares(structure, null_perp, nuisance) / null_total
    family_null = {f: added_squares(m, null_perp, nuisance) / null_total for f, m in families.items()}
    standard = {name: _standardise(observed[name], null[name]) for name in observed}
    family_max = np.max(np.vstack([s[1] for s in standard.values()]), axis=0)
    ordered = np.sort(family_max)[::-1]
    allowed = int(np.floor(alpha * (n_null + 1))) - 1  # replicates that may reach the threshold
    threshold = float(np.nextafter(ordered[allowed], np.inf)) if 0 <= allowed < ordered.size else np.inf
    scores = {}
    for name, (z, _, absorbed, median, q95, to_fraction) in standard.items():
        p = 1.0 if absorbed else _p_value(z, family_max)
        term = effect(name) if name != STRUCTURE else None
        scores[name] = CandidateScore(
            name=name, explained_fraction=observed[name], shape=best.get(name),
            shape_name=term.shape.name if term is not None and term.shape is not None else None,
            z=z, p_value=p, passes=p <= alpha, absorbed=absorbed, null_median=median, null_q95=q95,
            threshold_fraction=to_fraction(threshold), scan=scans.get(name))
    return StepEvidence(
        candidates={name: scores[name] for name in candidates}, structure=scores[STRUCTURE],
        families={f: {"explained_fraction": family_observed[f], "p_value": _p_value(family_observed[f],
                                                                                    family_null[f])}
                  for f in families},
        alpha=alpha, threshold_z=threshold, n_null=n_null, noise=noise)


def _partial_p(columns, given, base_columns, targets_perp) -> float:
    """p-value of ``columns`` explaining more once ``given`` is fitted too (first target observed, rest null)."""
    nuisance = Nuisance(np.hstack((base_columns, given)))
    targets = nuisance.project(targets_perp)
    reduction = added_squares(columns, targets, nuisance) / np.maximum(np.sum(targets ** 2, axis=0), 1e-300)
    return _p_value(reduction[0], reduction[1:])


def _choose(step: StepEvidence, best_columns: dict, base_columns, targets_perp, alpha) -> None:
    """Set the step's winner, the effects it cannot be told apart from, and the tests behind them."""
    passing = sorted((s for s in step.candidates.values() if s.passes),
                     key=lambda s: s.null_q95 - s.explained_fraction)
    if not passing:
        return
    winner, visited = passing[0].name, set()
    while winner not in visited:
        visited.add(winner)
        comparisons, switch = [], None
        for other in (s.name for s in passing if s.name != winner):
            beyond = _partial_p(best_columns[winner], best_columns[other], base_columns, targets_perp)
            reverse = _partial_p(best_columns[other], best_columns[winner], base_columns, targets_perp)
            comparisons.append({"winner": winner, "other": other, "p_winner_beyond_other": beyond,
                                "p_other_beyond_winner": reverse})
            if beyond > alpha and reverse <= alpha and switch is None:
                switch = other
        if switch is None:
            break
        winner = switch
    step.winner = winner
    step.comparisons = comparisons
    step.indistinguishable = [c["other"] for c in comparisons
                              if c["p_winner_beyond_other"] > alpha and c["p_other_beyond_winner"] > alpha]
