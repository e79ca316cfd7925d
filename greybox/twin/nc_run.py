"""The twin runs an NC program: the blocks of a one-axis program as a jerk-limited motion.

A control with look-ahead runs consecutive feed moves in one direction without stopping: the feed
changes on the fly at the block boundary, and the axis stops only where the direction reverses,
at a dwell and at the end. :func:`program_trajectory` does the same with the twin's motion
profiles (:class:`~greybox.twin.motion.MotionProfile`): each stroke from rest to rest visits the
feeds of its blocks in order, the cruise at each feed as long as its block; when the strokes'
ramps do not fit into its length at the twin's acceleration and jerk limits, every feed of the
stroke is lowered by one factor until they do, as a control's look-ahead lowers the feed.
Rapid moves (G0) run at :data:`RAPID_FEED`.
"""

from __future__ import annotations

import numpy as np

from ..errors import GreyboxError
from ..nc.blocks import Dwell, Move, Program
from .axes import AxisGeometry
from .motion import MotionLimits, MotionProfile
from .trajectories import Trajectory

__all__ = ["RAPID_FEED", "program_trajectory"]

#: Feed of rapid moves (G0) on the twin [mm/min or deg/min].
RAPID_FEED = 10000.0


def _strokes(program: Program):
    """Yield ``("dwell", seconds)`` and ``("stroke", direction, lengths, speeds_per_s, first_line)``."""
    position = program.blocks[0].target
    pending: list = []

    def stroke():
        if not pending:
            return None
        direction, lengths, speeds, line = pending[0][0], [p[1] for p in pending], [p[2] for p in pending], \
            pending[0][3]
        pending.clear()
        return ("stroke", direction, np.array(lengths), np.array(speeds), line)

    for block in program.blocks[1:]:
        if isinstance(block, Dwell):
            done = stroke()
            if done:
                yield done
            yield ("dwell", block.seconds)
            continue
        distance = block.target - position
        position = block.target
        if distance == 0.0:
            continue
        direction = 1.0 if distance > 0 else -1.0
        if pending and pending[0][0] != direction:
            yield stroke()
        feed = RAPID_FEED if block.feed is None else block.feed
        pending.append((direction, abs(distance), feed / 60.0, block.line))
    done = stroke()
    if done:
        yield done


def _fitting_factor(limits: MotionLimits, length: float, speeds: np.ndarray) -> float:
    """Largest factor <= 1 by which the speeds can be scaled so that the stroke's ramps fit into ``length``."""
    if limits.ramps_distance(speeds) <= length:
        return 1.0
    low, high = 0.0, 1.0
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if limits.ramps_distance(middle * speeds) <= length else (low, middle)
    return low


def program_trajectory(program: Program, geometry: AxisGeometry, limits: MotionLimits | None = None) -> Trajectory:
    """The motion of the twin's axis running ``program``.

    Parameters
    ----------
    program : Program
        A one-axis program (:func:`greybox.nc.gcode.read_program`); its axis must be ``geometry``'s
        and its first move the start position.
    geometry : AxisGeometry
        The twin axis; every position of the program must lie in its travel.
    limits : MotionLimits, optional
        Acceleration and jerk limits (default the twin's).

    Returns
    -------
    Trajectory
        Starting at rest at the first position; ``description`` names the program, its blocks and
        the strokes whose feeds the limits lowered.

    Raises
    ------
    GreyboxError
        For a program of another axis or kind of axis, or a position outside the travel (naming the line).
    """
    where = program.source or "the NC program"
    if program.axis != geometry.name:
        raise GreyboxError(f"{where}: the program moves {program.axis}, the twin axis is {geometry.name}")
    if program.motion != geometry.motion:
        raise GreyboxError(f"{where}: {program.axis} is a {program.motion} axis, the twin's {geometry.name} a "
                           f"{geometry.motion} one")
    low, high = geometry.travel_mm
    for block in program.blocks:
        if isinstance(block, Move) and not low <= block.target <= high:
            raise GreyboxError(f"{where}: line {block.line}: {program.axis}{block.target:g} lies outside the twin's "
                               f"travel {low:g}..{high:g}")
    profile = MotionProfile(program.blocks[0].target, limits)
    profile.hold(0.5)
    slowed = []
    for step in _strokes(program):
        if step[0] == "dwell":
            profile.hold(step[1])
            continue
        _, direction, lengths, speeds, line = step
        factor = _fitting_factor(profile.limits, float(lengths.sum()), speeds)
        if factor < 1.0:
            slowed.append({"line": line, "factor": factor})
        if factor <= 0.0:
            raise GreyboxError(f"{where}: line {line}: a stroke of {lengths.sum():.3g} too short to move at all")
        profile.move(direction * float(lengths.sum()), factor * speeds, lengths)
    profile.hold(0.5)
    return Trajectory(profile, {
        "kind": "NC program",
        "program": program.source,
        "blocks": len(program.blocks),
        "feeds_lowered": slowed,
        "max_acceleration_mm_s2": profile.limits.max_acceleration_mm_s2,
        "max_jerk_mm_s3": profile.limits.max_jerk_mm_s3,
    })
