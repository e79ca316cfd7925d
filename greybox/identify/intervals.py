"""95 % intervals of a fitted model's parameters, with the parameters the data do not determine flagged.

What is estimated
-----------------
Every current model is fitted by least squares of its prediction against the
measured effort. Its identified parameters are written here as one vector
``theta`` in the coordinates of the fit:

- the *linear* coefficients (:meth:`~greybox.base.ModelProtocol.linear_part`:
  ``J``, friction levels, stiffnesses, ...), whose regressor columns the model
  gives exactly, with their bounds (``J >= 0``, ``k_i >= 0``, ...);
- the *shape* parameters the model names in
  :meth:`~greybox.base.ModelProtocol.interval_coordinates`: positive numbers
  varied on a log scale (``v_s``, ``s_0``, the slip rate, ...) and element
  fractions varied in their logits (a simplex), whose columns of the
  Jacobian are central differences of the prediction (relative step 1e-3).

A model that wraps a fitted stage (GMS+SVR, a model behind a backlash)
hands its identified parameters to that stage
(:meth:`~greybox.base.ModelProtocol.interval_stage`); parameters chosen
rather than identified (SVR hyperparameters, a backlash width found on a
grid) get no interval, and the model says why
(:meth:`~greybox.base.ModelProtocol.interval_notes`).

Method ``"sandwich"`` (the default)
-----------------------------------
The covariance of ``theta`` at the optimum is the cluster-robust
("sandwich") covariance of the Gauss-Newton linearisation, in its jackknife
form (CV3)

    Cov = (G - 1) / G * sum_g d_g d_g',   d_g = (A - A_g)^+ X_g' r_g,   A = X'X,   A_g = X_g'X_g,

with ``X`` the Jacobian of the prediction (columns scaled to unit norm),
``r`` the residuals and ``g`` the clusters: ``d_g`` is the Gauss-Newton
step that leaving cluster ``g`` out would take, so this is a linearised
delete-one-cluster jackknife. It is mostly a little larger than the plain
form ``G / (G - 1) A^+ B A^+`` (``B = sum_g (X_g' r_g)(X_g' r_g)'``, CV1,
``jackknife=False``), much larger where one cluster carries much of the
information, and holds its coverage better with few clusters, where the plain
form is known to be too narrow. The clusters are whole runs when there are at
least :data:`MIN_RUN_CLUSTERS` of them (and twice as many as parameters),
else contiguous time blocks of the runs (:func:`greybox.identify.cv.time_blocks`),
:data:`N_BLOCKS` of them (at least twice the number of parameters), never
shorter than ten residual correlation lengths while that leaves enough
blocks. Samples of one axis log are strongly autocorrelated: an
independent-sample covariance would give intervals several times too narrow;
the clusters carry the correlation within a block, and only the correlation
across block borders is neglected. Each parameter of the table is a smooth
function of ``theta``; its variance is carried by the delta method
(derivatives by central differences of the table). The interval is
``value ± t * se`` with ``t`` the 97.5 % point of Student's t with ``G - 1``
degrees of freedom; for a parameter that is a function of the positive
(log-scale) coordinates only, it is taken on the log scale (always positive);
for one of non-negative linear coefficients only, it is clipped at 0.

Method ``"bootstrap"`` (thorough, slow)
---------------------------------------
A wild cluster bootstrap refitting the model: each replicate keeps the
measured motion, replaces the effort by the fitted prediction plus the
residuals of each cluster multiplied by one random sign (Rademacher), refits
a clone of the model (same settings) and reads its parameter table; the
interval is the 2.5 to 97.5 percentile of the replicates (widened to contain
the fitted value). It needs no linearisation but costs one fit per
replicate. The flags are those of the sandwich analysis.

Flags (one phrase per parameter, ``""`` when none)
--------------------------------------------------
``not identifiable``
    The parameter moves along a direction of ``theta`` that leaves the
    prediction unchanged (the information matrix is singular there, relative
    eigenvalue below :data:`NULL_TOLERANCE`): the data cannot determine it;
    no interval.
``at bound``
    It depends on a linear coefficient that the fit held at a bound (e.g.
    ``J = 0``, a stiffness 0); the interval is that of the unconstrained
    linearisation, clipped to the bound.
``poorly determined``
    The 95 % interval reaches zero for a positive quantity or spans more
    than a factor :data:`WIDE_FACTOR`: the data say little about it. Beyond
    a factor :data:`UNBOUNDED_FACTOR` no interval is given
    (``poorly determined: no bounded interval``), nor where a single cluster
    alone determines the parameter (``poorly determined: rests on one run or
    block``: the spread between clusters says nothing about it then).
``no interval: ...``
    Chosen rather than identified, or not varied by the method (the phrase
    says which).

Assumptions and limits
----------------------
The sandwich is a first-order (Wald) interval: it assumes the cost is
smooth near the optimum and the optimum is the global one; stick-slip
switching makes the GMS and LuGre costs only piecewise smooth, and a
parameter near a bound or weakly determined has a skewed distribution. It
treats the residuals of different clusters as independent and needs many
more clusters than parameters; with few clusters the intervals are too
narrow. Model error (a friction law that does not fit) is part of the
residuals and widens the intervals, but a bias of the law is not covered.
The intervals are those of the parameters for the training runs' region:
they say nothing about extrapolation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import t as student_t

from ..data.log import split_runs
from ..errors import GreyboxError, ParameterError
from .cv import time_blocks

__all__ = [
    "METHODS",
    "LEVEL",
    "ParameterInterval",
    "parameter_intervals",
    "attach_intervals",
    "check_intervals",
    "with_intervals",
    "cluster_labels",
]

#: Names of the interval methods (``"none"``: no intervals).
METHODS = ("sandwich", "bootstrap", "none")
#: Confidence level of every interval.
LEVEL = 0.95
#: Fewest runs that are used as clusters themselves (fewer: contiguous time blocks).
MIN_RUN_CLUSTERS = 20
#: Number of contiguous time blocks by default (raised to twice the number of parameters).
N_BLOCKS = 40
#: Relative eigenvalue of the scaled information matrix below which a direction counts as undetermined.
NULL_TOLERANCE = 1e-10
#: A positive parameter whose 95 % interval spans more than this factor is poorly determined.
WIDE_FACTOR = 10.0
#: A log-scale interval wider than this factor either way is not given.
UNBOUNDED_FACTOR = 1e6
#: Relative step of the central differences in the log-scale coordinates.
LOG_STEP = 1e-3
#: Name of the learned attribute that holds the intervals.
ATTRIBUTE = "parameter_intervals_"

_NOT_IDENTIFIABLE = "not identifiable"
_AT_BOUND = "at bound"
_POOR = "poorly determined"
_UNBOUNDED = "poorly determined: no bounded interval"
_ONE_CLUSTER = "poorly determined: rests on one run or block"
_NOT_VARIED = "no interval: held fixed in the fit, or not varied by the linearised method"


@dataclass(frozen=True)
class ParameterInterval:
    """The 95 % interval of one row of a parameter table.

    Attributes
    ----------
    lower, upper : float or ndarray
        Ends of the interval, in the row's unit and shape; NaN where there is none.
    flag : str
        ``""``, or a phrase saying why the interval is missing or not to be trusted.
    """

    lower: object
    upper: object
    flag: str


# ------------------------------------------------------------------ coordinates
class _Coordinates:
    """The identified parameters of a fitted model as one vector, and their Jacobian."""

    def __init__(self, model, runs):
        self.model = model
        self.runs = runs
        parts = [model.linear_part(run) for run in runs]
        self.linear = np.vstack([part.columns for part in parts]) if parts[0].columns.shape[1] else \
            np.empty((sum(len(run) for run in runs), 0))
        self.coefficients = np.asarray(model.linear_coefficients(), dtype=float)
        self.lower = parts[0].lower
        self.upper = parts[0].upper
        self.shapes = dict(model.interval_coordinates())
        for name, kind in self.shapes.items():
            if kind not in ("log", "simplex"):
                raise ValueError(f"coordinate {name!r} of kind {kind!r}: expected 'log' or 'simplex'")
        self.shape_index = [(name, element) for name, kind in self.shapes.items()
                            for element in (range(1, np.size(model.interval_value(name))) if kind == "simplex"
                                            else [None])]

    @property
    def n_linear(self) -> int:
        return self.coefficients.size

    @property
    def size(self) -> int:
        return self.n_linear + len(self.shape_index)

    def is_log(self) -> np.ndarray:
        return np.arange(self.size) >= self.n_linear

    def at_bound(self) -> np.ndarray:
        c = self.coefficients
        tolerance = 1e-9 * float(np.max(np.abs(c), initial=0.0))  # a bounded solver stops a rounding error away
        bound = np.zeros(self.size, dtype=bool)
        bound[: self.n_linear] = (c <= self.lower + tolerance) | (c >= self.upper - tolerance)
        return bound

    def non_negative(self) -> np.ndarray:
        out = np.zeros(self.size, dtype=bool)
        out[: self.n_linear] = self.lower >= 0.0
        return out

    def _linear_step(self, j: int) -> float:
        c = self.coefficients
        return 1e-4 * max(abs(c[j]), 1e-3 * float(np.max(np.abs(c), initial=0.0)), 1e-12)

    def _set_shape(self, index: int, delta: float) -> None:
        name, element = self.shape_index[index]
        value = np.array(self.model.interval_value(name), dtype=float)
        if element is None:
            self.model.set_interval_value(name, float(value * np.exp(delta)))
            return
        value[element] *= np.exp(delta)
        self.model.set_interval_value(name, value / value.sum())

    def perturbed(self, function, j: int, delta: float):
        """``function()`` with coordinate ``j`` moved by ``delta`` (its own units; log for a shape), then restored."""
        if j < self.n_linear:
            trial = self.coefficients.copy()
            trial[j] += delta
            try:
                self.model.set_linear_coefficients(trial)
                return function()
            finally:
                self.model.set_linear_coefficients(self.coefficients)
        name = self.shape_index[j - self.n_linear][0]
        saved = self.model.interval_value(name)
        try:
            self._set_shape(j - self.n_linear, delta)
            return function()
        finally:
            self.model.set_interval_value(name, saved)

    def step(self, j: int) -> float:
        return self._linear_step(j) if j < self.n_linear else LOG_STEP

    def jacobian(self) -> np.ndarray:
        """Derivatives of the prediction over the runs (concatenated) with respect to the coordinates."""
        columns = [self.linear]
        for j in range(self.n_linear, self.size):
            h = self.step(j)
            plus = self.perturbed(lambda: self.model.predict(self.runs), j, h)
            minus = self.perturbed(lambda: self.model.predict(self.runs), j, -h)
            columns.append(((plus - minus) / (2.0 * h))[:, None])
        return np.hstack(columns)

    def table_derivatives(self, names) -> dict:
        """``{row name: ndarray (row size, n coordinates)}``: derivatives of the table's values."""
        def values():
            return {row.name: _numbers(row.value) for row in self.model.parameter_table() if row.name in names}

        out = {name: np.zeros((value.size, self.size)) for name, value in values().items() if value is not None}
        for j in range(self.size):
            h = self.step(j)
            plus, minus = self.perturbed(values, j, h), self.perturbed(values, j, -h)
            for name in out:
                out[name][:, j] = (plus[name] - minus[name]) / (2.0 * h)
        return out


