"""A part checked while it is cut: samples in, block by block; the stretches leaving the envelope out at once.

:class:`PartWatch` is what a live stream needs from an envelope (``greybox live --envelope``,
:mod:`greybox.live.envelope`). It is fed one part's samples from the part's first one. The part is aligned by
its first motion against the reference part's (within the envelope's largest shift); every position whose
smoothing window is complete is compared with the band, as :func:`~greybox.process.check.check_part` compares
the whole part, and the start of every stretch outside is reported as soon as it is seen: half a smoothing
window after it happened. A re-levelling envelope is applied with the corrections of a previous part
(``corrections``, e.g. the last checked part's :attr:`~greybox.process.check.PartCheck.offsets`): the friction
changes little from one part to the next.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..windows import centred_nanmean
from .alignment import STANDSTILL_MM_S, shifted
from .check import stretch_kind

__all__ = ["Breach", "PartWatch"]


class Breach(NamedTuple):
    """The start of a stretch outside the envelope.

    Attributes
    ----------
    start_s : float
        Time [s] since the part's first sample.
    kind : str
        Its kind at its start (:data:`~greybox.process.check.KINDS`): a missing cut may start as a drop, before
        its load has fallen to the air level.
    """

    start_s: float
    kind: str


class PartWatch:
    """Check one part against an envelope while its samples arrive.

    Parameters
    ----------
    envelope : Envelope
        A fitted or loaded envelope.
    corrections : dict, optional
        ``{"negative": ..., "positive": ...}``: the re-levelling of a previous part (offsets [signal unit] of a
        raw envelope, factors of the model's current of a model's envelope); ignored without re-levelling,
        none applied when not given.
    skip_s : float, default 0.0
        Positions within this time [s] after the reference part's first motion are not compared: a stream's model
        carries its state from the previous part, while the envelope was taught on parts each computed from the
        model's initial state, which read otherwise until the model has settled and the smoothing window holds
        no sample from before the motion.
    """

    def __init__(self, envelope, *, corrections: dict | None = None, skip_s: float = 0.0):
        self.envelope = envelope
        self.corrections = dict(corrections or {})
        self.skip_s = skip_s
        length = envelope.reference_velocity_.size
        self._reference_start = int(np.argmax(np.abs(envelope.reference_velocity_) > STANDSTILL_MM_S))
        self._first_compared = self._reference_start + int(round(skip_s / envelope.sample_time_)) if skip_s else 0
        self._velocity: list = []
        self._signal: list = []
        self._extra: dict = {}
        self._shift: int | None = None
        self._grid = np.full(length, np.nan)
        self._checked = -1
        self._outside = False

    def _levelled(self, grid: dict, convert) -> np.ndarray:
        """The part's signal on the reference grid, re-levelled with the given corrections."""
        envelope, signal = self.envelope, grid["signal"]
        if not envelope.relevel or not self.corrections:
            return signal
        held = envelope.held_direction_
        factor = np.where(held < 0, self.corrections.get("negative", 0.0),
                          np.where(held > 0, self.corrections.get("positive", 0.0), 0.0))
        if not envelope.scaled_:
            return signal - factor
        if grid.get("level") is None:
            return signal
        if grid.get("current") is not None and convert is not None:
            return convert(grid["current"] - factor * grid["level"], grid["velocity"])
        return signal - factor * grid["level"]

    def update(self, velocity, signal, *, level=None, current=None, convert=None) -> list[Breach]:
        """Add the next samples of the part; the stretches that began outside the envelope since the last call.

        Parameters
        ----------
        velocity : array_like, shape (k,)
            Axis velocity [mm/s or deg/s] of the new samples.
        signal : array_like, shape (k,)
            The watched signal of the new samples (as the envelope was taught on).
        level : array_like, shape (k,), optional
            The model's current without process [A] (a model's re-levelled envelope).
        current : array_like, shape (k,), optional
            The process current [A] behind a force signal (a model's re-levelled envelope).
        convert : callable, optional
            ``convert(current_A, velocity)``: the force of a process current.
        """
        self._velocity.append(np.asarray(velocity, dtype=float))
        self._signal.append(np.asarray(signal, dtype=float))
        for name, values in (("level", level), ("current", current)):
            if values is not None:
                self._extra.setdefault(name, []).append(np.asarray(values, dtype=float))
        v = np.concatenate(self._velocity)
        if self._shift is None:
            moving = np.flatnonzero(np.abs(v) > STANDSTILL_MM_S)
            if moving.size == 0:
                return []
            limit = self.envelope.max_shift_
            self._shift = int(np.clip(moving[0] - self._reference_start, -limit, limit))
        length, shift = self._grid.size, self._shift
        arrays = {"velocity": v, "signal": np.concatenate(self._signal),
                  **{name: np.concatenate(parts) if len(parts) == len(self._signal) else None
                     for name, parts in self._extra.items()}}
        grid = {name: None if values is None else shifted(values, shift, length) for name, values in arrays.items()}
        smoothed = centred_nanmean(self._levelled(grid, convert), self.envelope.width_, complete=True)
        ready = np.flatnonzero(np.isfinite(smoothed))
        last = int(ready[-1]) if ready.size else -1
        first = max(self._checked + 1, int(ready[0]) if ready.size else 0, self._first_compared)
        if last < first:
            return []
        positions = np.arange(first, last + 1)
        self._grid[positions] = smoothed[positions]
        band = self.envelope.band_[positions]
        outside = (np.abs(self._grid[positions] - self.envelope.centre_[positions]) > band) \
            & (self.envelope.direction_[positions] != 0)
        breaches = []
        for index, flag in zip(positions, outside):
            if flag and not self._outside:
                kind, _ = stretch_kind(self.envelope, self._grid, int(index), int(index) + 1)
                breaches.append(Breach((index + shift) * self.envelope.sample_time_, kind))
            self._outside = bool(flag)
        self._checked = last
        return breaches
