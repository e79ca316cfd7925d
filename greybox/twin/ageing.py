"""A twin that ages: one short daily air-move log per axis, with friction drifting from a given day.

Every day the axis runs the same air-move programme inside its measurement window (back and forth at
four feeds, :func:`air_move_trajectory`); its truth plant is the default one with two changes:

- a day-to-day spread (temperature, lubricant state): the friction levels (every Maxwell-slip element's
  breakaway current) are scaled by ``exp(N(0, LEVEL_SPREAD))`` and the viscous coefficient by
  ``exp(N(0, VISCOUS_SPREAD))``, drawn from the seed and the day;
- the drifts (:class:`Drift`), from their start day on, scale the friction levels by
  ``1 + rate * (day - start)`` (lubrication loss: the levels rise) or ``1 - rate * (day - start)``
  (preload loss: they fall; never below :data:`MIN_LEVEL_FACTOR`); open an axial play of
  ``rate * (day - start)`` mm between motor and table (backlash growth); or raise the friction along a
  stretch of the travel (:data:`DEFECT_CENTRE_OFFSET_MM`, :data:`DEFECT_WIDTH_MM` from the window centre) by
  ``rate * (day - start)`` of its level (a local screw defect). ``none`` changes nothing (the spread alone).

A level change scales the sliding and the static level alike (the ratio of the two is the plant's).
The aged plant (:class:`AgedPlant`) is the default plant seen through a play and a defect: the logged
position is the motor's; the friction acts on the table, which follows the motor only while the play is
closed (:func:`play_operator`), and reaches the motor only then (while the play is open the Maxwell-slip
elements keep their deflection and the motor feels its inertia alone).
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
from numba import njit

from ..errors import GreyboxError
from .axes import axis_geometry
from .built_on import BuiltOnPlant
from .datasets import make_dataset, stored
from .motion import MotionProfile
from .plant import PlantParameters, PlantResponse, default_plant_parameters, fine_motion, maxwell_slip_kernel
from .trajectories import MM_MIN, Trajectory

__all__ = ["DRIFT_KINDS", "AgedPlant", "Drift", "air_move_trajectory", "aged_log", "defect_profile", "play_operator",
           "synthesize_history"]

#: Drift kinds and what each does to the truth plant.
DRIFT_KINDS = {
    "lubrication": "lubrication loss: the friction levels rise by RATE (a fraction) per day from day START",
    "preload": "preload loss: the friction levels fall by RATE (a fraction) per day from day START",
    "backlash": "backlash growth: an axial play of RATE mm per day opens from day START",
    "defect": "a local screw defect: the friction along a stretch of the travel rises by RATE (a fraction of its "
              "level) per day from day START",
    "none": "stable: only the day-to-day spread",
}
#: Standard deviation of the log of the daily friction-level factor (1 % spread).
LEVEL_SPREAD = 0.01
#: Standard deviation of the log of the daily viscous factor (3 % spread: viscosity follows temperature).
VISCOUS_SPREAD = 0.03
#: Smallest factor a preload loss takes the friction levels to.
MIN_LEVEL_FACTOR = 0.2
#: Centre of the defect's stretch [mm] from the window centre (towards negative positions).
DEFECT_CENTRE_OFFSET_MM = -12.0
#: Width [mm] of the defect's stretch (a raised cosine of this full width).
DEFECT_WIDTH_MM = 6.0
#: Spindle load [%] of an idle spindle, and its rise [%] per ampere of process current over the cut's strength.
SPINDLE_IDLE_PCT, SPINDLE_CUT_PCT = 5.0, 60.0
#: Name of the spindle-load column of the production days.
SPINDLE_COLUMN = "spindle_load_pct"
#: Feeds [mm/min] of the daily air moves, slowest first.
AIR_MOVE_FEEDS_MM_MIN = (60.0, 300.0, 900.0, 1500.0, 2400.0)
#: Dataset label of the daily logs (it seeds their noise with the day's seed).
HISTORY_DATASET = "H"


@dataclass(frozen=True)
class Drift:
    """A friction drift of the ageing twin.

    Parameters
    ----------
    kind : {"lubrication", "preload", "backlash", "defect", "none"}
        Kind of drift (:data:`DRIFT_KINDS`).
    start_day : int, default 0
        First day (counted from 0) on which the drift acts.
    rate : float, default 0.0
        Change per day, at least 0: of the friction levels [1/day] (lubrication, preload), of the play
        [mm/day] (backlash), of the friction along the defect's stretch [1/day] (defect).
    """

    kind: str
    start_day: int = 0
    rate: float = 0.0

    def __post_init__(self):
        if self.kind not in DRIFT_KINDS:
            raise GreyboxError(f"unknown drift kind {self.kind!r}; choose from {', '.join(DRIFT_KINDS)}")
        if isinstance(self.start_day, bool) or not isinstance(self.start_day, (int, np.integer)) \
                or self.start_day < 0:
            raise GreyboxError(f"drift start day must be a non-negative integer, got {self.start_day!r}")
        if not (np.isfinite(self.rate) and self.rate >= 0.0):
            raise GreyboxError(f"drift rate must be a non-negative fraction per day, got {self.rate!r}")

    @classmethod
    def parse(cls, text: str) -> "Drift":
        """A drift from ``KIND:START:RATE`` (``none`` alone is accepted too).

        Parameters
        ----------
        text : str
            E.g. ``"lubrication:30:0.01"``: from day 30 the levels rise by 1 % of their value per day.

        Raises
        ------
        GreyboxError
            If the text is not of that form.
        """
        parts = [part.strip() for part in str(text).split(":")]
        if parts == ["none"]:
            return cls("none")
        if len(parts) != 3:
            raise GreyboxError(f"drift {text!r}: expected KIND:START:RATE, e.g. lubrication:30:0.01")
        try:
            start, rate = int(parts[1]), float(parts[2])
        except ValueError:
            raise GreyboxError(f"drift {text!r}: START must be a whole day and RATE a number") from None
        return cls(parts[0], start, rate)

    def level_factor(self, day: int) -> float:
        """Factor of the friction levels on ``day`` (1 before the start).

        Parameters
        ----------
        day : int
            Day, counted from 0.
        """
        elapsed = max(0, int(day) - int(self.start_day))
        if self.kind == "lubrication":
            return 1.0 + self.rate * elapsed
        if self.kind == "preload":
            return max(MIN_LEVEL_FACTOR, 1.0 - self.rate * elapsed)
        return 1.0

    def play_mm(self, day: int) -> float:
        """Axial play [mm] this drift opens by ``day`` (0 unless a backlash growth).

        Parameters
        ----------
        day : int
            Day, counted from 0.
        """
        return self.rate * max(0, int(day) - int(self.start_day)) if self.kind == "backlash" else 0.0

    def defect_gain(self, day: int) -> float:
        """Relative friction rise at the centre of the defect's stretch on ``day`` (0 unless a defect).

        Parameters
        ----------
        day : int
            Day, counted from 0.
        """
        return self.rate * max(0, int(day) - int(self.start_day)) if self.kind == "defect" else 0.0


@njit(cache=True)
def play_operator(position_mm, velocity_mm_s, play_mm):
    """Table position and velocity behind an axial play, and whether the play is closed.

    The table starts centred in the play and is carried along only when the motor reaches either side:
    ``y <- clip(y, x - b/2, x + b/2)``.

    Parameters
    ----------
    position_mm, velocity_mm_s : ndarray, shape (n,)
        Motor position [mm] and velocity [mm/s].
    play_mm : float
        Width ``b`` [mm] of the play (0: the table is the motor).

    Returns
    -------
    table_mm, table_velocity_mm_s : ndarray, shape (n,)
        Table position [mm] and velocity [mm/s] (the motor's while the play is closed, else 0).
    closed : ndarray of bool, shape (n,)
        Whether the play is closed (the table is carried).
    """
    n = position_mm.shape[0]
    table = np.empty(n)
    speed = np.empty(n)
    closed = np.empty(n, dtype=np.bool_)
    half = 0.5 * play_mm
    y = position_mm[0] if n > 0 else 0.0
    for i in range(n):
        x = position_mm[i]
        carried = False
        if y <= x - half:
            y = x - half
            carried = velocity_mm_s[i] >= 0.0
        elif y >= x + half:
            y = x + half
            carried = velocity_mm_s[i] <= 0.0
        table[i] = y
        closed[i] = carried or play_mm <= 0.0
        speed[i] = velocity_mm_s[i] if closed[i] else 0.0
    return table, speed, closed


def defect_profile(position_mm, centre_mm: float, width_mm: float) -> np.ndarray:
    """Shape of a local defect along the travel: a raised cosine, 1 at ``centre_mm``, 0 beyond half the width.

    Parameters
    ----------
    position_mm : array_like
        Positions [mm].
    centre_mm : float
        Centre [mm] of the defect's stretch.
    width_mm : float
        Full width [mm] of the stretch (positive).
    """
    offset = (np.asarray(position_mm, dtype=float) - centre_mm) / width_mm
    return np.where(np.abs(offset) < 0.5, 0.5 * (1.0 + np.cos(2.0 * math.pi * offset)), 0.0)


@dataclass(frozen=True)
class AgedPlant(BuiltOnPlant):
    """The twin's plant with an axial play between motor and table and a local defect along the travel.

    Parameters
    ----------
    base : PlantParameters
        The plant without play and defect.
    play_mm : float, default 0.0
        Axial play [mm]; the friction acts on the table behind it.
    defect_gain : float, default 0.0
        Relative rise of the Maxwell-slip friction at the defect's centre (0: none).
    defect_centre_mm : float, default 0.0
        Centre [mm] of the defect's stretch.
    defect_width_mm : float, default 1.0
        Full width [mm] of the defect's stretch.
    """

    base: PlantParameters
    play_mm: float = 0.0
    defect_gain: float = 0.0
    defect_centre_mm: float = 0.0
    defect_width_mm: float = 1.0

    def __post_init__(self):
        if not (self.play_mm >= 0.0 and self.defect_gain >= 0.0 and self.defect_width_mm > 0.0):
            raise GreyboxError("aged plant: play and defect gain must be non-negative, the defect's width positive")

    @property
    def internal_step_s(self) -> float:
        """Fine integration step [s] of the base plant."""
        return self.base.internal_step_s

    def simulate(self, motion, n_samples: int, sample_time_s: float = 0.002) -> PlantResponse:
        """Motion (the motor's) and current at the log samples along ``motion``.

        Parameters
        ----------
        motion : object
            Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``: the motor's motion.
        n_samples : int
            Number of log samples, at times ``k * sample_time_s``.
        sample_time_s : float, default 0.002
            Log sample time [s]; a whole multiple of the fine step.
        """
        p = self.base
        stride, x, v, a = fine_motion(p, motion, n_samples, sample_time_s)
        table, speed, closed = play_operator(np.ascontiguousarray(x, float), np.ascontiguousarray(v, float),
                                             float(self.play_mm))
        maxwell = maxwell_slip_kernel(
            table, speed, p.internal_step_s, stride, p.stiffness_A_mm, np.asarray(p.breakaway_deflection_mm, float),
            p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape, p.lag_time_s)
        x_log, v_log, a_log = x[::stride], v[::stride], a[::stride]
        factor, cogging = p._position_terms(table[::stride])
        factor = factor * (1.0 + self.defect_gain * defect_profile(table[::stride], self.defect_centre_mm,
                                                                    self.defect_width_mm))
        friction = np.where(closed[::stride], factor * maxwell, 0.0) + p.viscous_A_s_mm * speed[::stride]
        return PlantResponse(x_log, v_log, a_log, friction, p.inertia_A_s2_mm * a_log, cogging)

    @property
    def underlying(self) -> PlantParameters:
        """The base plant, which gives the axis file and the process load."""
        return self.base

    def to_dict(self) -> dict:
        """JSON-serialisable parameters: the base plant's, the play and the defect."""
        return {**self.base.to_dict(), "play_mm": float(self.play_mm), "defect_gain": float(self.defect_gain),
                "defect_centre_mm": float(self.defect_centre_mm), "defect_width_mm": float(self.defect_width_mm)}

    def replace(self, **changes) -> "AgedPlant":
        """Return a copy with some parameters replaced."""
        return replace(self, **changes)


def air_move_trajectory(axis: str, feeds_mm_min: Sequence[float] = AIR_MOVE_FEEDS_MM_MIN,
                        cruise_s: float = 1.0, dwell_s: float = 0.2) -> Trajectory:
    """The daily air moves: from the window centre, back and forth at each feed.

    Each move cruises about ``cruise_s`` at its feed (its distance limited to the measurement window),
    first towards negative positions, then back.

    Parameters
    ----------
    axis : {"X", "Y", "C"}
        Axis of the twin.
    feeds_mm_min : sequence of float
        Feeds [mm/min], in the order run.
    cruise_s : float, default 1.0
        Cruise time [s] per move (before the window limit).
    dwell_s : float, default 0.2
        Dwell [s] at the start and after every move.
    """
    geometry = axis_geometry(axis)
    low, high = geometry.window_mm
    profile = MotionProfile(geometry.window_centre_mm)
    profile.hold(dwell_s)
    for feed in feeds_mm_min:
        speed = feed * MM_MIN
        distance = min(speed * cruise_s + profile.limits.ramps_distance([speed]), 0.45 * (high - low))
        for step in (-distance, distance):
            profile.move(step, [speed])
            profile.hold(dwell_s)
    return Trajectory(profile, {"kind": "daily air moves", "feeds_mm_min": [float(f) for f in feeds_mm_min],
                                "duration_s": profile.duration_s})


def _day_seed(seed: int, day: int, axis: str) -> int:
    """A seed of its own for each day and axis."""
    return int(np.random.SeedSequence([int(seed), int(day), ord(axis[0])]).generate_state(1)[0])


def aged_log(axis: str, day: int, seed: int, drifts: Sequence[Drift] = (), *,
             start_date: dt.date = dt.date(2026, 1, 1), machine: str = "twin", cutting=None):
    """The air-move (or production) log of ``axis`` on ``day`` of the ageing twin.

    With ``cutting`` the day is a production day: the same moves, the strokes in the cutting direction
    cutting across the workpiece (:mod:`greybox.twin.cutting`), the others air moves, and a spindle-load
    column :data:`SPINDLE_COLUMN` [%]: :data:`SPINDLE_IDLE_PCT` idle, plus :data:`SPINDLE_CUT_PCT` times the
    process current over the cut's strength, plus 0.5 % of noise.

    Parameters
    ----------
    axis : {"X", "Y", "C"}
        Axis of the twin.
    day : int
        Day, counted from 0.
    seed : int
        Seed of the history (spread and noise of every day follow from it).
    drifts : sequence of Drift
        Drifts acting on the axis; their level factors multiply.
    start_date : datetime.date, default 2026-01-01
        Calendar date of day 0.
    machine : str, default "twin"
        Machine name written to the log's attributes.
    cutting : CuttingSpec, optional
        Cutting conditions of a production day (none: an air-move day).

    Returns
    -------
    AxisLog
        With ``attrs`` ``date`` (ISO), ``machine``, ``day`` and ``drift`` (the kinds, starts, rates and the
        day's level factor).
    """
    geometry = axis_geometry(axis)
    rng = np.random.default_rng(_day_seed(seed, day, geometry.name))
    plant = default_plant_parameters(geometry.name)
    level = float(np.exp(rng.normal(0.0, LEVEL_SPREAD))) * float(np.prod([d.level_factor(day) for d in drifts]))
    viscous = float(np.exp(rng.normal(0.0, VISCOUS_SPREAD)))
    plant = plant.replace(breakaway_A=tuple(level * b for b in plant.breakaway_A),
                          viscous_A_s_mm=viscous * plant.viscous_A_s_mm)
    play = float(sum(d.play_mm(day) for d in drifts))
    defect = float(sum(d.defect_gain(day) for d in drifts))
    plant = AgedPlant(plant, play, defect, geometry.window_centre_mm + DEFECT_CENTRE_OFFSET_MM, DEFECT_WIDTH_MM)
    log = make_dataset(geometry.name, HISTORY_DATASET, _day_seed(seed, day, geometry.name),
                       plant=plant, trajectory=air_move_trajectory(geometry.name), cutting=cutting)
    if cutting is not None:
        spindle = SPINDLE_IDLE_PCT + SPINDLE_CUT_PCT * np.abs(log.extras["truth_process_A"]) / cutting.strength_A
        spindle = spindle + rng.normal(0.0, 0.5, len(log))
        log = log.replace(extras={**log.extras, SPINDLE_COLUMN: np.round(spindle, 2)})
    date = start_date + dt.timedelta(days=int(day))
    attrs = {**log.attrs, "date": date.isoformat(), "machine": machine, "day": int(day),
             "drift": {"drifts": [{"kind": d.kind, "start_day": int(d.start_day), "rate": float(d.rate)}
                                  for d in drifts], "level_factor": level, "viscous_factor": viscous,
                       "play_mm": play, "defect_gain": defect}}
    return log.replace(attrs=attrs)


def synthesize_history(axes: Sequence[str], days: int, seed: int, out_dir, drifts: Sequence[Drift] = (), *,
                       start_date: dt.date = dt.date(2026, 1, 1), machine: str = "twin",
                       truth_channels: Sequence[str] | None = None, cutting=None,
                       progress: Callable[[str], None] | None = None) -> list[Path]:
    """Write ``days`` daily air-move (or production) logs per axis as ``out_dir/<axis>_<date>.mcap``.

    Parameters
    ----------
    axes : sequence of str
        Axes of the twin.
    days : int
        Number of days (at least 1).
    seed : int
        Seed of the history.
    out_dir : path-like
        Output directory (created if missing).
    drifts : sequence of Drift
        Drifts acting on every axis.
    start_date : datetime.date, default 2026-01-01
        Calendar date of day 0.
    machine : str, default "twin"
        Machine name written to the logs.
    truth_channels : sequence of str, optional
        Truth channels kept (:func:`greybox.twin.datasets.stored`); all by default.
    cutting : CuttingSpec, optional
        Production days: cutting conditions (:func:`aged_log`); the spindle-load column is kept.
    progress : callable, optional
        Called with one line per axis written.

    Returns
    -------
    list of Path
        The files written, day by day.
    """
    from ..data.io import write_log

    if isinstance(days, bool) or not isinstance(days, (int, np.integer)) or days < 1:
        raise GreyboxError(f"days must be a positive whole number, got {days!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for axis in axes:
        for day in range(days):
            log = aged_log(axis, day, seed, drifts, start_date=start_date, machine=machine, cutting=cutting)
            path = out / f"{log.axis}_{log.attrs['date']}.mcap"
            kept = stored(log, truth_channels)
            if SPINDLE_COLUMN in log.extras:
                kept = kept.replace(extras={**kept.extras, SPINDLE_COLUMN: log.extras[SPINDLE_COLUMN]})
            write_log(kept, path)
            written.append(path)
        if progress is not None:
            kind = "production" if cutting is not None else "air-move"
            progress(f"{axis}: {days} daily {kind} logs from {start_date.isoformat()} -> {out}")
    return written