def _numbers(value):
    """A row's value as a flat float array, or None when it is not numeric."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    return array.ravel()


# ------------------------------------------------------------------ clusters
def _correlation_length(residuals: np.ndarray, run_lengths) -> int:
    """Smallest lag [samples] at which the residuals' autocorrelation (pooled over runs) falls below 1/e."""
    edges = np.concatenate(([0], np.cumsum(run_lengths)))
    longest = int(np.max(run_lengths))
    n_fft = 1 << int(np.ceil(np.log2(2 * longest)))
    total = np.zeros(longest)
    for a, b in zip(edges[:-1], edges[1:]):
        r = residuals[a:b] - np.mean(residuals[a:b])
        spectrum = np.fft.rfft(r, n_fft)
        total[: b - a] += np.fft.irfft(spectrum * np.conj(spectrum), n_fft)[: b - a]
    if not total[0] > 0.0:
        return 1
    below = np.flatnonzero(total / total[0] < np.exp(-1.0))
    return int(below[0]) if below.size else longest


def cluster_labels(run_lengths, n_params: int, residuals=None, n_blocks: int | None = None) -> np.ndarray:
    """Cluster of every sample of the runs (concatenated): whole runs, or contiguous time blocks.

    Parameters
    ----------
    run_lengths : sequence of int
        Samples of each run.
    n_params : int
        Number of identified parameters (the clusters are at least twice as many).
    residuals : ndarray, shape (n,), optional
        Residuals of the fit [A]: with them, blocks are kept at least ten residual
        correlation lengths long while that leaves at least ``2 n_params`` blocks.
    n_blocks : int, optional
        Number of time blocks; default :data:`N_BLOCKS` (raised to ``2 n_params``).

    Returns
    -------
    ndarray of int, shape (n,)
        Cluster index of each sample, from 0.
    """
    lengths = [int(n) for n in run_lengths]
    wanted = max(2 * n_params, N_BLOCKS if n_blocks is None else int(n_blocks))
    if len(lengths) >= max(MIN_RUN_CLUSTERS, 2 * n_params) and n_blocks is None:
        return np.repeat(np.arange(len(lengths)), lengths)
    if residuals is not None and n_blocks is None:
        longest_allowed = sum(lengths) // max(10 * _correlation_length(residuals, lengths), 1)
        wanted = max(2 * n_params, min(wanted, longest_allowed))
    wanted = min(wanted, sum(lengths))
    labels = np.empty(sum(lengths), dtype=np.int64)
    for index, block in enumerate(time_blocks(lengths, wanted)):
        labels[block.indices] = index
    return labels


