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

from os import PathLike
from pathlib import Path
from typing import NamedTuple, Sequence

import numpy as np

from ..data.log import AxisLog
from ..errors import GreyboxError
from ..nc.blocks import Dwell, Move, Program
from ..nc.gcode import read_program
from .axes import AxisGeometry, axis_geometry
from .datasets import make_dataset, stored
from .motion import MotionLimits, MotionProfile
from .trajectories import Trajectory

__all__ = ["RAPID_FEED", "ProgramRun", "program_trajectory", "synthesize_program"]

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


class ProgramRun(NamedTuple):
    """What :func:`synthesize_program` wrote.

    Attributes
    ----------
    log : AxisLog
        The simulated log (all its truth channels).
    path : pathlib.Path
        The file written, ``out_dir/<axis>_<program name>.mcap``.
    program : Program
        The program read.
    trajectory : Trajectory
        The motion the twin ran; ``trajectory.description["feeds_lowered"]`` lists the strokes whose feeds
        the acceleration limit lowered.
    """

    log: AxisLog
    path: Path
    program: Program
    trajectory: Trajectory


def synthesize_program(program_path: str | PathLike, seed: int, out_dir: str | PathLike, *, force: bool = False,
                       truth_channels: Sequence[str] | None = None, **options) -> ProgramRun:
    """Run a one-axis NC program on the twin axis it moves and write the log as MCAP.

    Parameters
    ----------
    program_path : str or path-like
        G-code program file (:func:`greybox.nc.gcode.read_program`).
    seed : int
        Master seed (see :func:`~greybox.twin.datasets.make_dataset`).
    out_dir : str or path-like
        Output directory, created if missing; the log is ``out_dir/<axis>_<program name>.mcap``.
    force : bool, default False
        Overwrite an existing file; otherwise it is an error and nothing is written.
    truth_channels : sequence of str, optional
        Truth channels to keep in the file (default all), e.g.
        :data:`~greybox.twin.datasets.ESSENTIAL_TRUTH_CHANNELS`.
    **options
        Passed to :func:`~greybox.twin.datasets.make_dataset` (effect, effect_strength, effect_params,
        cutting, noise, ...).

    Returns
    -------
    ProgramRun
        The log, the file written, the program and the twin's trajectory.

    Raises
    ------
    GreyboxError
        For a program that cannot be read or run, or an existing file without ``force``.
    """
    from ..data.io import write_log

    program = read_program(program_path)
    geometry = axis_geometry(program.axis)
    trajectory = program_trajectory(program, geometry)
    out = Path(out_dir) / f"{geometry.name}_{Path(program_path).stem}.mcap"
    if out.exists() and not force:
        raise GreyboxError(f"{out}: file exists; pass --force to overwrite it")
    log = make_dataset(geometry.name, "N", seed, trajectory=trajectory, **options)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_log(stored(log, truth_channels), out)
    return ProgramRun(log, out, program, trajectory)
