"""Parts of a simple repeated program, built in memory with known content (no twin, no model)."""

from __future__ import annotations

import numpy as np

from greybox.process.envelope import level_direction
from greybox.process.parts import Part

DT = 0.002


def program_velocity(wait_s: float = 1.0, dwell_s: float = 0.5) -> np.ndarray:
    """Rest, a slow stroke in -x (air 1 s, cut 4 s, air 1 s), a dwell, a fast return in +x (2 s), rest 0.5 s."""
    return np.concatenate([np.full(int(round(length / DT)), speed) for length, speed in _blocks(wait_s, dwell_s)])


def _blocks(wait_s: float, dwell_s: float) -> list[tuple[float, float]]:
    return [(wait_s, 0.0), (6.0, -10.0), (dwell_s, 0.0), (2.0, 30.0), (0.5, 0.0)]


def program_blocks(wait_s: float = 1.0, dwell_s: float = 0.5) -> np.ndarray:
    """The NC block number (10, 20, ...) of each sample of :func:`program_velocity`."""
    return np.concatenate([np.full(int(round(length / DT)), 10.0 * (k + 1))
                           for k, (length, _) in enumerate(_blocks(wait_s, dwell_s))])


def make_part(number: int, rng: np.random.Generator, *, wait_s: float = 1.0, cut: float = 1.0, friction: float = 1.0,
              break_at_s: float | None = None, bump_at_s: float | None = None, noise: float = 0.05,
              with_level: bool = False, dwell_s: float = 0.5, blocks: bool = False) -> Part:
    """A part: friction (times ``friction``) of the direction plus a cut of ``cut`` in the cut stroke, plus noise.

    The cut runs from 1 s to 5 s after the start of the slow stroke; ``break_at_s`` (since the part's first
    sample) ends it early, ``bump_at_s`` adds a 0.3 s load in the fast return's direction of motion; ``blocks``
    adds the NC block number column.
    """
    v = program_velocity(wait_s, dwell_s)
    extras = {"block": program_blocks(wait_s, dwell_s)} if blocks else {}
    n = v.size
    time = np.arange(n) * DT
    sign = np.sign(v)
    model_friction = level_direction(v)  # the friction a model would predict: at rest the last motion's, held
    start = wait_s
    cutting = (time >= start + 1.0) & (time < start + 5.0)
    if break_at_s is not None:
        cutting &= time < break_at_s
    load = np.where(cutting, cut, 0.0)
    if bump_at_s is not None:
        load = load + np.where((time >= bump_at_s) & (time < bump_at_s + 0.3), 1.0, 0.0)
    process = sign * load
    measured = friction * model_friction + process + noise * rng.standard_normal(n)
    if with_level:
        return Part("series.csv", number, 0.0, time, v, measured - model_friction, extras, level=model_friction)
    return Part("series.csv", number, 0.0, time, v, measured, extras)


def good_parts(count: int, seed: int = 0, **options) -> list[Part]:
    """``count`` good parts with random waits of 1-1.1 s."""
    rng = np.random.default_rng(seed)
    return [make_part(k + 1, rng, wait_s=float(rng.uniform(1.0, 1.1)), **options) for k in range(count)]