# ------------------------------------------------------------------ the analysis
def cluster_covariance(x: np.ndarray, residuals: np.ndarray, labels: np.ndarray, *, jackknife: bool = True):
    """Cluster-robust covariance of a least-squares estimate from its Jacobian and residuals.

    Parameters
    ----------
    x : ndarray, shape (n, p)
        Jacobian of the prediction with respect to the parameters (any units; scaled columns
        condition the eigenvalue test).
    residuals : ndarray, shape (n,)
        Measured minus predicted effort at the estimate [A].
    labels : ndarray of int, shape (n,)
        Cluster of each sample (0 .. G - 1).
    jackknife : bool, default True
        ``True``: the delete-one-cluster jackknife form (CV3 in the cluster-robust literature),
        ``(G - 1) / G * sum_g d_g d_g'`` with ``d_g = (A - A_g)^+ X_g' r_g``, the Gauss-Newton step
        that leaving cluster ``g`` out would take; larger than the plain form where one cluster
        carries much of the information, and closer to the nominal coverage with few clusters.
        ``False``: the plain form (CV1), ``G / (G - 1) A^+ B A^+`` (see the module notes).

    Returns
    -------
    covariance : ndarray, shape (p, p)
        In the units of ``x``'s parameters, restricted to the directions the data determine.
    null : ndarray, shape (p, q)
        Orthonormal basis of the directions they do not (relative eigenvalue of ``A = X'X`` below
        :data:`NULL_TOLERANCE`).
    carried : ndarray, shape (p, m)
        Orthonormal basis of the determined directions that only one cluster determines (``A - A_g``
        singular there): the clusters give no estimate of their variance.
    """
    n_clusters = int(labels.max()) + 1
    eigenvalues, vectors = np.linalg.eigh(x.T @ x)
    keep = eigenvalues > NULL_TOLERANCE * max(float(eigenvalues.max(initial=0.0)), np.finfo(float).tiny)
    basis, null = vectors[:, keep], vectors[:, ~keep]
    reduced = x @ basis  # coordinates along the determined directions: A = diag(eigenvalues[keep]) there
    scores = np.zeros((n_clusters, basis.shape[1]))
    np.add.at(scores, labels, reduced * residuals[:, None])
    information = np.diag(eigenvalues[keep])
    steps = np.empty_like(scores)
    order = np.argsort(labels, kind="stable")
    edges = np.searchsorted(labels[order], np.arange(n_clusters + 1))
    carried = []  # directions that the data without one cluster do not determine
    for g in range(n_clusters):
        rows = reduced[order[edges[g]:edges[g + 1]]]
        values, directions = np.linalg.eigh(information - rows.T @ rows)
        kept = values > NULL_TOLERANCE * max(float(values.max(initial=0.0)), np.finfo(float).tiny)
        carried.append(directions[:, ~kept])
        steps[g] = directions[:, kept] @ ((directions[:, kept].T @ scores[g]) / values[kept])
    if jackknife:
        inner = (n_clusters - 1) / n_clusters * steps.T @ steps
    else:
        inverse = np.diag(1.0 / eigenvalues[keep])
        inner = n_clusters / max(n_clusters - 1, 1) * inverse @ scores.T @ scores @ inverse
    carried = np.hstack(carried)
    if carried.shape[1]:
        u, singular, _ = np.linalg.svd(carried, full_matrices=False)
        carried = u[:, singular > 1e-6]
    return basis @ inner @ basis.T, null, basis @ carried


