"""The teach-in envelope: the signal of good parts along the part, its spread, and the limits of a check.

:meth:`Envelope.fit` lays every good part on the sample grid of a reference part (the one of median
length), block by block where the logs carry NC block numbers, else by the bounded velocity shift
(:mod:`~greybox.process.alignment`), smooths each with a moving mean
of ``smoothing_s`` and learns per position

- the centre ``c_i`` (mean of the parts) and the spread ``s_i`` (their standard deviation, pooled over a
  window of five smoothing lengths and floored at half its median, so that a few parts give a usable band);
- the load direction ``d_i`` (the sign of the reference's velocity, 0 at standstill), the cut samples (where
  the load ``d_i c_i`` exceeds its direction's air level by more than ``cut_share`` of the largest excess,
  :func:`cut_samples`) and the air samples (moving, farther than one smoothing length from a cut).

With ``relevel=True`` each part is first re-levelled on its own air samples, per direction of motion (the
friction's level changes as the machine warms up; at standstill the direction is the last motion's, whose
friction the axis holds):

- a model's signal (process force or current) should be zero in air: the model's current without process
  ``m_i`` (inertia and friction) is scaled, ``beta = sum(y_i m_i) / sum(m_i^2)`` over the air samples of the
  direction, and ``beta m_i`` removed from the samples of that direction (a friction that changes by a factor
  changes the signal in proportion to the friction the model predicts, along the whole part);
- the raw current has no model: the median of its deviation from the centre over the air samples of the
  direction is removed (an offset).

**Limits, from the false-alarm rate** ``alpha`` per good part, split evenly between two checks:

- the band: a position is outside when ``|y_i - c_i| > k_b s_i`` while the reference moves. A part is a
  false alarm of the band when its largest standardised deviation ``u = max_i |y_i - c_i| / s_i`` passes
  ``k_b``, so ``k_b`` is set on the distribution of ``u`` (:func:`band_count`): the smoothed deviations are
  taken as Gaussian and ``u`` as the largest of ``M`` independent ones (``M``, the *effective count*, stands
  for the smoothed signal's correlation, which no formula in ``L / w`` gets right). Each teach-in part's ``u``
  is measured against the centre and spread of the *other* parts (leave one out), ``M`` is fitted to those
  ``n`` maxima by maximum likelihood and its one-sided 95 % upper confidence bound ``M_95`` kept (a larger
  ``M`` widens the band), and ``k_b = t_nu(p / 2) sqrt(1 + 1/n)`` with ``1 - (1 - p)^M_95 = alpha / 2``
  (``t_nu(q)`` the upper ``q`` quantile of Student's t with ``nu = 5 (n - 1)`` degrees of freedom: the
  spread is pooled over five smoothing lengths of ``n`` parts);
- the part's mean load deviation over the cut samples, ``D = mean_cut(d_i (y_i - c_i))``: outside when
  ``|D| > k_m sd(D)``, ``sd(D)`` over the teach-in parts and ``k_m = t_{n-1}(alpha / 4) sqrt(1 + 1/n)``
  (Student's t, two-sided). A worn tool raises ``D`` long before single positions leave the band.

The rule assumes Gaussian deviations whose part maxima behave as those of ``M`` independent ones; how many
false alarms it gives on good parts is measured on held-out twin parts (``scripts/process_head_to_head.py``),
not promised. An envelope is saved as JSON (no pickle) and
validated fully when loaded (:meth:`Envelope.load`).
"""

from __future__ import annotations

import json
import math
from os import PathLike
from pathlib import Path

import numpy as np
from scipy.stats import chi2
from scipy.stats import t as student

from ..atomic import write_text_atomic
from ..errors import GreyboxError
from ..predict.relevel import level_direction, relevelled
from ..windows import centred_nanmean
from .alignment import BLOCK_COLUMN, STANDSTILL_MM_S, best_shift, block_positions, shifted, warped

__all__ = ["ENVELOPE_FORMAT", "Envelope", "band_count", "cut_samples", "level_direction", "relevelled"]

#: Format tag of an envelope file.
ENVELOPE_FORMAT = "greybox-envelope/2"
#: Percentile of the load over a direction's samples taken as its air level (:func:`cut_samples`).
AIR_PERCENTILE = 20.0
#: Pooling window of the spread, in smoothing lengths.
SPREAD_POOL = 5
#: Confidence of the upper bound of the effective count the band is set with (:func:`band_count`).
COUNT_CONFIDENCE = 0.95


