"""Re-levelling: the friction model scaled per direction of motion to the air moves of the same log.

A model trained once carries the change of the machine's friction (a fifth to a third in its first hour of
warm-up) into the process current. Where the axis moves in air the process current should be zero, so the
model's current ``m_i`` (inertia and friction) is scaled per direction of motion to those samples:
``beta = sum(I_i m_i) / sum(m_i^2)`` over the air samples of the direction (``I_i`` the process current), and
``beta m_i`` is removed from the process current of that direction (:func:`relevelled`). At standstill the
direction is the last motion's, whose friction the axis holds (:func:`level_direction`).

``greybox process`` re-levels each part on the air samples its envelope knows. ``greybox predict --relevel``
has no envelope: per chunk of the log (``--chunk-s``, the sliding window) and direction it finds the air samples
itself (:func:`air_samples`), and carries the previous chunk's factor when a chunk has too few of them.
"""

from __future__ import annotations

import numpy as np

from ..windows import centred_mean

__all__ = ["STANDSTILL_MM_S", "MIN_AIR_S", "level_direction", "relevelled", "air_samples", "Relevel"]

#: Speed [mm/s or deg/s] below which the axis is taken to stand still.
STANDSTILL_MM_S = 0.5
#: Fewest seconds of air samples of a direction in a chunk for its own factor.
MIN_AIR_S = 1.0
#: Smoothing window [s] of the air-sample search.
SMOOTHING_S = 0.1
#: Smallest departure from the scaled model that counts as a cut, a share of the direction's median model current
#: (the model's own misfit in air, e.g. at the accelerations of a fast return, stays below it).
FLOOR_SHARE = 0.05


def level_direction(velocity) -> np.ndarray:
    """Direction whose friction the axis holds: the sign of the velocity, at standstill the last motion's.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Axis velocity [mm/s or deg/s]; a rest before the first motion takes the last motion's direction (a part
        of a series starts where the same program's previous part ended).
    """
    v = np.asarray(velocity, dtype=float)
    sign = np.where(np.abs(v) > STANDSTILL_MM_S, np.sign(v), 0.0)
    moving = np.flatnonzero(sign)
    if moving.size == 0:
        return sign
    last = np.maximum.accumulate(np.where(sign != 0, np.arange(v.size), -1))
    return np.where(last >= 0, sign[np.maximum(last, 0)], sign[moving[-1]])


def relevelled(signal, direction, air, *, target=None, template=None) -> tuple[np.ndarray, dict]:
    """A signal re-levelled on its air samples, per direction (module docstring).

    Parameters
    ----------
    signal : ndarray, shape (L,)
        The signal (NaN where it has no sample).
    direction : ndarray, shape (L,)
        Direction whose friction is held per sample (:func:`level_direction`): -1 or 1 (0: left alone).
    air : ndarray of bool, shape (L,)
        Air samples.
    target : ndarray, shape (L,), optional
        Level of the air samples (e.g. an envelope's centre) for an offset; used without ``template``.
    template : ndarray, shape (L,), optional
        The model's current without process: scaled to the air samples, which should read zero.

    Returns
    -------
    signal : ndarray
        Re-levelled.
    corrections : dict
        ``{"negative": ..., "positive": ...}``: the factor ``beta`` [signal unit per A] removed with a template,
        else the offset [signal unit] (0 for a direction without air samples).
    """
    out = np.array(signal, dtype=float)
    corrections = {}
    for sign, name in ((-1, "negative"), (1, "positive")):
        side = direction == sign
        picked = air & side & np.isfinite(out)
        if template is not None:
            m = np.asarray(template, dtype=float)
            picked &= np.isfinite(m)
            energy = float(np.sum(m[picked] ** 2))
            beta = float(np.sum(out[picked] * m[picked]) / energy) if energy > 0 else 0.0
            out[side] -= beta * m[side]
            corrections[name] = beta
        else:
            offset = float(np.median(out[picked] - target[picked])) if picked.any() else 0.0
            out[side] -= offset
            corrections[name] = offset
    return out, corrections


