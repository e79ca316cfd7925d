"""Compiled evaluation of a Gaussian (RBF) kernel expansion, exact to a stated tolerance.

A fitted support vector regression with an RBF kernel predicts

.. math:: f(x) = \\sum_j \\alpha_j \\exp(-\\gamma \\lVert x - s_j \\rVert^2) + b

for support vectors :math:`s_j`, dual coefficients :math:`\\alpha_j` and
intercept :math:`b`. libsvm (behind :class:`sklearn.svm.SVR`) evaluates every
support vector for every sample. Here a term is left out where it cannot
matter: a term with :math:`\\gamma \\lVert x - s_j \\rVert^2 > c` is smaller in
magnitude than :math:`|\\alpha_j| e^{-c}`, so with the cut-off

.. math:: c = \\ln\\big(\\textstyle\\sum_j |\\alpha_j| / \\text{tolerance}\\big)

all the terms left out of one sample's sum add up to less than
``tolerance`` (in the unit of the output). The samples of a log come in time
order and move little from one to the next, so the samples are taken in
blocks of :data:`BLOCK_SAMPLES`: the support vectors farther than the cut-off
from a block's bounding box are dropped for the whole block at once, and the
rest are evaluated term by term (the distance computed directly, without the
cancellation of the expanded square), two samples at a time, so that each kept support vector is
loaded once for both.

The exponential is branch-free, so that the compiler vectorises it:
:math:`e^{-t} = e^{-n/32} e^{-(t - n/32)}` with :math:`n/32` the multiple of
1/32 nearest to :math:`t`, :math:`e^{-n/32}` from a table and
:math:`e^{-(t - n/32)}` from its Taylor polynomial of degree 6 (truncation
error below :math:`5 \\times 10^{-17}`); its relative error stays within
:data:`EXP_RELATIVE_ERROR` of ``math.exp`` on :math:`0 \\le t \\le 64`. The
result therefore differs from the exact sum by at most

.. math:: \\text{tolerance} + \\texttt{EXP\\_RELATIVE\\_ERROR} \\sum_j |\\alpha_j|

plus the rounding of the sum (tested against a plain one-term-at-a-time
evaluation). Blocks are shared out over threads (:func:`numba.get_num_threads`
of them: the ``NUMBA_NUM_THREADS`` setting, one per core by default); the
compiled kernel releases the GIL. Working memory: a few rows of
``n_support`` values per thread, whatever the number of samples.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit

from ...threads import shared_pool

__all__ = ["rbf_expansion", "add_expansion", "threads_for", "expansion_cutoff",
           "DEFAULT_TOLERANCE", "BLOCK_SAMPLES", "EXP_RELATIVE_ERROR",
           "MAX_CUTOFF"]

#: Default bound on the sum of the terms left out of one sample [unit of the output, e.g. A]: a micro-ampere, a
#: thousandth of the milliampere a drive's trace resolves current to (and as far below any current noise), so the
#: terms left out cannot show in a predicted current; a smaller bound keeps more terms of every sum for nothing.
DEFAULT_TOLERANCE = 1e-6

#: Consecutive samples that share one selection of support vectors.
BLOCK_SAMPLES = 64

#: Bound on the relative error of the compiled exponential on ``[0, MAX_CUTOFF]`` against ``math.exp``.
EXP_RELATIVE_ERROR = 1e-15

#: Largest cut-off ``gamma ||x - s||^2`` the compiled exponential covers.
MAX_CUTOFF = 64.0

#: Blocks below which one thread does all the work (a thread pool costs more than it saves).
_MIN_BLOCKS_PER_THREAD = 64

#: Parts of the samples' blocks per thread of :func:`add_expansion`, taken by the threads as they come free.
_PARTS_PER_THREAD = 4

#: The table of the compiled exponential holds ``exp(-n / _EXP_STEPS)``: a power of two, so that ``t * _EXP_STEPS``
#: and ``n / _EXP_STEPS`` are exact.
_EXP_STEPS = 32

_INVERSE_FACTORIALS = tuple(1.0 / math.factorial(k) for k in range(7))
_F2, _F3, _F4, _F5, _F6 = _INVERSE_FACTORIALS[2:]
#: ``exp(-n / _EXP_STEPS)`` for whole ``n`` from 0 to ``MAX_CUTOFF * _EXP_STEPS``, correctly rounded by ``math.exp``.
_EXP_NEG_TABLE = np.array([math.exp(-n / _EXP_STEPS) for n in range(int(MAX_CUTOFF) * _EXP_STEPS + 1)])


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _exp_neg(t):
    """``exp(-t)`` for ``0 <= t <= MAX_CUTOFF``: ``exp(-m) exp(-(t - m))`` with ``m`` the nearest multiple of 1/32.

    ``exp(-m)`` comes from a table, ``exp(-(t - m))`` with ``|t - m| <= 1/64`` from its Taylor polynomial
    of degree 6 (truncation error below 5e-17; ``t - m`` is exact): branch-free, so that the compiler
    vectorises the loops.
    """
    whole = int(t * _EXP_STEPS + 0.5)
    x = whole * (1.0 / _EXP_STEPS) - t
    p = 1.0 + x * (1.0 + x * (_F2 + x * (_F3 + x * (_F4 + x * (_F5 + x * _F6)))))
    return _EXP_NEG_TABLE[whole] * p


@njit(cache=True, nogil=True, error_model="numpy", fastmath={"reassoc", "contract"})
def _expansion_blocks(X, support_t, alpha, gamma, cutoff, block, first_block, stride, out):
    """Add the kernel sums of the samples of every ``stride``-th block from ``first_block`` on to ``out``.

    ``support_t`` holds the support vectors column-wise, shape (n_features, n_support).
    """
    n_features, n_support = support_t.shape
    n_samples = X.shape[0]
    kept_t = np.empty((n_features, n_support))
    kept_alpha = np.empty(n_support)
    squared = np.empty(n_support)
    squared_next = np.empty(n_support)
    low = np.empty(n_features)
    high = np.empty(n_features)
    reach = cutoff / gamma  # squared distance beyond which a term is left out
    n_blocks = (n_samples + block - 1) // block
    for b in range(first_block, n_blocks, stride):
        start = b * block
        stop = min(start + block, n_samples)
        for f in range(n_features):
            low[f] = X[start, f]
            high[f] = X[start, f]
        for i in range(start + 1, stop):
            for f in range(n_features):
                value = X[i, f]
                low[f] = min(low[f], value)
                high[f] = max(high[f], value)
        n_kept = 0
        for j in range(n_support):
            gap_squared = 0.0
            for f in range(n_features):
                gap = max(low[f] - support_t[f, j], support_t[f, j] - high[f], 0.0)
                gap_squared += gap * gap
            if gap_squared <= reach:
                for f in range(n_features):
                    kept_t[f, n_kept] = support_t[f, j]
                kept_alpha[n_kept] = alpha[j]
                n_kept += 1
        for i in range(start, stop, 2):  # two samples at a time (the second the first again at an odd end)
            last = min(i + 1, stop - 1)
            for k in range(n_kept):
                squared[k] = 0.0
                squared_next[k] = 0.0
            for f in range(n_features):
                value = X[i, f]
                value_next = X[last, f]
                for k in range(n_kept):
                    centre = kept_t[f, k]
                    diff = value - centre
                    diff_next = value_next - centre
                    squared[k] += diff * diff
                    squared_next[k] += diff_next * diff_next
            total = 0.0
            total_next = 0.0
            for k in range(n_kept):
                exponent = gamma * squared[k]
                exponent_next = gamma * squared_next[k]
                term = kept_alpha[k] * _exp_neg(min(exponent, cutoff))
                term_next = kept_alpha[k] * _exp_neg(min(exponent_next, cutoff))
                total += term if exponent <= cutoff else 0.0
                total_next += term_next if exponent_next <= cutoff else 0.0
            out[i] += total
            if last > i:
                out[last] += total_next


def expansion_cutoff(dual_coef, tolerance: float = DEFAULT_TOLERANCE) -> float | None:
    """The largest ``gamma ||x - s||^2`` whose term :func:`rbf_expansion` keeps, for a bound ``tolerance``.

    Parameters
    ----------
    dual_coef : ndarray, shape (n_support,)
        Dual coefficients [unit of the output].
    tolerance : float, default 1e-6
        Bound on the sum of the terms left out of each sample's sum [unit of the output], > 0.

    Returns
    -------
    float or None
        ``log(sum(|dual_coef|) / tolerance)`` [1]; None when all the terms together stay within the tolerance.

    Raises
    ------
    ValueError
        For a cut-off beyond :data:`MAX_CUTOFF`.
    """
    weight = float(np.sum(np.abs(dual_coef)))
    if weight <= tolerance:
        return None
    cutoff = math.log(weight / tolerance)
    if cutoff > MAX_CUTOFF:
        raise ValueError(f"tolerance {tolerance:g} is too small for dual coefficients summing to {weight:g} "
                         f"(at least {weight * math.exp(-MAX_CUTOFF):.3g})")
    return cutoff


def rbf_expansion(
    X,
    support_vectors,
    dual_coef,
    intercept: float = 0.0,
    gamma: float = 1.0,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    threads: int | None = None,
) -> np.ndarray:
    """Evaluate ``sum_j dual_coef[j] * exp(-gamma * ||x - sv_j||^2) + intercept``.

    Parameters
    ----------
    X : array_like, shape (n_samples, n_features)
        Points at which to evaluate the expansion (already in the scaled
        coordinates of the support vectors), best in time order.
    support_vectors : array_like, shape (n_support, n_features)
        Support vectors.
    dual_coef : array_like, shape (n_support,)
        Dual coefficients, in the unit of the output (e.g. A).
    intercept : float, default 0.0
        Constant added to every output, same unit.
    gamma : float, default 1.0
        Kernel width parameter [1 / (unit of X)^2], > 0.
    tolerance : float, default 1e-6
        Bound on the sum of the terms left out of each sample's sum [unit of
        the output], > 0. The result differs from the exact expansion by at
        most ``tolerance + EXP_RELATIVE_ERROR * sum(|dual_coef|)`` plus rounding.
    threads : int, optional
        Threads sharing the samples; default :func:`numba.get_num_threads`
        (``NUMBA_NUM_THREADS``, one per core unless set). Short inputs use one.

    Returns
    -------
    ndarray, shape (n_samples,)
        The expansion at each row of ``X``.

    Raises
    ------
    ValueError
        On inconsistent shapes, a non-positive ``gamma``, ``tolerance`` or
        ``threads``, or a ``tolerance`` so small against ``sum(|dual_coef|)``
        that the cut-off would exceed :data:`MAX_CUTOFF`.
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    sv = np.asarray(support_vectors, dtype=np.float64)
    alpha = np.ascontiguousarray(dual_coef, dtype=np.float64).ravel()
    if X.ndim != 2 or sv.ndim != 2:
        raise ValueError("X and support_vectors must be two-dimensional")
    if X.shape[1] != sv.shape[1]:
        raise ValueError(f"X has {X.shape[1]} features, the support vectors {sv.shape[1]}")
    if alpha.shape[0] != sv.shape[0]:
        raise ValueError(f"{alpha.shape[0]} dual coefficients for {sv.shape[0]} support vectors")
    if not gamma > 0:
        raise ValueError(f"gamma must be positive, got {gamma}")
    if not tolerance > 0:
        raise ValueError(f"tolerance must be positive, got {tolerance}")
    threads = numba.get_num_threads() if threads is None else threads
    if threads < 1:
        raise ValueError(f"threads must be at least 1, got {threads}")

    n_samples = X.shape[0]
    out = np.full(n_samples, float(intercept))
    cutoff = None if n_samples == 0 else expansion_cutoff(alpha, tolerance)
    if cutoff is None:
        return out  # every term together stays within the tolerance
    add_expansion(X, np.ascontiguousarray(sv.T), alpha, float(gamma), cutoff, out, threads)
    return out