def band_count(maxima, dof: float, scale: float, confidence: float = COUNT_CONFIDENCE) -> tuple[float, float]:
    """Effective count ``M`` of independent deviations whose largest matches the part maxima ``u_j``.

    Model: ``u / scale`` is the largest of ``M`` independent ``|t_dof|`` values, ``P(u <= x) = G(x)^M`` with
    ``G(x) = P(|t_dof| <= x / scale)``. Then ``-log G(u_j)`` is exponential with rate ``M``: the maximum
    likelihood ``M = n / S`` with ``S = sum_j -log G(u_j)``, and ``2 M S`` is chi-square with ``2 n`` degrees
    of freedom, which gives the one-sided upper bound ``M_c = chi2_{2n}(confidence) / (2 S)``.

    Parameters
    ----------
    maxima : array_like, shape (n,)
        Largest standardised deviation of each part (dimensionless, > 0).
    dof : float
        Degrees of freedom of the standardised deviations.
    scale : float
        Their scale beyond Student's t (``sqrt(1 + 1/n')`` for a centre of ``n'`` parts).
    confidence : float, default 0.95
        Confidence of the upper bound, in (0, 1).

    Returns
    -------
    estimate : float
        Maximum-likelihood ``M`` (at least 1).
    upper : float
        Its upper confidence bound (at least 1).
    """
    maxima = np.asarray(maxima, dtype=float)
    inside = 1.0 - 2.0 * student.sf(maxima / scale, dof)
    total = float(np.sum(-np.log(np.clip(inside, 1e-300, None))))
    if not total > 0:
        return 1.0, 1.0
    n = maxima.size
    return max(1.0, n / total), max(1.0, float(chi2.ppf(confidence, 2 * n)) / (2.0 * total))


def cut_samples(centre, direction, share: float) -> np.ndarray:
    """Where the part cuts: the load ``d_i c_i`` above its air level by more than ``share`` of the largest excess.

    The air level of a direction is the 20th percentile of the load over its samples (a part moves in air
    for a share of its time in either direction: a model's signal is zero there, the raw current the friction).

    Parameters
    ----------
    centre : ndarray, shape (L,)
        The taught centre.
    direction : ndarray, shape (L,)
        Direction of motion per position: -1, 0 or 1.
    share : float
        Share of the largest excess, in (0, 1).
    """
    load = direction * centre
    excess = np.zeros_like(load)
    for sign in (-1, 1):
        side = (direction == sign) & np.isfinite(load)
        if side.any():
            excess[side] = load[side] - np.percentile(load[side], AIR_PERCENTILE)
    top = float(np.nanmax(excess))
    return (excess > share * top) if top > 0 else np.zeros(load.shape, dtype=bool)


def _dilated(mask: np.ndarray, width: int) -> np.ndarray:
    return centred_nanmean(mask.astype(float), 2 * int(width) + 1) > 0


