"""The air-cut plan: an NC program that records the paper's datasets A and B on a machine.

Rüppel et al. (2024) train on air cuts of two kinds (their Table 1): dataset A, random feed steps
with reversals and sinusoidal motion inside a short measurement window in the middle of the
travel, and dataset B, constant-feed sweeps over the whole travel. :func:`plan_air_cuts` writes
both as one program, after a warm-up block (slow strokes over the travel that spread the
lubricant and warm the screw, so that the recording does not start on a cold axis):

1. warm-up: ``warmup_strokes`` times back and forth over the travel at ``warmup_feed``;
2. dataset A, about ``duration_a_s`` seconds inside the window, alternating

   - random moves: 1-3 feeds each (log-uniform in ``feed``), written as consecutive feed
     moves in one direction (the control changes the feed on the fly), reversals, and
     now and then a short dwell;
   - sinusoidal motion ``x = c + a sin(w t)`` around the window centre, 3-6 periods, as short
     feed moves (24 per period) whose feed is the mean speed over the move, the peak speed
     log-uniform in ``feed`` and the peak acceleration ``a w^2`` within ``max_acceleration``;

3. dataset B: for each of ``sweep_feeds``, once back and forth over the travel, dwelling at
   each end.

Limits are checked before anything is written: the window inside the travel, feeds positive
and within ``max_feed``, the window long enough to reach the highest feed and stop again
at ``max_acceleration`` (``v^2 / a`` per stroke).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import GreyboxError
from .blocks import AXIS_LETTERS, Dwell, Move, Program

__all__ = ["AirCutPlan", "plan_air_cuts", "SEGMENTS_PER_PERIOD", "MIN_DURATION_A_S"]

#: Feed moves per period of the sinusoidal motion (a multiple of 4: the reversals fall on block ends).
SEGMENTS_PER_PERIOD = 24

#: Shortest dataset A [s]: at least one block of random moves and one sinusoidal motion.
MIN_DURATION_A_S = 10.0


@dataclass(frozen=True)
class AirCutPlan:
    """What an air-cut programme covers, in the axis's units (mm, or deg for A, B, C).

    Parameters
    ----------
    axis : str
        NC address letter: X, Y, Z (mm) or A, B, C (deg).
    travel : (float, float)
        Ends of the travel the sweeps of dataset B cross [mm].
    window : (float, float)
        The measurement window of dataset A, inside the travel [mm].
    feed : (float, float)
        Lowest and highest feed of dataset A [mm/min].
    sweep_feeds : tuple of float, default (600, 1800)
        Feeds of the sweeps of dataset B [mm/min] (the paper's).
    duration_a_s : float, default 120
        Approximate length of dataset A [s].
    warmup_strokes : int, default 2
        Back-and-forth strokes over the travel before the recording; 0 for none.
    warmup_feed : float, default 1000
        Feed of the warm-up [mm/min].
    max_feed : float, default 10000
        Highest feed the axis may be programmed [mm/min].
    max_acceleration : float, default 1000
        Acceleration the axis reaches [mm/s^2], for the checks and the sine's frequency.
    dwell_s : float, default 0.2
        Dwell at the ends of the sweeps [s].
    """

    axis: str
    travel: tuple
    window: tuple
    feed: tuple
    sweep_feeds: tuple = (600.0, 1800.0)
    duration_a_s: float = 120.0
    warmup_strokes: int = 2
    warmup_feed: float = 1000.0
    max_feed: float = 10000.0
    max_acceleration: float = 1000.0
    dwell_s: float = 0.2

    @property
    def unit(self) -> str:
        """Length unit: ``"mm"`` or ``"deg"``."""
        return "mm" if AXIS_LETTERS[self.axis] == "linear" else "deg"

    def check(self) -> None:
        """Raise :class:`GreyboxError` (naming the option) for a plan the axis cannot run."""
        unit = self.unit
        if self.axis not in AXIS_LETTERS:
            raise GreyboxError(f"--axis {self.axis}: an NC axis letter is one of {', '.join(AXIS_LETTERS)}")
        low, high = self.travel
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise GreyboxError(f"--travel {low:g}:{high:g}: give LOW:HIGH with LOW < HIGH [{unit}]")
        w_low, w_high = self.window
        if not (low <= w_low < w_high <= high):
            raise GreyboxError(f"--window {w_low:g}:{w_high:g}: the window must lie inside the travel "
                               f"{low:g}:{high:g} {unit}, LOW < HIGH")
        f_low, f_high = self.feed
        if not (0 < f_low < f_high):
            raise GreyboxError(f"--feed {f_low:g}:{f_high:g}: give LOW:HIGH with 0 < LOW < HIGH [{unit}/min]")
        for option, values in (("--feed", self.feed), ("--sweep-feeds", self.sweep_feeds),
                               ("--warmup-feed", (self.warmup_feed,))):
            for value in values:
                if not 0 < value <= self.max_feed:
                    raise GreyboxError(f"{option}: feed {value:g} {unit}/min is outside (0, {self.max_feed:g}] "
                                       f"(--max-feed)")
        if not self.max_acceleration > 0:
            raise GreyboxError(f"--max-acceleration must be positive [{unit}/s^2], got {self.max_acceleration:g}")
        reach = _stopping_distance(f_high, self.max_acceleration)
        if 2.0 * reach > 0.5 * (w_high - w_low):
            raise GreyboxError(
                f"--window {w_low:g}:{w_high:g}: {w_high - w_low:g} {unit} is too short to reach {f_high:g} "
                f"{unit}/min and stop again at {self.max_acceleration:g} {unit}/s^2 (needs {4 * reach:.1f} {unit}); "
                "widen the window, lower --feed or raise --max-acceleration")
        for feed in self.sweep_feeds:
            if 2.0 * _stopping_distance(feed, self.max_acceleration) > high - low:
                raise GreyboxError(f"--sweep-feeds: {feed:g} {unit}/min cannot be reached over the travel at "
                                   f"{self.max_acceleration:g} {unit}/s^2")
        if not self.duration_a_s >= MIN_DURATION_A_S:
            raise GreyboxError(f"--duration-a {self.duration_a_s:g}: dataset A needs at least {MIN_DURATION_A_S:g} s "
                               "(random feed steps with reversals, then a sinusoidal motion)")
        if self.warmup_strokes < 0 or not self.dwell_s >= 0:
            raise GreyboxError("the warm-up strokes and the dwell must not be negative")

    def to_dict(self) -> dict:
        """The settings as a JSON-able dict."""
        return {key: list(value) if isinstance(value, tuple) else value for key, value in asdict(self).items()}


def _stopping_distance(feed_per_min: float, acceleration: float) -> float:
    """Distance to reach ``feed_per_min`` from rest at constant ``acceleration`` (per s^2)."""
    speed = feed_per_min / 60.0
    return speed * speed / (2.0 * acceleration)


def _log_uniform(rng, low, high, size=None):
    return np.exp(rng.uniform(np.log(low), np.log(high), size))


class _Writer:
    """Appends blocks, tracking the position and the section titles."""

    def __init__(self, start: float):
        self.blocks = [Move(start, None)]
        self.sections = []
        self.position = start

    def section(self, title: str) -> None:
        self.sections.append((len(self.blocks), title))

    def move(self, target: float, feed: float) -> None:
        self.blocks.append(Move(round(float(target), 4), round(float(feed), 1)))
        self.position = round(float(target), 4)

    def dwell(self, seconds: float) -> None:
        self.blocks.append(Dwell(round(float(seconds), 3)))


def _random_moves(out: _Writer, plan: AirCutPlan, rng, low: float, high: float, until_s: float) -> float:
    """Random moves inside [low, high] for about ``until_s`` seconds; return the time they take [s]."""
    elapsed = 0.0
    while elapsed < until_s:
        room_up, room_down = high - out.position, out.position - low
        direction = 1.0 if rng.uniform() < room_up / (room_up + room_down) else -1.0
        room = room_up if direction > 0 else room_down
        feeds = _log_uniform(rng, *plan.feed, size=int(rng.integers(1, 4)))
        distance = room * rng.uniform(0.4, 1.0)
        reach = 2.0 * _stopping_distance(float(feeds.max()), plan.max_acceleration)
        if distance < 2.0 * reach:  # too little room to reach the feeds and stop: one slow move
            feeds = np.array([plan.feed[0]])
        weights = rng.uniform(0.5, 1.5, size=feeds.size)
        lengths = distance * weights / weights.sum()
        for length, feed in zip(lengths, feeds):
            out.move(out.position + direction * length, feed)
            elapsed += 60.0 * length / feed
        if rng.uniform() < 0.1:
            pause = rng.uniform(0.05, 0.5)
            out.dwell(pause)
            elapsed += pause
    return elapsed


def _sine(out: _Writer, plan: AirCutPlan, rng, low: float, high: float) -> float:
    """Sinusoidal motion around the window centre as short feed moves; return its length [s]."""
    centre, half = 0.5 * (low + high), 0.5 * (high - low)
    elapsed = 0.0
    if abs(out.position - centre) > 1e-9:
        feed = float(_log_uniform(rng, *plan.feed))
        elapsed += 60.0 * abs(centre - out.position) / feed
        out.move(centre, feed)
    amplitude = half * rng.uniform(0.3, 0.9)
    # peak speed per s; a sine of a low peak spends most of its time below the lowest feed
    peak = float(_log_uniform(rng, min(3.0 * plan.feed[0], plan.feed[1]), plan.feed[1])) / 60.0
    omega = peak / amplitude
    if amplitude * omega ** 2 > plan.max_acceleration:  # keep the peak acceleration within the limit
        omega = math.sqrt(plan.max_acceleration / amplitude)
    periods = int(rng.integers(3, 7))
    steps = SEGMENTS_PER_PERIOD * periods
    step_s = 2.0 * math.pi / omega / SEGMENTS_PER_PERIOD
    positions = centre + amplitude * np.sin(omega * step_s * np.arange(1, steps + 1))
    previous = centre
    for position in positions:
        feed = max(60.0 * abs(position - previous) / step_s, plan.feed[0])
        out.move(position, min(feed, plan.feed[1]))
        previous = position
    return elapsed + steps * step_s


def plan_air_cuts(plan: AirCutPlan, seed: int = 0) -> Program:
    """The air-cut program of ``plan`` (see the module docstring), drawn with ``seed``.

    Parameters
    ----------
    plan : AirCutPlan
        Axis, travel, window, feeds and limits; checked first.
    seed : int, default 0
        Seed of the random moves and sines (the same seed gives the same program).

    Returns
    -------
    Program
        Starting with a rapid move to the window centre; sections ``warm-up``, ``dataset A``,
        ``dataset B``.

    Raises
    ------
    GreyboxError
        For a plan that fails :meth:`AirCutPlan.check`.
    """
    plan.check()
    rng = np.random.default_rng(seed)
    unit = plan.unit
    low, high = plan.travel
    margin = 0.02 * (plan.window[1] - plan.window[0])
    w_low, w_high = plan.window[0] + margin, plan.window[1] - margin
    out = _Writer(0.5 * (plan.window[0] + plan.window[1]))
    if plan.warmup_strokes:
        out.section(f"warm-up: {plan.warmup_strokes} strokes over the travel at {plan.warmup_feed:g} {unit}/min")
        for _ in range(plan.warmup_strokes):
            out.move(low, plan.warmup_feed)
            out.move(high, plan.warmup_feed)
        out.move(0.5 * (plan.window[0] + plan.window[1]), plan.warmup_feed)
        out.dwell(1.0)
    out.section(f"dataset A: random feed steps and sinusoidal motion in the window {plan.window[0]:g}.."
                f"{plan.window[1]:g} {unit}, feeds {plan.feed[0]:g}-{plan.feed[1]:g} {unit}/min")
    elapsed = 0.0
    random_steps = True
    while elapsed < plan.duration_a_s or not random_steps:  # ends after a sine: both kinds are in
        if random_steps:
            elapsed += _random_moves(out, plan, rng, w_low, w_high, min(rng.uniform(15.0, 30.0),
                                                                         plan.duration_a_s - elapsed))
        else:
            elapsed += _sine(out, plan, rng, w_low, w_high)
        random_steps = not random_steps
    out.dwell(0.5)
    out.section(f"dataset B: constant feeds {', '.join(f'{f:g}' for f in plan.sweep_feeds)} {unit}/min over the "
                f"travel {low:g}..{high:g} {unit}")
    out.move(high, plan.sweep_feeds[0])
    out.dwell(plan.dwell_s)
    for feed in plan.sweep_feeds:
        out.move(low, feed)
        out.dwell(plan.dwell_s)
        out.move(high, feed)
        out.dwell(plan.dwell_s)
    return Program(axis=plan.axis, blocks=tuple(out.blocks), sections=tuple(out.sections))