def _stage(model, runs):
    """The model and runs whose least-squares problem identifies the parameters, and the row name map.

    Follows :meth:`~greybox.base.ModelProtocol.interval_stage` down to the model that fits its own
    parameters; the map takes that model's row names to the outer model's (``J`` and ``offset`` keep theirs).
    """
    names = {}
    delegate = model.interval_stage(runs)
    while delegate is not None:
        stage, prefix, runs = delegate
        inner = {row.name: row.name if row.name in ("J", "offset") else prefix + row.name
                 for row in stage.parameter_table()}
        names = {name: names.get(outer, outer) for name, outer in inner.items()}
        model = stage
        delegate = model.interval_stage(runs)
    return model, runs, names


def _flag_text(flags: list[str], size: int) -> str:
    """One phrase for a row from the flags of its elements (which elements, for a vector)."""
    phrases = []
    for phrase in dict.fromkeys(flag for flag in flags if flag):
        elements = [i + 1 for i, flag in enumerate(flags) if flag == phrase]
        phrases.append(phrase if size == 1 or len(elements) == size
                       else f"{phrase} (element{'s' if len(elements) > 1 else ''} {', '.join(map(str, elements))})")
    return "; ".join(phrases)


def _shaped(values: np.ndarray, like):
    return float(values[0]) if np.ndim(like) == 0 else values.reshape(np.shape(like))


