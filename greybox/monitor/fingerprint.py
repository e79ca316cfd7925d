"""A compact friction fingerprint of one axis from one log, with bootstrap intervals.

The fingerprint is fitted on the stretches of a log without process load:

- an air cut (a dedicated run, e.g. of ``greybox plan``, or the twin's daily air moves) is unloaded
  throughout;
- in a production log, the samples where a reference model's residual stays within its noise
  (:func:`unloaded_samples`), or where a spindle-load column says the spindle idles
  (:func:`spindle_idle_samples`).

On those samples, per direction of motion:

- the sliding (Coulomb) level ``F_c`` and the viscous coefficient ``mu``, with the inertia, by the existing
  linear least squares (:func:`greybox.identify.static.fit_coulomb`, asymmetric) on the samples faster than
  ``sliding_speed``, where the Stribeck rise has died out;
- the break-away level: the mean friction current (the effort less the fitted inertial and viscous parts) of
  the samples slower than ``breakaway_speed`` (but moving), where friction is near its static level;
- the residual noise: the root-mean-square residual of the sliding fit;
- the backlash width: after every reversal (a start from rest against the previous direction of motion),
  the travel [mm] from the last position at rest until the friction current (the effort less the fitted
  inertial and viscous parts) first reaches half the sliding level of the new direction (linearly
  interpolated between samples), the median over the log's reversals. Without play this is the
  pre-sliding distance to half the level (fractions of a micrometre on the twin); a play adds its width;
- friction along the travel: on the samples at sliding speed, the friction's excess over its direction's
  sliding level [A] (both directions pooled), as a map of mean excess per ``map_bin_mm`` bin of absolute
  position (:attr:`FrictionFingerprint.map_position_mm_`, :attr:`FrictionFingerprint.map_excess_A_`), and
  two features of it: the local excess, the largest mean residual of a bin under a linear trend along the
  travel fitted to all samples but those of the bin and its two neighbours, after the component periodic
  in ``period_mm`` (the screw lead, fitted with a trend to all samples) is taken off, over the bins at least
  two bins inside the travelled stretch (a stretch of raised friction, a damaged screw section, lifts it
  and cannot pull the trend up to itself); and the amplitude of the periodic component, fitted with the
  trend without the stretch of the largest local excess.

Intervals come from a block bootstrap (the backlash width's from the reversals drawn with replacement): the
unloaded moving samples are cut into blocks of contiguous samples (default 0.2 s, much longer than the
correlation of the current noise and of the friction memory), as many blocks as there are are drawn with
replacement, and every feature is recomputed on each replicate. Every feature but the backlash is a
least-squares fit or a mean, so it follows from sums over the samples (the normal equations of the sliding
fit, the slow samples' sums, per bin of the travel the normal equations along the travel); these sums are
taken once per block (per block and bin along the travel), and a replicate sums the blocks' sums weighted by
how often each block was drawn: exactly the refit on the replicate's samples, at a cost per replicate that
does not grow with the log. The replicates are seeded, so the same log gives the same fingerprint.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy import sparse

from ..data.log import AxisLog, as_log_list
from ..errors import LogError, ParameterError
from ..identify.static import coulomb_from_normal_equations, coulomb_regressors
from ..windows import centred_mean, widened

__all__ = ["FEATURES", "FEATURE_UNITS", "FrictionFingerprint", "reversal_widths", "spindle_idle_samples",
           "unloaded_samples"]

#: The fingerprint's features, in the order of every table, with their unit.
FEATURE_UNITS = {
    "sliding_pos": "A",
    "sliding_neg": "A",
    "breakaway_pos": "A",
    "breakaway_neg": "A",
    "viscous_pos": "A s/mm",
    "viscous_neg": "A s/mm",
    "noise": "A",
    "backlash": "mm",
    "periodic_amp": "A",
    "local_excess": "A",
}
#: Feature names, in order.
FEATURES = tuple(FEATURE_UNITS)

#: Fewest unloaded moving samples per direction of motion for a fingerprint.
MIN_SAMPLES_PER_DIRECTION = 100


def unloaded_samples(residual, *, noise_A: float | None = None, factor: float = 3.0, window: int = 50) -> np.ndarray:
    """Samples without process load: where a reference model's residual stays within its noise.

    A sample is unloaded where the root-mean-square of the residual over a centred window is at most
    ``factor`` times the noise level. A cut shows as a sustained residual (the process current), so the
    window keeps single noisy samples inside a cut from counting as unloaded.

    Parameters
    ----------
    residual : array_like, shape (n,)
        Measured minus predicted current of the reference model [A].
    noise_A : float, optional
        Noise level [A] of the residual without load; by default estimated from the sample-to-sample
        changes of the residual, 1.4826 times their median absolute value over sqrt(2), which a sustained
        process load (a step in, a step out) hardly moves. For noise correlated from sample to sample
        this is an underestimate (by 23 % at the twin's lag-1 correlation 0.7): more samples are then
        counted loaded, never fewer.
    factor : float, default 3.0
        Samples whose windowed RMS residual exceeds ``factor * noise_A`` are loaded.
    window : int, default 50
        Window length [samples] of the RMS (100 ms at 2 ms).

    Returns
    -------
    ndarray of bool, shape (n,)
        True where the sample is unloaded.
    """
    r = np.asarray(residual, dtype=float)
    if noise_A is None:
        noise_A = 1.4826 * float(np.median(np.abs(np.diff(r)))) / np.sqrt(2.0) if len(r) > 1 else 0.0
    if not (np.isfinite(noise_A) and noise_A >= 0.0):
        raise ParameterError(f"noise level must be a non-negative current, got {noise_A} A")
    if not factor > 0.0 or int(window) < 1:
        raise ParameterError("factor must be positive and window at least one sample")
    centred = r - np.median(r)
    return np.sqrt(centred_mean(centred * centred, int(window))) <= factor * noise_A


def spindle_idle_samples(load, *, threshold: float | None = None, pad: int = 100) -> np.ndarray:
    """Samples without process load by a spindle-load column: the spindle idles, and did so for a while.

    Parameters
    ----------
    load : array_like, shape (n,)
        Spindle load (any unit: %, A, kW); larger under cut.
    threshold : float, optional
        Load above which the spindle cuts, in the column's unit. By default the log's 5th percentile plus
        a fifth of the span from its 5th to its 99th percentile (a log without a cut then has a span of
        noise only: use ``threshold`` when whole logs may be without a cut).
    pad : int, default 100
        Samples (200 ms at 2 ms) on either side of a cut that count as loaded too (the axis load ramps in
        and out with the engagement).

    Returns
    -------
    ndarray of bool, shape (n,)
        True where the sample is without process load.
    """
    values = np.asarray(load, dtype=float)
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ParameterError("spindle load: the column is empty or has NaN or infinite values")
    if threshold is None:
        low, high = np.percentile(values, [5.0, 99.0])
        threshold = low + 0.2 * (high - low)
    if not np.isfinite(threshold) or isinstance(pad, bool) or not isinstance(pad, (int, np.integer)) or pad < 0:
        raise ParameterError(f"spindle load: need a finite threshold and a non-negative pad, got {threshold}, {pad}")
    return ~widened(values > threshold, int(pad))


def _block_counts(n_blocks: int, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    """How often each of ``n_blocks`` blocks is drawn in each of ``n_boot`` replicates of ``n_blocks`` draws."""
    return rng.multinomial(n_blocks, np.full(n_blocks, 1.0 / n_blocks), size=n_boot).astype(float)


def _travel_design(x: np.ndarray, low: float, high: float, period_mm: float) -> np.ndarray:
    """Columns of the fit along the travel: 1, u (the position scaled from [low, high] to [-1, 1]), sin, cos of
    the period."""
    u = (2.0 * x - low - high) / max(high - low, 1e-12)
    phase = 2.0 * np.pi * x / period_mm
    return np.column_stack([np.ones_like(x), u, np.sin(phase), np.cos(phase)])


def _row_products(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Per row the outer product of ``left`` (n, p) and ``right`` (n, q), flattened to (n, p * q)."""
    return (left[:, :, None] * right[:, None, :]).reshape(len(left), -1)


class _Statistics:
    """Sums over blocks of contiguous samples from which every feature but the backlash follows.

    The features are least-squares fits and means, so each is a function of sums over the samples: of the
    normal equations of the sliding fit, of the slow samples' effort and motion, and per bin of the travel
    of the normal equations along the travel. A replicate of the block bootstrap is a weighted sum of the
    blocks' sums (weight: how often the block is drawn), so nothing is refitted on the samples.
    """

    def __init__(self, x, v, a, y, block: int, sliding_speed: float, breakaway_speed: float, period_mm: float,
                 bin_mm: float):
        n = len(y)
        self.n_blocks = -(-n // block)
        blocks = np.arange(n) // block
        fast = np.abs(v) >= sliding_speed
        regressors = coulomb_regressors(v[fast], a[fast], asymmetric=True)
        columns = [_row_products(regressors, regressors), regressors * y[fast, None], (y[fast] ** 2)[:, None],
                   np.ones((int(fast.sum()), 1))]
        self.fast = self._sum(blocks[fast], np.hstack(columns), self.n_blocks)
        slow = []
        for sign in (1.0, -1.0):
            chosen = (sign * v > 0.0) & (np.abs(v) < breakaway_speed)
            values = np.column_stack([np.ones(int(chosen.sum())), y[chosen], a[chosen], v[chosen]])
            slow.append(self._sum(blocks[chosen], values, self.n_blocks))
        self.slow = np.hstack(slow)
        # along the travel: the excess over the sliding level is linear in the sliding fit's parameters,
        # excess = Z @ [1, -J, -viscous_pos, -viscous_neg, -coulomb_pos, -coulomb_neg]
        xf, vf, af, yf = x[fast], v[fast], a[fast], y[fast]
        sign = np.sign(vf)
        positive, negative = (vf > 0.0).astype(float), (vf < 0.0).astype(float)
        z = np.column_stack([sign * yf, sign * af, np.abs(vf) * positive, np.abs(vf) * negative, positive,
                             negative])
        low, high = (float(np.min(xf)), float(np.max(xf))) if len(xf) else (0.0, 1.0)
        design = _travel_design(xf, low, high, period_mm)
        bins = np.floor(xf / bin_mm).astype(np.int64)
        self.first_bin = int(bins.min()) if len(bins) else 0
        bin_index = bins - self.first_bin
        self.n_bins = int(bin_index.max()) + 1 if len(bins) else 0
        pairs, pair_index = np.unique(blocks[fast] * max(self.n_bins, 1) + bin_index, return_inverse=True)
        self.pair_block = pairs // max(self.n_bins, 1)
        self.pair_bin = pairs % max(self.n_bins, 1)
        self.travel = self._sum(pair_index, np.hstack([_row_products(design, design), _row_products(design, z)]),
                                len(pairs))
        self.pair_to_bin = sparse.csr_matrix((np.ones(len(pairs)), (self.pair_bin, np.arange(len(pairs)))),
                                             shape=(max(self.n_bins, 1), len(pairs)))

    @staticmethod
    def _sum(groups: np.ndarray, values: np.ndarray, n_groups: int) -> np.ndarray:
        """Column sums of ``values`` per group (the rows' ``groups``), shape (n_groups, columns)."""
        return np.column_stack([np.bincount(groups, weights=column, minlength=n_groups) for column in values.T])

    def features(self, weights: np.ndarray, settings: tuple) -> tuple[np.ndarray, dict, tuple]:
        """The features of :data:`FEATURES` (the backlash NaN), the sliding fit and the travel map of the
        samples with the blocks weighted by ``weights`` (n_blocks,)."""
        min_count = settings[-1]
        fast = weights @ self.fast
        gram, rhs, yy, count = fast[:25].reshape(5, 5), fast[25:30], fast[30], fast[31]
        params = coulomb_from_normal_equations(gram, rhs, asymmetric=True)
        theta = np.array([params["J"], params["coulomb_pos"], params["coulomb_neg"], params["viscous_pos"],
                          params["viscous_neg"]])
        rss = yy - 2.0 * theta @ rhs + theta @ gram @ theta
        noise = float(np.sqrt(max(rss, 0.0) / count)) if count else np.nan
        slow = weights @ self.slow
        breakaway = []
        for offset, viscous, sign in ((0, params["viscous_pos"], 1.0), (4, params["viscous_neg"], -1.0)):
            n_slow, sum_y, sum_a, sum_v = slow[offset:offset + 4]
            breakaway.append(sign * (sum_y - params["J"] * sum_a - viscous * sum_v) / n_slow if n_slow else np.nan)
        excess_coef = np.array([1.0, -params["J"], -params["viscous_pos"], -params["viscous_neg"],
                                -params["coulomb_pos"], -params["coulomb_neg"]])
        periodic, local, centres, level = self._travel_features(weights, excess_coef, settings[2], settings[3],
                                                                min_count)
        values = np.array([params["coulomb_pos"], params["coulomb_neg"], breakaway[0], breakaway[1],
                           params["viscous_pos"], params["viscous_neg"], noise, np.nan, periodic, local])
        return values, params, (centres, level)

    def _travel_features(self, weights, excess_coef, period_mm, bin_mm, min_count):
        """Periodic amplitude [A], local excess [A] and the map (bin centres [mm], mean excess [A]).

        A linear trend and the periodic part are fitted to all samples; the local excess of a bin is its mean
        residual under the trend refitted (the periodic part kept) to all samples but those of the bin and its
        two neighbours (a deleted residual: a raised stretch cannot pull the trend up to itself), over the
        bins at least two bins inside the travelled stretch (no extrapolation). The local excess is the
        largest of them, and the periodic amplitude that of the fit of trend and periodic part without the
        stretch of the largest one.
        """
        per_bin = self.pair_to_bin @ (self.travel * weights[self.pair_block][:, None])
        gram_bin = per_bin[:, :16].reshape(-1, 4, 4)
        rhs_bin = per_bin[:, 16:].reshape(-1, 4, 6) @ excess_coef  # design.T @ excess per bin
        counts = gram_bin[:, 0, 0]
        full = np.flatnonzero(counts >= min_count - 1e-9)
        if counts.sum() < 6 or not len(full):
            return np.nan, np.nan, np.empty(0), np.empty(0)
        interior = full[(full - 2 >= full.min()) & (full + 2 <= full.max())]  # the fit is not extrapolated there
        centres = (full + self.first_bin + 0.5) * bin_mm
        level = rhs_bin[full, 0] / counts[full]
        if not len(interior):
            return np.nan, np.nan, centres, level
        gram, rhs = gram_bin.sum(axis=0), rhs_bin.sum(axis=0)
        coef = np.linalg.lstsq(gram, rhs, rcond=None)[0]
        # design.T @ trend per bin, the trend being the excess less its periodic part
        trend_bin = rhs_bin - gram_bin[:, :, 2:] @ coef[2:]
        padded_gram = np.pad(gram_bin, ((1, 1), (0, 0), (0, 0)))
        padded_trend = np.pad(trend_bin, ((1, 1), (0, 0)))
        window_gram = padded_gram[interior] + padded_gram[interior + 1] + padded_gram[interior + 2]
        window_trend = padded_trend[interior] + padded_trend[interior + 1] + padded_trend[interior + 2]
        line_gram = (gram - window_gram)[:, :2, :2]
        line_rhs = (trend_bin.sum(axis=0) - window_trend)[:, :2]
        line = np.linalg.solve(line_gram, line_rhs[:, :, None])[:, :, 0]
        local = (trend_bin[interior, 0] - np.einsum("ij,ij->i", gram_bin[interior, 0, :2], line)) / counts[interior]
        worst = int(interior[np.argmax(local)])
        stretch = slice(max(worst - 1, 0), worst + 2)
        refit = np.linalg.lstsq(gram - gram_bin[stretch].sum(axis=0), rhs - rhs_bin[stretch].sum(axis=0),
                                rcond=None)[0]
        return float(np.hypot(refit[2], refit[3])), float(np.max(local)), centres, level


def reversal_widths(position, velocity, friction, level_pos: float, level_neg: float, *, keep=None,
                    max_samples: int = 200) -> np.ndarray:
    """Travel [mm] after each reversal until the friction reaches half the new direction's sliding level.

    A reversal is a start of motion (from rest or straight through zero) against the direction of the
    previous motion. Its travel is counted from the last position before the start; the crossing of half
    the level is interpolated linearly between the two samples around it.

    Parameters
    ----------
    position, velocity, friction : array_like, shape (n,)
        Position [mm], velocity [mm/s] and friction current [A] (the effort less inertia and viscous part)
        of one run, in time order.
    level_pos, level_neg : float
        Sliding levels [A] (magnitudes) of positive and negative motion.
    keep : array_like of bool, shape (n,), optional
        Samples that may be used (e.g. unloaded); a reversal whose samples up to the crossing are not all
        kept is skipped.
    max_samples : int, default 200
        A reversal whose friction does not reach the half level within this many samples of motion in the
        new direction is skipped.

    Returns
    -------
    ndarray
        One width [mm] per reversal found (possibly none).
    """
    x, v, f = (np.asarray(values, dtype=float) for values in (position, velocity, friction))
    keep = np.ones(len(x), dtype=bool) if keep is None else np.asarray(keep, dtype=bool)
    direction = np.sign(v)
    moving = np.flatnonzero(direction != 0.0)
    widths = []
    if len(moving) < 2:
        return np.empty(0)
    starts = moving[1:][(direction[moving[1:]] != direction[moving[:-1]])]
    for start in starts:
        if start == 0:
            continue
        s = direction[start]
        half = 0.5 * (level_pos if s > 0.0 else level_neg)
        origin = x[start - 1]
        stop = min(len(x), start + max_samples)
        run = np.flatnonzero(direction[start:stop] != s)
        stop = start + int(run[0]) if len(run) else stop
        above = np.flatnonzero(s * f[start:stop] >= half)
        if not len(above):
            continue
        k = start + int(above[0])
        if not np.all(keep[start - 1:k + 1]):
            continue
        before, after = s * f[k - 1], s * f[k]
        share = 1.0 if after == before else float(np.clip((half - before) / (after - before), 0.0, 1.0))
        widths.append(abs(x[k - 1] + share * (x[k] - x[k - 1]) - origin))
    return np.asarray(widths)


class FrictionFingerprint:
    """Per-direction friction levels, viscous coefficients and residual noise of one axis, with intervals.

    Parameters
    ----------
    sliding_speed : float, default 10.0
        Samples at least this fast [mm/s] give the sliding levels, the viscous coefficients and the noise
        (the twin's Stribeck rise, ``v_s`` = 3 mm/s, is gone there).
    breakaway_speed : float, default 2.0
        Moving samples slower than this [mm/s] give the break-away levels.
    n_boot : int, default 200
        Number of block bootstrap replicates for the intervals.
    block_s : float, default 0.2
        Length [s] of a bootstrap block of contiguous samples.
    confidence : float, default 0.95
        Coverage of the percentile intervals.
    seed : int, default 0
        Seed of the bootstrap (the same log and seed give the same fingerprint).
    period_mm : float, default 10.0
        Period [mm] of the position-periodic friction sought (the screw lead; on a rotary axis in deg).
    map_bin_mm : float, default 2.5
        Bin width [mm] of the friction-along-travel map.
    map_min_samples : int, default 20
        Fewest samples at sliding speed in a bin of the map.

    Attributes
    ----------
    values_ : dict of str to float
        Point estimate of each feature of :data:`FEATURES` (units in :data:`FEATURE_UNITS`).
    lower_, upper_ : dict of str to float
        Ends of the interval of each feature.
    inertia_ : float
        Inertia [A s^2/mm] fitted with the sliding friction.
    n_samples_ : int
        Number of unloaded moving samples used.
    n_reversals_ : int
        Number of reversals that gave a backlash width (the width is NaN without any).
    map_position_mm_ : ndarray
        Centres [mm] of the bins of the friction-along-travel map.
    map_excess_A_ : ndarray
        Mean friction excess [A] over the direction's sliding level in each bin.
    """

    def __init__(self, *, sliding_speed: float = 10.0, breakaway_speed: float = 2.0, n_boot: int = 200,
                 block_s: float = 0.2, confidence: float = 0.95, seed: int = 0, period_mm: float = 10.0,
                 map_bin_mm: float = 2.5, map_min_samples: int = 20):
        self.sliding_speed = sliding_speed
        self.breakaway_speed = breakaway_speed
        self.n_boot = n_boot
        self.block_s = block_s
        self.confidence = confidence
        self.seed = seed
        self.period_mm = period_mm
        self.map_bin_mm = map_bin_mm
        self.map_min_samples = map_min_samples

    def _check_params(self) -> None:
        if not (isinstance(self.n_boot, (int, np.integer)) and self.n_boot >= 10):
            raise ParameterError(f"n_boot must be an integer of at least 10, got {self.n_boot!r}")
        if not (np.isfinite(self.block_s) and self.block_s > 0.0):
            raise ParameterError(f"block_s must be a positive time, got {self.block_s} s")
        if not 0.0 < self.confidence < 1.0:
            raise ParameterError(f"confidence must be in (0, 1), got {self.confidence}")
        if not (np.isfinite(self.breakaway_speed) and 0.0 < self.breakaway_speed < self.sliding_speed
                and np.isfinite(self.sliding_speed)):
            raise ParameterError(f"need 0 < breakaway_speed < sliding_speed, got {self.breakaway_speed} and "
                                 f"{self.sliding_speed} mm/s")
        if not (np.isfinite(self.period_mm) and self.period_mm > 0.0 and np.isfinite(self.map_bin_mm)
                and self.map_bin_mm > 0.0):
            raise ParameterError(f"period_mm and map_bin_mm must be positive lengths, got {self.period_mm} and "
                                 f"{self.map_bin_mm} mm")
        if not (isinstance(self.map_min_samples, (int, np.integer)) and self.map_min_samples >= 1):
            raise ParameterError(f"map_min_samples must be a positive integer, got {self.map_min_samples!r}")

    def fit(self, logs: AxisLog | list[AxisLog], *, unloaded=None) -> "FrictionFingerprint":
        """Fit the fingerprint on the unloaded moving samples of prepared runs.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs (velocity and acceleration present) of one axis, effort in A.
        unloaded : list of ndarray of bool, optional
            Per run, the samples without process load (:func:`unloaded_samples`); all of them by default
            (an air cut).

        Returns
        -------
        FrictionFingerprint
            ``self``.

        Raises
        ------
        LogError
            If a run is not prepared, or too few unloaded samples move in either direction (fewer than
            :data:`MIN_SAMPLES_PER_DIRECTION` at sliding speed, or none below the break-away speed).
        """
        self._check_params()
        runs = as_log_list(logs)
        masks = [None] * len(runs) if unloaded is None else list(unloaded)
        if len(masks) != len(runs):
            raise ParameterError(f"unloaded: {len(masks)} masks for {len(runs)} runs")
        pieces, loads, sample_time = [], [], None
        for run, mask in zip(runs, masks):
            if run.velocity is None or run.acceleration is None:
                raise LogError(run.source or None, "not prepared: velocity and acceleration are needed")
            keep = run.velocity != 0.0
            unloaded = np.ones(len(run), dtype=bool)
            if mask is not None:
                unloaded = np.asarray(mask, dtype=bool)
                if unloaded.shape != keep.shape:
                    raise ParameterError(f"unloaded mask has {unloaded.size} samples, the run {len(run)}")
                keep &= unloaded
            loads.append(unloaded)
            pieces.append((run.position[keep], run.velocity[keep], run.acceleration[keep], run.effort[keep]))
            sample_time = sample_time or run.sample_time
        x, v, a, y = (np.concatenate([p[k] for p in pieces]) for k in range(4))
        source = runs[0].source or None
        for sign, name in ((1.0, "positive"), (-1.0, "negative")):
            fast = int(np.sum(sign * v >= self.sliding_speed))
            slow = int(np.sum((sign * v > 0.0) & (sign * v < self.breakaway_speed)))
            if fast < MIN_SAMPLES_PER_DIRECTION or slow == 0:
                raise LogError(source, f"{fast} unloaded samples of {name} motion at {self.sliding_speed:g} mm/s "
                               f"or faster and {slow} below {self.breakaway_speed:g} mm/s; a fingerprint needs at "
                               f"least {MIN_SAMPLES_PER_DIRECTION} and 1 in each direction")
        settings = (self.sliding_speed, self.breakaway_speed, self.period_mm, self.map_bin_mm, self.map_min_samples)
        block = max(1, int(round(self.block_s / sample_time)))
        stats = _Statistics(x, v, a, y, block, *settings[:4])
        point, params, (centres, level) = stats.features(np.ones(stats.n_blocks), settings)
        widths = np.concatenate([np.empty(0)] + [
            reversal_widths(run.position, run.velocity,
                            run.effort - params["J"] * run.acceleration
                            - np.where(run.velocity > 0.0, params["viscous_pos"], params["viscous_neg"]) * run.velocity,
                            params["coulomb_pos"], params["coulomb_neg"], keep=unloaded)
            for run, unloaded in zip(runs, loads)])
        backlash = FEATURES.index("backlash")
        point[backlash] = float(np.median(widths)) if len(widths) else np.nan
        rng = np.random.default_rng(self.seed)
        counts = _block_counts(stats.n_blocks, self.n_boot, rng)
        replicates = np.empty((self.n_boot, len(FEATURES)))
        with np.errstate(all="ignore"):
            for b in range(self.n_boot):
                replicates[b] = stats.features(counts[b], settings)[0]
                if len(widths):
                    replicates[b, backlash] = np.median(widths[rng.integers(0, len(widths), len(widths))])
        tail = 50.0 * (1.0 - self.confidence)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a feature without any value: NaN ends
            low, high = np.nanpercentile(replicates, [tail, 100.0 - tail], axis=0)
        self.values_ = {name: float(value) for name, value in zip(FEATURES, point)}
        self.lower_ = {name: float(value) for name, value in zip(FEATURES, low)}
        self.upper_ = {name: float(value) for name, value in zip(FEATURES, high)}
        self.inertia_ = float(params["J"])
        self.n_samples_ = int(len(y))
        self.n_reversals_ = int(len(widths))
        self.map_position_mm_ = centres
        self.map_excess_A_ = level
        return self