def threads_for(n_samples: int, threads: int) -> int:
    """Threads worth sharing the kernel sums of ``n_samples`` samples: at most ``threads``, at least 1.

    Each thread gets :data:`_MIN_BLOCKS_PER_THREAD` blocks of :data:`BLOCK_SAMPLES` at least (a thread pool
    costs more than it saves on fewer).

    Parameters
    ----------
    n_samples : int
        Samples to evaluate.
    threads : int
        Threads available, >= 1.
    """
    return min(threads, max(1, -(-n_samples // BLOCK_SAMPLES) // _MIN_BLOCKS_PER_THREAD))


def add_expansion(X, support_t, alpha, gamma: float, cutoff: float, out, threads: int) -> None:
    """Add the kernel sums of the rows of ``X`` to ``out``, the blocks of samples dealt out over threads.

    Parameters
    ----------
    X : ndarray, shape (n_samples, n_features)
        Points in the support vectors' coordinates, C-contiguous.
    support_t : ndarray, shape (n_features, n_support)
        Support vectors column-wise, C-contiguous.
    alpha : ndarray, shape (n_support,)
        Dual coefficients [unit of the output].
    gamma : float
        Kernel width parameter [1 / (unit of X)^2].
    cutoff : float
        :func:`expansion_cutoff` of ``alpha`` [1].
    out : ndarray, shape (n_samples,)
        Receives the sums, added to what it holds.
    threads : int
        Most threads to use; fewer for short inputs (:func:`threads_for`).
    """
    threads = threads_for(X.shape[0], threads)
    if threads == 1:
        _expansion_blocks(X, support_t, alpha, gamma, cutoff, BLOCK_SAMPLES, 0, 1, out)
        return
    # blocks dealt out in turn (the work per block varies along a log, neighbouring blocks alike) to
    # _PARTS_PER_THREAD parts per thread, which the threads take as they come free: a thread slowed by other work
    # on its core (reading and writing a log's next blocks) leaves more of the parts to the others
    n_parts = min(threads * _PARTS_PER_THREAD, -(-X.shape[0] // BLOCK_SAMPLES))
    parts = [shared_pool(threads).submit(_expansion_blocks, X, support_t, alpha, gamma, cutoff,
                                         BLOCK_SAMPLES, k, n_parts, out) for k in range(n_parts)]
    for part in parts:
        part.result()