class Envelope:
    """Teach-in envelope of a part's signal (module docstring).

    Parameters
    ----------
    false_alarm_rate : float, default 1e-3
        False alarms per good part the limits are set for, in (0, 0.5).
    smoothing_s : float, default 0.1
        Moving-mean window [s] of the signal.
    max_shift_s : float, default 1.0
        Largest timing difference [s] between parts the alignment tries.
    relevel : bool, default False
        Re-level each part on its air samples per direction before comparing.
    cut_share : float, default 0.2
        Cut samples: where the taught load exceeds this share of its largest value, in (0, 1).
    """

    def __init__(self, *, false_alarm_rate: float = 1e-3, smoothing_s: float = 0.1, max_shift_s: float = 1.0,
                 relevel: bool = False, cut_share: float = 0.2):
        self.false_alarm_rate = false_alarm_rate
        self.smoothing_s = smoothing_s
        self.max_shift_s = max_shift_s
        self.relevel = relevel
        self.cut_share = cut_share

    def _check_params(self) -> None:
        if not 0.0 < self.false_alarm_rate < 0.5:
            raise GreyboxError(f"false-alarm rate must be in (0, 0.5) per part, got {self.false_alarm_rate}")
        if not (self.smoothing_s > 0 and self.max_shift_s >= 0):
            raise GreyboxError("smoothing must be positive and the largest shift non-negative")
        if not 0.0 < self.cut_share < 1.0:
            raise GreyboxError(f"cut share must be in (0, 1), got {self.cut_share}")

    # ------------------------------------------------------------------ fit
    def fit(self, parts, *, unit: str = "", signal: dict | None = None) -> "Envelope":
        """Learn the envelope from good parts.

        Parameters
        ----------
        parts : sequence of Part
            At least three good parts of one program (:class:`~greybox.process.parts.Part`).
        unit : str, default ""
            Unit of the signal.
        signal : dict, optional
            Description of the signal (:meth:`~greybox.process.parts.PartSignal.describe`).

        Returns
        -------
        Envelope
            self.
        """
        self._check_params()
        parts = list(parts)
        if len(parts) < 3:
            raise GreyboxError(f"teach-in needs at least 3 good parts, got {len(parts)}")
        dt = float(np.median([part.sample_time for part in parts]))
        if not dt > 0:
            raise GreyboxError("teach-in: a part has fewer than two samples")
        reference = sorted(parts, key=lambda part: len(part.time))[len(parts) // 2]
        self.sample_time_ = dt
        self.width_ = max(1, int(round(self.smoothing_s / dt)))
        self.max_shift_ = int(round(self.max_shift_s / dt))
        self.reference_velocity_ = np.asarray(reference.velocity, dtype=float)
        blocks = reference.extras.get(BLOCK_COLUMN)
        self.blocks_ = blocks is not None
        self.reference_block_ = (np.nan_to_num(np.asarray(blocks, dtype=float), nan=-1.0) if self.blocks_
                                 else np.zeros(self.reference_velocity_.size))
        self.direction_ = np.where(np.abs(self.reference_velocity_) > STANDSTILL_MM_S,
                                   np.sign(self.reference_velocity_), 0.0)
        self.held_direction_ = level_direction(self.reference_velocity_)
        self.scaled_ = all(part.level is not None for part in parts)
        raw = [self._aligned(part) for part in parts]
        first = np.vstack([centred_nanmean(row, self.width_) for row, _, _, _ in raw])
        centre = np.nanmean(first, axis=0)
        self.cut_ = cut_samples(centre, self.direction_, self.cut_share)
        self.air_ = (self.direction_ != 0) & ~_dilated(self.cut_, self.width_)
        aligned = first
        if self.relevel:
            aligned = np.vstack([centred_nanmean(self._relevelled(part, row, template, place, centre)[0], self.width_)
                                 for part, (row, template, _, place) in zip(parts, raw)])
            centre = np.nanmean(aligned, axis=0)
        self.centre_ = centre
        self.spread_ = self._spread(aligned)
        n = len(parts)
        moving = self.direction_ != 0
        maxima = []
        for j in range(n):
            others = np.delete(aligned, j, axis=0)
            standardised = np.abs(aligned[j] - np.nanmean(others, axis=0)) / self._spread(others)
            maxima.append(float(np.nanmax(standardised[moving])))
        _, self.band_count_ = band_count(maxima, (n - 2) * SPREAD_POOL, math.sqrt(1.0 + 1.0 / (n - 1)))
        per_value = -math.expm1(math.log1p(-self.false_alarm_rate / 2.0) / self.band_count_)
        self.band_factor_ = float(student.isf(per_value / 2.0, (n - 1) * SPREAD_POOL) * math.sqrt(1.0 + 1.0 / n))
        deviations = np.array([self.deviation(row) for row in aligned])
        self.deviation_sd_ = float(np.std(deviations, ddof=1))
        self.mean_factor_ = float(student.isf(self.false_alarm_rate / 4.0, n - 1) * math.sqrt(1.0 + 1.0 / n))
        levels = [float(np.median(self.direction_[self.air_ & (self.direction_ == s)] *
                                  centre[self.air_ & (self.direction_ == s)]))
                  if np.any(self.air_ & (self.direction_ == s)) else 0.0 for s in (-1, 1)]
        self.air_level_ = np.where(self.direction_ < 0, levels[0], np.where(self.direction_ > 0, levels[1], 0.0))
        self.cut_load_ = float(np.mean((self.direction_ * centre)[self.cut_])) if self.cut_.any() else 0.0
        self.n_parts_ = n
        self.unit_ = str(unit)
        self.signal_ = dict(signal or {})
        self.parts_ = [{"source": Path(part.source).name, "number": part.number} for part in parts]
        return self

    def _spread(self, rows) -> np.ndarray:
        """Spread per position of aligned parts: standard deviation pooled over five smoothing lengths, floored."""
        spread = np.nanstd(rows, axis=0, ddof=1)
        pooled = np.sqrt(centred_nanmean(spread ** 2, SPREAD_POOL * self.width_))
        return np.maximum(pooled, 0.5 * float(np.nanmedian(pooled)))

    def _aligned(self, part) -> tuple:
        """The part's signal and template on the reference grid (unsmoothed), its shift [samples] and the function
        that lays any of its arrays on the grid: block by block where both carry NC block numbers, else by the
        velocity's shift."""
        length = self.reference_velocity_.size
        blocks = part.extras.get(BLOCK_COLUMN) if self.blocks_ else None
        if blocks is not None:
            positions = block_positions(self.reference_block_, blocks)
            offset = positions - np.arange(length)
            shift = int(round(float(np.nanmedian(offset)))) if np.isfinite(offset).any() else 0

            def place(values):
                return warped(values, positions)
        else:
            shift = best_shift(self.reference_velocity_, part.velocity, self.max_shift_)

            def place(values):
                return shifted(values, shift, length)
        template = None if part.level is None or not self.scaled_ else place(part.level)
        return place(part.signal), template, shift, place

    def _relevelled(self, part, signal, template, place, centre) -> tuple[np.ndarray, dict]:
        """Re-level a part's aligned signal; a force is re-levelled as its process current, then converted."""
        if not self.scaled_:
            return relevelled(signal, self.held_direction_, self.air_, target=centre)
        if template is None:
            raise GreyboxError("the envelope re-levels a model's signal; the part has no model current")
        if part.current is None or part.convert is None:
            return relevelled(signal, self.held_direction_, self.air_, template=template)
        current, corrections = relevelled(place(part.current), self.held_direction_, self.air_, template=template)
        return part.convert(current, place(part.velocity)), corrections

    def deviation(self, aligned) -> float:
        """Mean load deviation ``D`` [signal unit] of an aligned signal over the cut samples.

        Parameters
        ----------
        aligned : ndarray, shape (L,)
            A smoothed signal on the reference grid (re-levelled if the envelope re-levels).
        """
        values = (self.direction_ * (np.asarray(aligned, dtype=float) - self.centre_))[self.cut_]
        finite = values[np.isfinite(values)]
        return float(finite.mean()) if finite.size else 0.0

    def prepared(self, part) -> tuple[np.ndarray, int, dict]:
        """A part's signal as the envelope compares it: aligned, smoothed, re-levelled if set.

        Parameters
        ----------
        part : Part
            The part.

        Returns
        -------
        signal : ndarray, shape (L,)
            On the reference grid (NaN where the part has no sample).
        shift : int
            Its shift [samples] against the reference.
        offsets : dict
            The re-levelling offsets (empty without re-levelling).
        """
        aligned, template, shift, place = self._aligned(part)
        offsets: dict = {}
        if self.relevel:
            aligned, offsets = self._relevelled(part, aligned, template, place, self.centre_)
        return centred_nanmean(aligned, self.width_, complete=True), shift, offsets

    @property
    def band_(self) -> np.ndarray:
        """Half-width of the band per position [signal unit]."""
        return self.band_factor_ * self.spread_

    @property
    def deviation_limit_(self) -> float:
        """Limit of ``|D|`` [signal unit]."""
        return self.mean_factor_ * self.deviation_sd_

    # ------------------------------------------------------------------ files
    _ARRAYS = ("reference_velocity_", "reference_block_", "direction_", "held_direction_", "centre_", "spread_",
               "cut_", "air_", "air_level_")
    _NUMBERS = ("sample_time_", "band_factor_", "band_count_", "deviation_sd_", "mean_factor_", "cut_load_")
    _INTEGERS = ("width_", "max_shift_", "n_parts_")

    def to_dict(self) -> dict:
        """JSON-able content: the settings, the learned arrays and figures."""
        params = {"false_alarm_rate": self.false_alarm_rate, "smoothing_s": self.smoothing_s,
                  "max_shift_s": self.max_shift_s, "relevel": bool(self.relevel), "cut_share": self.cut_share}
        arrays = {name: [bool(v) for v in getattr(self, name)] if name in ("cut_", "air_")
                  else [float(v) for v in getattr(self, name)] for name in self._ARRAYS}
        return {"format": ENVELOPE_FORMAT, "params": params, "unit": self.unit_, "signal": self.signal_,
                "scaled": bool(self.scaled_), "blocks": bool(self.blocks_),
                "parts": self.parts_, **{name: float(getattr(self, name)) for name in self._NUMBERS},
                **{name: int(getattr(self, name)) for name in self._INTEGERS}, "arrays": arrays}

    def save(self, path: str | PathLike) -> Path:
        """Write the envelope as JSON, atomically.

        Parameters
        ----------
        path : str or path-like
            The envelope file.
        """
        return write_text_atomic(path, json.dumps(self.to_dict(), allow_nan=False) + "\n")

    @classmethod
    def from_dict(cls, content, source: str = "envelope") -> "Envelope":
        """An envelope from :meth:`to_dict`'s content, every field checked.

        Parameters
        ----------
        content : dict
            The content.
        source : str, default "envelope"
            Name for the messages.

        Raises
        ------
        GreyboxError
            Naming the source and the first field that is missing or wrong.
        """
        def bad(what: str) -> GreyboxError:
            return GreyboxError(f"{source}: not a valid envelope file ({what})")

        if isinstance(content, dict) and content.get("format") == "greybox-envelope/1":
            raise bad("format greybox-envelope/1 has the earlier band rule: teach it again")
        if not isinstance(content, dict) or content.get("format") != ENVELOPE_FORMAT:
            raise bad(f"format is not {ENVELOPE_FORMAT}")
        params = content.get("params")
        if not isinstance(params, dict) or set(params) != {"false_alarm_rate", "smoothing_s", "max_shift_s",
                                                           "relevel", "cut_share"}:
            raise bad("params")
        if not isinstance(params["relevel"], bool) or not all(
                isinstance(params[k], (int, float)) and not isinstance(params[k], bool)
                for k in ("false_alarm_rate", "smoothing_s", "max_shift_s", "cut_share")):
            raise bad("params")
        envelope = cls(**params)
        try:
            envelope._check_params()
        except GreyboxError as error:
            raise bad(str(error)) from None
        for name in cls._NUMBERS:
            value = content.get(name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise bad(name)
            setattr(envelope, name, float(value))
        for name in cls._INTEGERS:
            value = content.get(name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise bad(name)
            setattr(envelope, name, value)
        if (envelope.sample_time_ <= 0 or envelope.band_count_ < 1 or envelope.width_ < 1 or envelope.n_parts_ < 3
                or envelope.deviation_sd_ < 0):
            raise bad("sample time, smoothing, parts or spread out of range")
        arrays = content.get("arrays")
        if not isinstance(arrays, dict) or set(arrays) != set(cls._ARRAYS):
            raise bad("arrays")
        length = None
        for name in cls._ARRAYS:
            values = arrays[name]
            if not isinstance(values, list) or not values or (length is not None and len(values) != length):
                raise bad(f"{name}: missing, empty or of another length")
            length = len(values)
            if name in ("cut_", "air_"):
                if not all(isinstance(v, bool) for v in values):
                    raise bad(f"{name}: not all true/false")
                setattr(envelope, name, np.array(values, dtype=bool))
            else:
                if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
                    raise bad(f"{name}: not all numbers")
                array = np.array(values, dtype=float)
                if not np.all(np.isfinite(array)):
                    raise bad(f"{name}: not finite")
                setattr(envelope, name, array)
        if not (np.all(np.isin(envelope.direction_, (-1.0, 0.0, 1.0)))
                and np.all(np.isin(envelope.held_direction_, (-1.0, 0.0, 1.0)))) or np.any(envelope.spread_ <= 0):
            raise bad("direction not -1/0/1 or spread not positive")
        if not isinstance(content.get("scaled"), bool) or not isinstance(content.get("blocks"), bool):
            raise bad("scaled or blocks")
        envelope.scaled_, envelope.blocks_ = content["scaled"], content["blocks"]
        if not isinstance(content.get("unit"), str) or not isinstance(content.get("signal"), dict) \
                or not isinstance(content.get("parts"), list):
            raise bad("unit, signal or parts")
        envelope.unit_, envelope.signal_, envelope.parts_ = content["unit"], content["signal"], content["parts"]
        return envelope

    @classmethod
    def load(cls, path: str | PathLike) -> "Envelope":
        """Read and validate an envelope file (JSON; nothing in it is executed).

        Parameters
        ----------
        path : str or path-like
            The envelope file.

        Raises
        ------
        GreyboxError
            For a missing, unreadable or invalid file, naming it.
        """
        name = Path(path).name
        try:
            text = Path(path).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise GreyboxError(f"{name}: cannot read the envelope file ({error.__class__.__name__})") from None

        def refuse(constant):
            raise ValueError(f"{constant} is not a number")

        try:
            content = json.loads(text, parse_constant=refuse)
        except (ValueError, RecursionError) as error:
            raise GreyboxError(f"{name}: not a valid envelope file (not JSON: {error})") from None
        return cls.from_dict(content, name)
