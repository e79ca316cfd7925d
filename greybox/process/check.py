"""A part against its envelope: the stretches that leave the band, their kind, and the part's verdict.

A stretch is a run of positions outside the band (:class:`~greybox.process.envelope.Envelope`) while the
reference part moves (at standstill the drive holds a friction that depends on what went before, which no
model knows and no cut changes; a part of a long log starts with the previous part's friction held). Its kind
follows from the load deviation ``d_i (y_i - c_i)`` over it and from where it lies:

- **rise**: more load than taught where the part cuts;
- **extra cut**: more load where the taught part moves in air (a collision, an oversized blank's extra
  material, a cut where none should be);
- **missing cut**: less load where the part cuts, down to the air level (less than ``MISSING_SHARE`` of the
  taught cut load above the air level remains: a broken tool, a missing blank);
- **drop**: less load otherwise.

A part is flagged when it has a stretch or its mean load deviation over the cut ``D`` leaves its limit
(``rise`` or ``drop`` of the whole part, e.g. a worn tool).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["KINDS", "MISSING_SHARE", "Stretch", "PartCheck", "check_part", "stretch_kind"]

#: The kinds of a stretch.
KINDS = ("rise", "drop", "missing cut", "extra cut")
#: A drop over the cut that leaves less than this share of the taught cut load above the air level is a missing cut.
MISSING_SHARE = 0.4


@dataclass(frozen=True)
class Stretch:
    """A stretch of a part outside the band.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    start_s, end_s : float
        Its first and last time [s] since the part's first sample.
    peak : float
        Largest ``|y - c|`` over it, in band half-widths.
    deviation : float
        Mean load deviation over it [signal unit].
    """

    kind: str
    start_s: float
    end_s: float
    peak: float
    deviation: float


@dataclass(frozen=True)
class PartCheck:
    """One part's check.

    Attributes
    ----------
    source : str
        Log file.
    number : int
        Part number.
    start_s : float
        Log time [s] of the part's first sample.
    shift_s : float
        Its timing difference [s] against the reference part.
    deviation : float
        Mean load deviation ``D`` over the cut [signal unit].
    deviation_limit : float
        Limit of ``|D|`` [signal unit].
    cut_load : float
        Mean load over the taught cut samples [signal unit] (the mean cut force of a force envelope).
    stretches : list of Stretch
        The stretches outside the band, in order.
    offsets : dict
        Re-levelling offsets [signal unit] per direction (empty without re-levelling).
    signal : ndarray
        The part's smoothed (re-levelled) signal on the reference grid, for the figure.
    """

    source: str
    number: int
    start_s: float
    shift_s: float
    deviation: float
    deviation_limit: float
    cut_load: float
    stretches: list = field(default_factory=list)
    offsets: dict = field(default_factory=dict)
    signal: np.ndarray | None = None

    @property
    def mean_kind(self) -> str:
        """``"rise"`` or ``"drop"`` when ``D`` leaves its limit, else ``""``."""
        if abs(self.deviation) <= self.deviation_limit:
            return ""
        return "rise" if self.deviation > 0 else "drop"

    @property
    def flagged(self) -> bool:
        """True when a stretch leaves the band or ``D`` its limit."""
        return bool(self.stretches) or bool(self.mean_kind)

    @property
    def kinds(self) -> list[str]:
        """The kinds found, the whole part's first, each once."""
        return list(dict.fromkeys(([self.mean_kind] if self.mean_kind else []) + [s.kind for s in self.stretches]))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def stretch_kind(envelope, signal: np.ndarray, a: int, b: int) -> tuple[str, float]:
    """Kind and mean load deviation [signal unit] of the stretch ``[a, b)`` of an aligned signal (module docstring).

    Parameters
    ----------
    envelope : Envelope
        The envelope.
    signal : ndarray, shape (L,)
        The part's smoothed signal on the reference grid.
    a, b : int
        First and one past the last position of the stretch.
    """
    direction = envelope.direction_[a:b]
    deviation = float(np.nanmean(direction * (signal[a:b] - envelope.centre_[a:b])))
    cut = envelope.cut_[a:b]
    on_cut = cut.mean() >= 0.5
    if deviation > 0:
        return ("rise" if on_cut else "extra cut"), deviation
    if on_cut:
        taught = (direction * envelope.centre_[a:b] - envelope.air_level_[a:b])[cut]
        left = (direction * signal[a:b] - envelope.air_level_[a:b])[cut]
        if np.nanmean(left) < MISSING_SHARE * np.mean(taught):
            return "missing cut", deviation
    return "drop", deviation


def check_part(envelope, part) -> PartCheck:
    """Check one part against a fitted envelope.

    Parameters
    ----------
    envelope : Envelope
        A fitted (or loaded) envelope.
    part : Part
        The part (:class:`~greybox.process.parts.Part`).
    """
    signal, shift, offsets = envelope.prepared(part)
    excess = np.abs(signal - envelope.centre_) / envelope.band_
    outside = (np.nan_to_num(excess, nan=0.0) > 1.0) & (envelope.direction_ != 0)
    stretches = []
    dt = envelope.sample_time_
    for a, b in _runs(outside):
        kind, deviation = stretch_kind(envelope, signal, a, b)
        stretches.append(Stretch(kind, (a + shift) * dt, (b - 1 + shift) * dt, float(np.nanmax(excess[a:b])),
                                 deviation))
    load = (envelope.direction_ * signal)[envelope.cut_]
    finite = load[np.isfinite(load)]
    return PartCheck(part.source, part.number, part.start_s, shift * dt, envelope.deviation(signal),
                     envelope.deviation_limit_, float(finite.mean()) if finite.size else float("nan"), stretches,
                     offsets, signal)
