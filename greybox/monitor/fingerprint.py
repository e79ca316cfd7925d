"""A compact friction fingerprint of one axis from one log, with bootstrap intervals.

The fingerprint is fitted on the stretches of a log without process load:

- an air cut (a dedicated run, e.g. of ``greybox plan``, or the twin's daily air moves) is unloaded
  throughout;
- in a production log, the samples where a reference model's residual stays within its noise
  (:func:`unloaded_samples`).

On those samples, per direction of motion:

- the sliding (Coulomb) level ``F_c`` and the viscous coefficient ``mu``, with the inertia, by the existing
  linear least squares (:func:`greybox.identify.static.fit_coulomb`, asymmetric) on the samples faster than
  ``sliding_speed``, where the Stribeck rise has died out;
- the break-away level: the mean friction current (the effort less the fitted inertial and viscous parts) of
  the samples slower than ``breakaway_speed`` (but moving), where friction is near its static level;
- the residual noise: the root-mean-square residual of the sliding fit.

Intervals come from a moving-block bootstrap: blocks of contiguous samples (default 0.2 s, much longer than the
correlation of the current noise and of the friction memory) are drawn with replacement and everything is
refitted on every replicate. The replicates are seeded, so the same log gives the same fingerprint.
"""

from __future__ import annotations

import numpy as np

from ..data.log import AxisLog, as_log_list
from ..errors import LogError, ParameterError
from ..identify.static import fit_coulomb

__all__ = ["FEATURES", "FEATURE_UNITS", "FrictionFingerprint", "unloaded_samples"]

#: The fingerprint's features, in the order of every table, with their unit.
FEATURE_UNITS = {
    "sliding_pos": "A",
    "sliding_neg": "A",
    "breakaway_pos": "A",
    "breakaway_neg": "A",
    "viscous_pos": "A s/mm",
    "viscous_neg": "A s/mm",
    "noise": "A",
}
#: Feature names, in order.
FEATURES = tuple(FEATURE_UNITS)

#: Fewest unloaded moving samples per direction of motion for a fingerprint.
MIN_SAMPLES_PER_DIRECTION = 100


def _moving_rms(values: np.ndarray, width: int) -> np.ndarray:
    """Root-mean-square of ``values`` over a centred window of ``width`` samples (shorter at the ends)."""
    squares = np.concatenate([[0.0], np.cumsum(values * values)])
    n = len(values)
    half = width // 2
    start = np.clip(np.arange(n) - half, 0, n)
    stop = np.clip(np.arange(n) + width - half, 0, n)
    return np.sqrt((squares[stop] - squares[start]) / np.maximum(stop - start, 1))


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
    return _moving_rms(r - np.median(r), int(window)) <= factor * noise_A


def _block_indices(n: int, block: int, rng: np.random.Generator) -> np.ndarray:
    """Row indices of one moving-block bootstrap replicate of ``n`` rows in blocks of ``block`` rows."""
    block = min(block, n)
    starts = rng.integers(0, n - block + 1, size=-(-n // block))
    return (starts[:, None] + np.arange(block)[None, :]).ravel()[:n]


def _features(v: np.ndarray, a: np.ndarray, y: np.ndarray, sliding_speed: float, breakaway_speed: float,
              ) -> tuple[np.ndarray, float]:
    """The features of :data:`FEATURES` of the samples ``v, a, y`` [mm/s, mm/s^2, A], and the inertia."""
    fast = np.abs(v) >= sliding_speed
    params = fit_coulomb(v[fast], a[fast], y[fast], asymmetric=True)
    viscous = np.where(v > 0.0, params["viscous_pos"], params["viscous_neg"])
    residual = y[fast] - (params["J"] * a[fast] + np.where(v[fast] > 0.0, params["coulomb_pos"],
                                                           -params["coulomb_neg"]) + viscous[fast] * v[fast])
    friction = y - params["J"] * a - viscous * v
    slow = np.abs(v) < breakaway_speed
    slow_pos, slow_neg = friction[slow & (v > 0.0)], friction[slow & (v < 0.0)]
    breakaway_pos = float(np.mean(slow_pos)) if len(slow_pos) else np.nan
    breakaway_neg = -float(np.mean(slow_neg)) if len(slow_neg) else np.nan
    values = np.array([params["coulomb_pos"], params["coulomb_neg"], breakaway_pos, breakaway_neg,
                       params["viscous_pos"], params["viscous_neg"], float(np.sqrt(np.mean(residual * residual)))])
    return values, params["J"]


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
        Number of moving-block bootstrap replicates for the intervals.
    block_s : float, default 0.2
        Length [s] of a bootstrap block of contiguous samples.
    confidence : float, default 0.95
        Coverage of the percentile intervals.
    seed : int, default 0
        Seed of the bootstrap (the same log and seed give the same fingerprint).

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
    """

    def __init__(self, *, sliding_speed: float = 10.0, breakaway_speed: float = 2.0, n_boot: int = 200,
                 block_s: float = 0.2, confidence: float = 0.95, seed: int = 0):
        self.sliding_speed = sliding_speed
        self.breakaway_speed = breakaway_speed
        self.n_boot = n_boot
        self.block_s = block_s
        self.confidence = confidence
        self.seed = seed

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
        pieces, sample_time = [], None
        for run, mask in zip(runs, masks):
            if run.velocity is None or run.acceleration is None:
                raise LogError(run.source or None, "not prepared: velocity and acceleration are needed")
            keep = run.velocity != 0.0
            if mask is not None:
                mask = np.asarray(mask, dtype=bool)
                if mask.shape != keep.shape:
                    raise ParameterError(f"unloaded mask has {mask.size} samples, the run {len(run)}")
                keep &= mask
            pieces.append((run.velocity[keep], run.acceleration[keep], run.effort[keep]))
            sample_time = sample_time or run.sample_time
        v, a, y = (np.concatenate([p[k] for p in pieces]) for k in range(3))
        source = runs[0].source or None
        for sign, name in ((1.0, "positive"), (-1.0, "negative")):
            fast = int(np.sum(sign * v >= self.sliding_speed))
            slow = int(np.sum((sign * v > 0.0) & (sign * v < self.breakaway_speed)))
            if fast < MIN_SAMPLES_PER_DIRECTION or slow == 0:
                raise LogError(source, f"{fast} unloaded samples of {name} motion at {self.sliding_speed:g} mm/s "
                               f"or faster and {slow} below {self.breakaway_speed:g} mm/s; a fingerprint needs at "
                               f"least {MIN_SAMPLES_PER_DIRECTION} and 1 in each direction")
        point, inertia = _features(v, a, y, self.sliding_speed, self.breakaway_speed)
        rng = np.random.default_rng(self.seed)
        block = max(1, int(round(self.block_s / sample_time)))
        replicates = np.empty((self.n_boot, len(FEATURES)))
        for b in range(self.n_boot):
            rows = _block_indices(len(y), block, rng)
            replicates[b] = _features(v[rows], a[rows], y[rows], self.sliding_speed, self.breakaway_speed)[0]
        tail = 50.0 * (1.0 - self.confidence)
        low, high = np.nanpercentile(replicates, [tail, 100.0 - tail], axis=0)
        self.values_ = {name: float(value) for name, value in zip(FEATURES, point)}
        self.lower_ = {name: float(value) for name, value in zip(FEATURES, low)}
        self.upper_ = {name: float(value) for name, value in zip(FEATURES, high)}
        self.inertia_ = float(inertia)
        self.n_samples_ = int(len(y))
        return self