def parameter_intervals(model, logs, *, method: str = "sandwich", n_bootstrap: int = 100, n_blocks: int | None = None,
                        jackknife: bool = True, random_state: int = 0, progress=None) -> dict:
    """95 % intervals of every row of a fitted model's parameter table (see the module notes).

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    logs : AxisLog or list of AxisLog
        The prepared runs it was fitted on (for a two-stage model: those of the first stage).
    method : {"sandwich", "bootstrap"}, default "sandwich"
        Cluster-robust linearisation, or a wild cluster bootstrap refitting the model.
    n_bootstrap : int, default 100
        Replicates of the bootstrap.
    n_blocks : int, optional
        Number of contiguous time blocks as clusters (default: runs or :data:`N_BLOCKS` blocks, see
        :func:`cluster_labels`).
    jackknife : bool, default True
        The jackknife form of the cluster-robust covariance (see :func:`cluster_covariance`).
    random_state : int, default 0
        Seed of the bootstrap's signs.
    progress : callable, optional
        Called with ``(replicate, n_bootstrap)`` after each bootstrap refit.

    Returns
    -------
    dict
        ``method``, ``level`` (0.95), ``n_clusters`` (number of clusters), ``clusters`` ("runs" or
        "time blocks") and ``rows``: ``{row name: {"lower", "upper", "flag"}}`` with ``lower`` and
        ``upper`` of the row value's shape (floats for a scalar row; NaN where there is no interval).

    Raises
    ------
    ParameterError
        On an unknown method, fewer than 2 replicates, or more than half of the bootstrap refits failing.
    """
    from ..data.log import as_log_list

    if method not in METHODS[:2]:
        raise ParameterError(f"unknown interval method {method!r}; expected one of {METHODS[:2]}")
    if not (isinstance(n_bootstrap, (int, np.integer)) and n_bootstrap >= 2):
        raise ParameterError(f"n_bootstrap must be an integer >= 2, got {n_bootstrap!r}")
    outer_rows = model.parameter_table()
    outer_notes = dict(model.interval_notes())
    stage, runs, names = _stage(model, as_log_list(logs))
    runs = list(runs)
    notes = dict(stage.interval_notes())
    stage_rows = {row.name: row for row in stage.parameter_table()}
    names = names or {name: name for name in stage_rows}
    varied = [name for name in stage_rows if name not in notes]

    coordinates = _Coordinates(stage, runs)
    target = np.concatenate([run.effort for run in runs])
    fitted = stage.predict(runs)
    residuals = target - fitted
    labels = cluster_labels([len(run) for run in runs], coordinates.size, residuals, n_blocks)
    n_clusters = int(labels.max()) + 1
    jacobian = coordinates.jacobian()
    derivatives = coordinates.table_derivatives(varied)

    scale = np.linalg.norm(jacobian, axis=0)
    scale[scale == 0.0] = 1.0
    covariance, null, carried = cluster_covariance(jacobian / scale, residuals, labels, jackknife=jackknife)
    quantile = float(student_t.ppf(0.5 + LEVEL / 2.0, max(n_clusters - 1, 1)))
    is_log, bound, non_negative = coordinates.is_log(), coordinates.at_bound(), coordinates.non_negative()

    result_rows = {}
    for name, row in stage_rows.items():
        outer = names.get(name, name)
        value = _numbers(row.value)
        if name in notes or value is None:
            nan = np.full(0 if value is None else value.size, np.nan)
            reason = f"no interval: {notes.get(name, 'not a number')}"
            result_rows[outer] = (nan, nan.copy(), [reason] * max(nan.size, 1))
            continue
        gradient = derivatives[name] / scale  # d value / d (scaled coordinates)
        lower, upper, flags = np.full(value.size, np.nan), np.full(value.size, np.nan), [""] * value.size
        for i in range(value.size):
            g = gradient[i]
            size = float(np.linalg.norm(g))
            slopes = np.abs(derivatives[name][i])
            uses = slopes > 1e-9 * max(float(np.max(slopes, initial=0.0)), 1e-300)
            if size == 0.0:
                flags[i] = _NOT_VARIED
                continue
            if null.shape[1] and np.linalg.norm(g @ null) > 1e-2 * size:
                flags[i] = _NOT_IDENTIFIABLE
                continue
            if carried.shape[1] and np.linalg.norm(g @ carried) > 1e-2 * size:
                flags[i] = _ONE_CLUSTER
                continue
            se = float(np.sqrt(max(g @ covariance @ g, 0.0)))
            v = value[i]
            if np.all(is_log[uses]) and v > 0.0:
                spread = quantile * se / v  # half-width on the log scale
                if not spread < np.log(UNBOUNDED_FACTOR):
                    flags[i] = _UNBOUNDED
                    continue
                lower[i], upper[i] = v * np.exp(-spread), v * np.exp(spread)
                poor = upper[i] / lower[i] > WIDE_FACTOR
            elif not np.isfinite(se):
                flags[i] = _UNBOUNDED
                continue
            else:
                lower[i], upper[i] = v - quantile * se, v + quantile * se
                poor = False
                if np.all(non_negative[uses]) and v >= 0.0:
                    poor = lower[i] <= 0.0 < v
                    lower[i] = max(lower[i], 0.0)
            if np.any(bound[uses]):
                flags[i] = _AT_BOUND
            elif poor:
                flags[i] = _POOR
        result_rows[outer] = (lower, upper, flags)

    if method == "bootstrap":
        _bootstrap(stage, runs, fitted, residuals, labels, result_rows, names, stage_rows, notes,
                   n_bootstrap, random_state, progress)

    rows = {}
    for row in outer_rows:
        if row.name in result_rows:
            lower, upper, flags = result_rows[row.name]
            value = _numbers(row.value)
            lower = np.where(np.isnan(lower), lower, np.minimum(lower, value))
            upper = np.where(np.isnan(upper), upper, np.maximum(upper, value))
            rows[row.name] = {"lower": _shaped(lower, row.value), "upper": _shaped(upper, row.value),
                              "flag": _flag_text(flags, value.size)}
        else:
            value = _numbers(row.value)
            size = 1 if value is None else value.size
            nan = np.full(size, np.nan)
            rows[row.name] = {"lower": _shaped(nan, row.value) if value is not None else float("nan"),
                              "upper": _shaped(nan.copy(), row.value) if value is not None else float("nan"),
                              "flag": f"no interval: {outer_notes.get(row.name, 'not identified by least squares')}"}
    return {"method": method, "level": LEVEL, "n_clusters": n_clusters,
            "clusters": "runs" if n_clusters == len(runs) and len(runs) > 1 else "time blocks", "rows": rows}


