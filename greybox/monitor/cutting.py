"""Stretches of a production log without process load, found without a spindle-load column.

A cut shows in the motor current as a process current that lasts while the tool is engaged: the current
departs from what friction and inertia alone need at that speed, for a whole pass. What friction needs is
learned from the log itself, from the moves that do not cut: a production programme's rapid traverses (and
its fastest returns) are air moves, whatever the part. So:

1. per direction of motion, the samples at least ``share`` of that direction's top speed (the rapids, with
   their ramps) are taken as unloaded;
2. an asymmetric Coulomb + viscous model with inertia (:func:`greybox.identify.static.coulomb_regressors`)
   is fitted to the unloaded samples at ``min_speed`` or faster;
3. a moving sample is loaded where the residual's mean over a centred window of ``window`` samples departs
   from zero by more than ``tolerance`` times the fitted sliding level of its direction (the process current
   has either sign: a cut against the feed raises the current, one pulled along by the tool lowers it),
   and ``pad`` samples on either side of a loaded stretch are loaded too;
4. steps 2 and 3 are repeated ``iterations`` times on the samples found unloaded, so the model learns the
   slower air moves (returns) as well.

Samples slower than ``min_speed`` (reversals, slow approaches, where a Stribeck rise departs from the
model) are judged by the stretch around them only: they are loaded if they lie within ``pad`` samples of a
loaded stretch.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..identify.static import coulomb_regressors
from ..windows import centred_mean, widened

__all__ = ["uncut_samples"]


def uncut_samples(velocity, acceleration, effort, *, share: float = 0.5, min_speed: float = 2.0,
                  tolerance: float = 0.1, window: int = 50, pad: int = 100, iterations: int = 3) -> np.ndarray:
    """Samples of one run without process load, from the current's departure from a friction model.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Velocity [mm/s].
    acceleration : array_like, shape (n,)
        Acceleration [mm/s^2].
    effort : array_like, shape (n,)
        Motor current [A].
    share : float, default 0.5
        Samples at least this share of their direction's top speed are taken as unloaded at first (rapid
        traverses do not cut).
    min_speed : float, default 2.0
        Samples at least this fast [mm/s] are fitted and judged; slower ones follow the stretch around them.
    tolerance : float, default 0.1
        A sustained departure of more than this share of the direction's sliding level is a process load.
    window : int, default 50
        Samples of the centred window the departure is averaged over (100 ms at 2 ms).
    pad : int, default 100
        Samples on either side of a loaded stretch that count as loaded too (200 ms at 2 ms).
    iterations : int, default 3
        Refits of the model on the samples found unloaded.

    Returns
    -------
    ndarray of bool, shape (n,)
        True where the sample is without process load (every sample if a direction has too few fast
        samples to fit a model on).
    """
    v, a, y = (np.asarray(values, dtype=float) for values in (velocity, acceleration, effort))
    if not (0.0 < share <= 1.0 and min_speed > 0.0 and tolerance > 0.0 and iterations >= 1
            and int(window) >= 1 and int(pad) >= 0):
        raise ParameterError(f"uncut_samples: need 0 < share <= 1, min_speed > 0, tolerance > 0, window >= 1, "
                             f"pad >= 0, iterations >= 1; got {share}, {min_speed}, {tolerance}, {window}, {pad}, "
                             f"{iterations}")
    fast = np.abs(v) >= min_speed
    top_pos = float(np.max(v, initial=0.0))
    top_neg = float(-np.min(v, initial=0.0))
    if top_pos < min_speed or top_neg < min_speed:
        return np.ones(len(v), dtype=bool)
    keep = fast & (((v > 0.0) & (v >= share * top_pos)) | ((v < 0.0) & (-v >= share * top_neg)))
    regressors = coulomb_regressors(v, a, asymmetric=True)
    unloaded = np.ones(len(v), dtype=bool)
    for _ in range(int(iterations)):
        if np.sum(keep & (v > 0.0)) < 2 or np.sum(keep & (v < 0.0)) < 2:
            break
        theta = np.linalg.lstsq(regressors[keep], y[keep], rcond=None)[0]
        residual = y - regressors @ theta
        departure = centred_mean(residual, int(window), counts=fast)
        level = np.where(v > 0.0, abs(theta[1]), abs(theta[2]))
        loaded = fast & (np.abs(departure) > tolerance * level)
        unloaded = ~widened(loaded, int(pad))
        keep = fast & unloaded
    return unloaded
