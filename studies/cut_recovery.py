"""How well a model recovers a known process current: the figures of the cutting validation.

A synthetic cutting log carries its true process current ``truth_process_A``.
:func:`recovery_metrics` compares the process current a model recovers
(measured minus model) with it. The recovery error ``e = recovered - truth``
does not depend on how strong the cut is as long as the cut changes neither
the motion nor the noise (true of the synthetic axis), while the true process
current scales with the cut strength ``s``: ``truth = s u``. The correlation
of the recovered with the true process current,

    r(s) = corr(s u, s u + e),

therefore rises with the cut strength, and :func:`strength_for_correlation`
finds the strength at which a model reaches a correlation target. That is the
fair way to state a correlation target: the same model gives r = 0.8 on a
light finishing cut and r = 0.99 on a roughing cut.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from greybox.metrics import rmse

__all__ = ["recovery_metrics", "correlation_at_strength", "strength_for_correlation"]


def recovery_metrics(truth_A, recovered_A, noise_A, force_constant_N_per_A: float) -> dict[str, float]:
    """Figures of one recovered process current.

    Parameters
    ----------
    truth_A : array_like
        True process current [A] (zero outside the cut).
    recovered_A : array_like
        Recovered process current [A], measured minus model.
    noise_A : array_like
        Current noise of the log [A] (measured minus noise-free current).
    force_constant_N_per_A : float
        Factor from process current to force [N/A].

    Returns
    -------
    dict
        ``process_rmse_A``; ``correlation`` of recovered and true process
        current; ``correlation_ceiling``, the correlation of the truth with the
        truth plus the noise (what a perfect model reaches);
        ``process_rmse_in_cut_A`` over the samples with a non-zero truth;
        ``force_rmse_N``; ``mean_cut_force_true_N`` and
        ``mean_cut_force_estimated_N`` over the cut; ``noise_floor_A`` (rms
        of the noise); ``cut_share``, the share of samples in the cut.
    """
    truth = np.asarray(truth_A, dtype=float)
    recovered = np.asarray(recovered_A, dtype=float)
    noise = np.asarray(noise_A, dtype=float)
    cutting = truth != 0.0
    if not cutting.any():
        raise ValueError("the true process current is zero everywhere: the log has no cut")
    return {
        "process_rmse_A": rmse(truth, recovered),
        "correlation": float(np.corrcoef(truth, recovered)[0, 1]),
        "correlation_ceiling": float(np.corrcoef(truth, truth + noise)[0, 1]),
        "process_rmse_in_cut_A": rmse(truth[cutting], recovered[cutting]),
        "force_rmse_N": force_constant_N_per_A * rmse(truth, recovered),
        "mean_cut_force_true_N": force_constant_N_per_A * float(np.mean(truth[cutting])),
        "mean_cut_force_estimated_N": force_constant_N_per_A * float(np.mean(recovered[cutting])),
        "noise_floor_A": float(np.sqrt(np.mean(noise**2))),
        "cut_share": float(np.mean(cutting)),
    }


def correlation_at_strength(unit_truth_A, error_A, strength) -> float:
    """Correlation ``corr(s u, s u + e)`` of the truth at strength ``s`` with its recovery.

    Parameters
    ----------
    unit_truth_A : array_like
        True process current per unit of cut strength, ``u`` [A per unit].
    error_A : array_like
        Recovery error ``e`` [A] (recovered minus true process current), which
        does not depend on the strength.
    strength : float
        Cut strength ``s`` (positive, in the units of ``u``'s denominator).

    Returns
    -------
    float
    """
    truth = strength * np.asarray(unit_truth_A, dtype=float)
    return float(np.corrcoef(truth, truth + np.asarray(error_A, dtype=float))[0, 1])


def strength_for_correlation(unit_truth_A, error_A, target: float = 0.95, *,
                             bracket: tuple[float, float] = (1e-3, 1e3)) -> float:
    """Smallest cut strength at which the recovered process current reaches a correlation.

    Parameters
    ----------
    unit_truth_A, error_A : array_like
        See :func:`correlation_at_strength`.
    target : float, default 0.95
        Correlation to reach, in (0, 1).
    bracket : tuple of float, default (1e-3, 1e3)
        Strengths searched.

    Returns
    -------
    float
        The strength ``s`` with ``r(s) = target`` (the first crossing on a
        logarithmic grid of the bracket, refined by Brent's method); the lower
        end of the bracket if the target is met there already; ``inf`` if it is
        not met within the bracket.
    """
    if not 0.0 < target < 1.0:
        raise ValueError(f"the correlation target must lie in (0, 1), got {target}")
    grid = np.geomspace(bracket[0], bracket[1], 121)
    gap = np.array([correlation_at_strength(unit_truth_A, error_A, s) - target for s in grid])
    reached = np.flatnonzero(gap >= 0.0)
    if reached.size == 0:
        return float("inf")
    first = reached[0]
    if first == 0:
        return float(grid[0])
    return float(brentq(lambda s: correlation_at_strength(unit_truth_A, error_A, s) - target,
                        grid[first - 1], grid[first], xtol=1e-9, rtol=1e-9))