def _bootstrap(stage, runs, fitted, residuals, labels, result_rows, names, stage_rows, notes, n_bootstrap,
               random_state, progress) -> None:
    """Replace the intervals of ``result_rows`` by percentile intervals of a wild cluster bootstrap."""
    from sklearn.base import clone

    rng = np.random.default_rng(random_state)
    n_clusters = int(labels.max()) + 1
    draws = {name: [] for name in stage_rows if name not in notes}
    for replicate in range(n_bootstrap):
        signs = rng.choice((-1.0, 1.0), size=n_clusters)
        effort = fitted + signs[labels] * residuals
        replicate_runs = [run.replace(effort=part) for run, part in zip(runs, split_runs(runs, effort))]
        try:
            refit = clone(stage).fit(replicate_runs)
        except GreyboxError:  # a replicate the model refuses (e.g. an unstable search) is left out
            continue
        for row in refit.parameter_table():
            if row.name in draws:
                draws[row.name].append(_numbers(row.value))
        if progress is not None:
            progress(replicate + 1, n_bootstrap)
    tail = 100.0 * (1.0 - LEVEL) / 2.0
    if min((len(values) for values in draws.values()), default=n_bootstrap) < max(2, n_bootstrap // 2):
        raise ParameterError("more than half of the bootstrap refits failed: no bootstrap intervals")
    for name, values in draws.items():
        lower, upper, flags = result_rows[names.get(name, name)]
        if len({np.size(v) for v in values}) != 1 or values[0] is None:
            continue
        sample = np.vstack(values)
        lower[:], upper[:] = np.percentile(sample, tail, axis=0), np.percentile(sample, 100.0 - tail, axis=0)
        value = _numbers(stage_rows[name].value)
        for i in range(value.size):
            if flags[i] in ("", _POOR, _UNBOUNDED, _ONE_CLUSTER):
                if value[i] > 0.0 and lower[i] > 0.0:
                    flags[i] = _POOR if upper[i] > WIDE_FACTOR * lower[i] else ""
                else:  # whether reaching zero matters (a positive quantity) the sandwich analysis knew
                    flags[i] = _POOR if flags[i] else ""
            elif flags[i] == _NOT_VARIED and upper[i] > lower[i]:
                flags[i] = ""


# ------------------------------------------------------------------ attaching, checking, rows
def attach_intervals(model, logs, *, method: str = "sandwich", **options):
    """Compute :func:`parameter_intervals` and store them in the model (learned attribute ``parameter_intervals_``).

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    logs : AxisLog or list of AxisLog
        The runs it was fitted on (of the first stage, for a two-stage model).
    method : {"sandwich", "bootstrap", "none"}, default "sandwich"
        ``"none"`` stores nothing (and drops intervals the model held).
    **options
        Passed to :func:`parameter_intervals` (``n_bootstrap``, ``n_blocks``, ``random_state``, ``progress``).

    Returns
    -------
    model
    """
    if method == "none":
        vars(model).pop(ATTRIBUTE, None)
        return model
    setattr(model, ATTRIBUTE, parameter_intervals(model, logs, method=method, **options))
    return model


def check_intervals(model) -> None:
    """Raise ``ValueError`` unless the model's stored intervals are well formed (a model file's check).

    Every named row must exist in the parameter table; ``lower`` and ``upper``
    have the row value's shape and are finite with ``lower <= value <= upper``,
    or NaN together where the flag (a string) says why there is no interval.

    Parameters
    ----------
    model : CurrentModel
        A fitted model, with or without ``parameter_intervals_``.
    """
    record = getattr(model, ATTRIBUTE, None)
    if record is None:
        return
    if not isinstance(record, dict) or not isinstance(record.get("rows"), dict):
        raise ValueError(f"{ATTRIBUTE} must be an object with 'rows'")
    if record.get("method") not in METHODS[:2]:
        raise ValueError(f"{ATTRIBUTE}: unknown method {record.get('method')!r}")
    if record.get("level") != LEVEL:
        raise ValueError(f"{ATTRIBUTE}: level must be {LEVEL}, got {record.get('level')!r}")
    values = {row.name: row.value for row in model.parameter_table()}
    for name, entry in record["rows"].items():
        if name not in values:
            raise ValueError(f"{ATTRIBUTE} names a parameter the model has not: {name!r}")
        if not (isinstance(entry, dict) and set(entry) == {"lower", "upper", "flag"}
                and isinstance(entry["flag"], str)):
            raise ValueError(f"{ATTRIBUTE}[{name!r}] must hold lower, upper and a flag string")
        value = _numbers(values[name])
        try:
            lower = np.asarray(entry["lower"], dtype=float)
            upper = np.asarray(entry["upper"], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{ATTRIBUTE}[{name!r}]: lower and upper must be numbers") from None
        shape = np.shape(values[name]) if value is not None else ()
        if lower.shape != shape or upper.shape != shape:
            raise ValueError(f"{ATTRIBUTE}[{name!r}]: lower and upper must have the value's shape {shape}")
        lower, upper = lower.ravel(), upper.ravel()
        missing = np.isnan(lower) | np.isnan(upper)
        if np.any(np.isnan(lower) != np.isnan(upper)) or (np.any(missing) and not entry["flag"]):
            raise ValueError(f"{ATTRIBUTE}[{name!r}]: an interval is missing without a flag saying why")
        if not np.all(np.isfinite(lower[~missing]) & np.isfinite(upper[~missing])):
            raise ValueError(f"{ATTRIBUTE}[{name!r}]: the interval is not finite")
        inside = (lower[~missing] <= value[~missing]) & (value[~missing] <= upper[~missing]) if value is not None \
            else np.ones(0, dtype=bool)
        if not np.all(inside):
            raise ValueError(f"{ATTRIBUTE}[{name!r}]: the interval does not contain the value")


def with_intervals(model, rows) -> list:
    """The rows of a parameter table with their stored intervals and flags (rows unchanged without a record).

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    rows : list of Parameter
        Its parameter table.
    """
    from dataclasses import replace

    record = getattr(model, ATTRIBUTE, None)
    if not isinstance(record, dict):
        return rows
    stored = record.get("rows")
    if not isinstance(stored, dict):
        return rows
    out = []
    for row in rows:
        entry = stored.get(row.name)
        if isinstance(entry, dict) and {"lower", "upper", "flag"} <= set(entry):
            row = replace(row, lower=entry["lower"], upper=entry["upper"], flag=entry["flag"])
        out.append(row)
    return out