def air_samples(process, model, velocity, *, width: int, share: float = 0.2, iterations: int = 2) -> np.ndarray:
    """Samples moving in air, found in the process current of a stretch of log without knowing its program.

    Per direction of motion, with both currents smoothed over ``width`` samples (``P``, ``M``): a first factor ``b``
    is the 20th percentile of ``P / M`` over the direction's moving samples (air reads ``b``, a cut more); a sample
    cuts where ``|P - b M|`` exceeds ``share`` of its 99th percentile, three times the smoothed noise (from the
    sample-to-sample changes of the process current) and :data:`FLOOR_SHARE` of the direction's median ``|M|`` (two-
    sided, so that the noise of the air samples is trimmed evenly and their mean is kept); the rest, farther than
    ``width`` from a cut, is air. ``b`` is then fitted on those air samples and the search repeated ``iterations``
    times.

    Parameters
    ----------
    process : ndarray, shape (n,)
        Process current [A] (measured minus model).
    model : ndarray, shape (n,)
        The model's current [A].
    velocity : ndarray, shape (n,)
        Axis velocity [mm/s or deg/s].
    width : int
        Smoothing window [samples], at least 1.
    share : float, default 0.2
        Share of the largest departure above which a sample cuts.
    iterations : int, default 2
        Refits of the factor on the air samples.

    Returns
    -------
    ndarray of bool, shape (n,)
    """
    p, m, v = (np.asarray(values, dtype=float) for values in (process, model, velocity))
    smooth_p, smooth_m = centred_mean(p, width), centred_mean(m, width)
    noise = 1.4826 * float(np.median(np.abs(np.diff(p)))) / np.sqrt(2.0 * width) if p.size > 1 else 0.0
    air = np.zeros(p.size, dtype=bool)
    for sign in (-1.0, 1.0):
        side = (np.abs(v) > STANDSTILL_MM_S) & (np.sign(v) == sign)
        usable = side & (np.abs(smooth_m) > 0.1 * float(np.median(np.abs(smooth_m[side])))) if side.any() else side
        if not usable.any():
            continue
        factor = float(np.percentile(smooth_p[usable] / smooth_m[usable], 20.0))
        level = float(np.median(np.abs(smooth_m[side])))
        for _ in range(iterations + 1):
            departure = np.abs(smooth_p - factor * smooth_m)
            limit = max(share * float(np.percentile(departure[side], 99.0)), 3.0 * noise, FLOOR_SHARE * level)
            cut = side & (departure > limit)
            near_cut = centred_mean(cut.astype(float), 2 * width + 1) > 0
            picked = side & ~near_cut
            energy = float(np.sum(m[picked] ** 2))
            if energy > 0:
                factor = float(np.sum(p[picked] * m[picked]) / energy)
        air |= picked
    return air


class Relevel:
    """The re-levelling of a log's chunks one after the other (``greybox predict --relevel``).

    Parameters
    ----------
    sample_time : float
        Step [s] of the log.

    Attributes
    ----------
    corrections_ : dict
        The last chunk's factors ``{"negative": ..., "positive": ...}`` (0 before the first chunk).
    chunks_ : list of dict
        Per chunk: ``start_s``, ``end_s``, the factor per direction and the seconds of air samples it was fitted
        on (0 where the previous chunk's factor was carried).
    """

    def __init__(self, *, sample_time: float):
        self.sample_time = sample_time
        self.corrections_ = {"negative": 0.0, "positive": 0.0}
        self.chunks_: list = []

    def model(self, time, measured, model, velocity) -> np.ndarray:
        """The chunk's model current, scaled per direction to the chunk's air samples.

        Parameters
        ----------
        time : ndarray, shape (n,)
            Time [s].
        measured : ndarray, shape (n,)
            Measured current [A].
        model : ndarray, shape (n,)
            The model's current [A].
        velocity : ndarray, shape (n,)
            Axis velocity [mm/s or deg/s].
        """
        m = np.asarray(model, dtype=float)
        process = np.asarray(measured, dtype=float) - m
        direction = level_direction(velocity)
        width = max(1, int(round(SMOOTHING_S / self.sample_time)))
        air = air_samples(process, m, velocity, width=width)
        enough = {name: float(np.count_nonzero(air & (direction == sign))) * self.sample_time
                  for sign, name in ((-1, "negative"), (1, "positive"))}
        _, found = relevelled(process, direction, air, template=m)
        for name in found:
            if enough[name] >= MIN_AIR_S:
                self.corrections_[name] = found[name]
            else:
                enough[name] = 0.0
        factor = np.where(direction < 0, self.corrections_["negative"],
                          np.where(direction > 0, self.corrections_["positive"], 0.0))
        self.chunks_.append({"start_s": float(time[0]), "end_s": float(time[-1]), **dict(self.corrections_),
                             "air_s": enough})
        return m * (1.0 + factor)
