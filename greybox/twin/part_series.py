"""A part series on the twin: one NC program cut again and again over a shift, through the warm-up.

Every part runs the same one-axis program (by default :func:`part_program`: passes across a workpiece at
several feeds, each with an air approach and exit at the cut's feed and an air return); before each part the
axis waits at rest for the loading time plus a random delay (the small timing differences of real parts).
Each part is simulated on its own: a short stroke in the direction of the program's last one
(:data:`LEAD_IN_MM`), cut off the log, leaves the friction held that the previous part left, so that the
parts joined into one long log are what a continuous run would log.

**Warm-up law.** The machine's warmth ``theta`` in [0, 1] rises while it runs (parts and loading times) and
falls during a pause, both first order::

    running:  theta(t) = 1 - (1 - theta_0) exp(-t / tau_warm)
    paused:   theta(t) = theta_0 exp(-t / tau_cool)

starting cold (``theta = 0``). The friction (the Maxwell-slip levels and the viscous part alike) is the cold
plant's times ``s = 1 - drop * theta``: with ``drop = 0.25`` it falls by 25 % when fully warm, by
``0.25 (1 - 1/e)`` = 15.8 % after one ``tau_warm``. Scaling a Maxwell-slip plant's stiffnesses and breakaway
levels together leaves its deflections as they were, so the scaled friction is exactly the cold one times ``s``.

**Tool events** (:class:`ToolEvents`), factors of the cutting load of a part: gradual wear (``1 + w (k - k_0)``
from part ``k_0`` on), a breakage (0 from a time inside its part on, and in every later part: the load falls
to the air level), a missing blank (0 for the part), an oversized blank (a factor, deeper cut).

:func:`synthesize_part_series` writes one log per part and/or one long log with a ``part`` column (the part
counter a control logs) and a ``block`` column (the program line of the NC block being run, :func:`block_numbers`),
and the truth beside them as JSON.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from os import PathLike
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..atomic import write_text_atomic
from ..data.log import AxisLog
from ..errors import GreyboxError
from ..json_values import jsonable
from ..nc.blocks import Dwell, Move, Program
from .axes import axis_geometry
from .built_on import BuiltOnPlant
from .cutting import CuttingSpec, cutting_current
from .datasets import SAMPLE_TIME_S, make_dataset, stored
from .nc_run import program_trajectory
from .noise import CurrentNoise
from .plant import default_plant_parameters

__all__ = ["PART_FEEDS_MM_MIN", "PART_COLUMN", "BLOCK_COLUMN", "PartSeriesSpec", "block_numbers", "ToolEvents",
           "WarmUp", "WarmPlant",
           "part_program", "make_part_series", "synthesize_part_series"]

#: Feeds [mm/min] of the passes of the default part program, in order.
PART_FEEDS_MM_MIN = (300.0, 400.0, 500.0, 600.0, 350.0, 450.0, 550.0)
#: Name of the part-counter column of the logs.
PART_COLUMN = "part"
#: Name of the NC block column of the logs: the program line of the block being run, per sample.
BLOCK_COLUMN = "block"
#: The default part on X: the air approach starts at PART_START_MM, the cut crosses the workpiece
#: PART_WORKPIECE_MM, the pass ends at PART_END_MM, the return runs at PART_RETURN_FEED_MM_MIN.
PART_START_MM, PART_END_MM, PART_WORKPIECE_MM, PART_RETURN_FEED_MM_MIN = -226.0, -272.0, (-264.0, -236.0), 2000.0
#: Cut strength [A] of the default part series (mean process current at 1000 mm/min, full engagement).
PART_STRENGTH_A = 0.5


def part_program(axis: str = "X", feeds_mm_min: Sequence[float] = PART_FEEDS_MM_MIN) -> Program:
    """The default part: one pass per feed across the workpiece, in air before and after, and back.

    Parameters
    ----------
    axis : str, default "X"
        Axis letter of the program.
    feeds_mm_min : sequence of float
        Feed [mm/min] of each pass; the approach to the workpiece and the exit run at the same feed, the
        return at :data:`PART_RETURN_FEED_MM_MIN`.
    """
    blocks: list = [Move(PART_START_MM, None, 1)]
    for feed in feeds_mm_min:
        blocks.append(Move(PART_END_MM, float(feed), len(blocks) + 1))
        blocks.append(Move(PART_START_MM, PART_RETURN_FEED_MM_MIN, len(blocks) + 1))
    return Program(axis, tuple(blocks), source="part program")


@dataclass(frozen=True)
class WarmUp:
    """The friction's warm-up law (module docstring).

    Parameters
    ----------
    drop : float, default 0.25
        Share by which the friction falls on a fully warm machine, in [0, 1).
    time_constant_s : float, default 2400.0
        ``tau_warm`` [s] of the warming while the machine runs.
    cooling_time_constant_s : float, default 2400.0
        ``tau_cool`` [s] of the cooling during a pause.
    """

    drop: float = 0.25
    time_constant_s: float = 2400.0
    cooling_time_constant_s: float = 2400.0

    def __post_init__(self):
        if not 0.0 <= self.drop < 1.0:
            raise GreyboxError(f"warm-up: the friction drop must be in [0, 1), got {self.drop}")
        if not (self.time_constant_s > 0 and self.cooling_time_constant_s > 0):
            raise GreyboxError("warm-up: the time constants must be positive")

    def running(self, warmth: float, elapsed_s):
        """Warmth after running ``elapsed_s`` [s] from ``warmth``.

        Parameters
        ----------
        warmth : float
            Warmth at the start, in [0, 1].
        elapsed_s : float or array_like
            Running time [s].
        """
        return 1.0 - (1.0 - warmth) * np.exp(-np.asarray(elapsed_s, dtype=float) / self.time_constant_s)

    def paused(self, warmth: float, elapsed_s: float) -> float:
        """Warmth after a pause of ``elapsed_s`` [s] from ``warmth``.

        Parameters
        ----------
        warmth : float
            Warmth at the start of the pause, in [0, 1].
        elapsed_s : float
            Length of the pause [s].
        """
        return float(warmth * np.exp(-float(elapsed_s) / self.cooling_time_constant_s))

    def level(self, warmth):
        """Friction factor ``1 - drop * warmth`` at a warmth.

        Parameters
        ----------
        warmth : float or array_like
            Warmth, in [0, 1].
        """
        return 1.0 - self.drop * np.asarray(warmth, dtype=float)


class WarmPlant(BuiltOnPlant):
    """A truth plant whose friction is scaled sample by sample by the warm-up law.

    Parameters
    ----------
    plant : PlantParameters
        The cold plant.
    warm_up : WarmUp
        The law.
    warmth : float
        Warmth at the log's first sample; the machine runs throughout the log.
    """

    def __init__(self, plant, warm_up: WarmUp, warmth: float):
        self.plant = plant
        self.warm_up = warm_up
        self.warmth = float(warmth)

    def simulate(self, motion, n_samples: int, sample_time_s: float = SAMPLE_TIME_S):
        """The cold plant's response with its friction times the warm-up factor.

        Parameters
        ----------
        motion : object
            Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
        n_samples : int
            Number of log samples.
        sample_time_s : float
            Log sample time [s].
        """
        response = self.plant.simulate(motion, n_samples, sample_time_s)
        factor = self.warm_up.level(self.warm_up.running(self.warmth, np.arange(n_samples) * sample_time_s))
        return replace(response, friction_A=response.friction_A * factor)

    @property
    def underlying(self):
        """The cold plant, which gives the axis file and the process load."""
        return self.plant

    def to_dict(self) -> dict:
        """The cold plant's parameters with the warm-up law and the starting warmth."""
        return {**self.plant.to_dict(), "warm_up": asdict(self.warm_up), "warmth_at_start": self.warmth}


@dataclass(frozen=True)
class ToolEvents:
    """Tool and blank events of a part series (parts counted from 1).

    Parameters
    ----------
    wear_pct_per_part : float, default 0.0
        Rise [%] of the cutting load per part from ``wear_start_part`` on.
    wear_start_part : int, default 1
        Last part of the sharp tool: part ``k`` cuts with ``1 + wear (k - start)`` for ``k > start``.
    breakage_part : int, optional
        Part in which the tool breaks; from then on the cutting load is 0.
    breakage_time_s : float, optional
        Time [s] since the part's log start at which it breaks (needs ``breakage_part``).
    missing_blank : tuple of int, default ()
        Parts without a blank: no cutting load.
    oversized_blank : tuple of int, default ()
        Parts with an oversized blank: the load times ``oversize_factor``.
    oversize_factor : float, default 1.3
        Factor of the load of an oversized blank, above 1.
    """

    wear_pct_per_part: float = 0.0
    wear_start_part: int = 1
    breakage_part: int | None = None
    breakage_time_s: float | None = None
    missing_blank: tuple = ()
    oversized_blank: tuple = ()
    oversize_factor: float = 1.3

    def __post_init__(self):
        if not (np.isfinite(self.wear_pct_per_part) and self.wear_pct_per_part >= 0):
            raise GreyboxError(f"tool wear must be a non-negative percent per part, got {self.wear_pct_per_part}")
        if (self.breakage_part is None) != (self.breakage_time_s is None):
            raise GreyboxError("a breakage needs both its part and its time")
        if self.breakage_time_s is not None and not self.breakage_time_s >= 0:
            raise GreyboxError(f"breakage time must be non-negative, got {self.breakage_time_s}")
        parts = [*self.missing_blank, *self.oversized_blank, *([self.breakage_part] if self.breakage_part else [])]
        if any(int(p) != p or p < 1 for p in parts):
            raise GreyboxError("parts of tool events are counted from 1")
        if int(self.wear_start_part) != self.wear_start_part or self.wear_start_part < 0:
            raise GreyboxError(f"wear start part must be a whole number >= 0, got {self.wear_start_part}")
        if not self.oversize_factor > 1.0:
            raise GreyboxError(f"oversize factor must be above 1, got {self.oversize_factor}")

    def scale(self, part: int, time_s) -> np.ndarray:
        """Factor of the cutting load of ``part`` at times ``time_s`` [s] since the part's log start.

        Parameters
        ----------
        part : int
            Part number, from 1.
        time_s : array_like, shape (n,)
            Times [s] since the start of the part's log.
        """
        t = np.asarray(time_s, dtype=float)
        factor = 1.0 + 0.01 * self.wear_pct_per_part * max(0, part - self.wear_start_part)
        if part in self.missing_blank:
            factor = 0.0
        elif part in self.oversized_blank:
            factor *= self.oversize_factor
        scale = np.full(t.shape, factor)
        if self.breakage_part is not None:
            if part > self.breakage_part:
                scale[:] = 0.0
            elif part == self.breakage_part:
                scale[t >= self.breakage_time_s] = 0.0
        return scale

    def worn_part(self, rise_pct: float) -> int | None:
        """First part whose wear reaches ``rise_pct`` [%] (None without wear).

        Parameters
        ----------
        rise_pct : float
            Rise [%] of the cutting load.
        """
        if self.wear_pct_per_part <= 0:
            return None
        return int(self.wear_start_part + np.ceil(rise_pct / self.wear_pct_per_part - 1e-9))


@dataclass(frozen=True)
class PartSeriesSpec:
    """A part series.

    Parameters
    ----------
    parts : int, default 20
        Number of parts.
    axis : str, default "X"
        Twin axis.
    program : Program, optional
        The part's program (default :func:`part_program` of ``axis``).
    cutting : CuttingSpec, optional
        Cutting conditions; default strength :data:`PART_STRENGTH_A`, the workpiece of the default part
        (:data:`PART_WORKPIECE_MM`) when the program is the default one.
    warm_up : WarmUp, optional
        The warm-up law (default :class:`WarmUp`).
    events : ToolEvents, optional
        Tool and blank events (default none).
    loading_s : float, default 5.0
        Wait [s] at rest before each part (the machine keeps warming).
    jitter_s : float, default 0.2
        Largest extra random wait [s] before each part, uniform.
    pauses : tuple of (int, float), default ()
        ``(part, seconds)``: a pause [s] before that part, during which the machine cools.
    noise : CurrentNoise, optional
        Current noise (default :class:`~greybox.twin.noise.CurrentNoise`).
    """

    parts: int = 20
    axis: str = "X"
    program: Program | None = None
    cutting: CuttingSpec | None = None
    warm_up: WarmUp = field(default_factory=WarmUp)
    events: ToolEvents = field(default_factory=ToolEvents)
    loading_s: float = 5.0
    jitter_s: float = 0.2
    pauses: tuple = ()
    noise: CurrentNoise | None = None

    def __post_init__(self):
        if isinstance(self.parts, bool) or not isinstance(self.parts, (int, np.integer)) or not 1 <= self.parts:
            raise GreyboxError(f"a part series needs at least one part, got {self.parts!r}")
        if not (self.loading_s >= 0 and self.jitter_s >= 0):
            raise GreyboxError("loading time and jitter must be non-negative")
        for part, seconds in self.pauses:
            if int(part) != part or part < 1 or not seconds >= 0:
                raise GreyboxError(f"pause {part}:{seconds}: the part is counted from 1, the pause is non-negative")

    def the_program(self) -> Program:
        """The part's program."""
        return self.program if self.program is not None else part_program(self.axis)

    def the_cutting(self) -> CuttingSpec:
        """The cutting conditions."""
        if self.cutting is not None:
            return self.cutting
        workpiece = PART_WORKPIECE_MM if self.program is None else None
        return CuttingSpec(strength_A=PART_STRENGTH_A, workpiece_mm=workpiece)


#: Length [mm] of the stroke the twin runs before each part, in the direction of the program's last one, so
#: that each part starts with the friction the previous part left held (the stroke is cut off the log).
LEAD_IN_MM = 0.5


def _waiting(program: Program, seconds: float) -> Program:
    """The program with a dwell of ``seconds`` after its first move, and the lead-in stroke before it."""
    moves = [block for block in program.blocks if isinstance(block, Move)]
    last = next((b for a, b in zip(moves[-2::-1], moves[::-1]) if b.target != a.target), None)
    if last is None:
        return replace(program, blocks=(program.blocks[0], Dwell(seconds, 0), *program.blocks[1:]))
    before = moves[[i for i, m in enumerate(moves) if m is last][-1] - 1]
    sign = 1.0 if last.target > before.target else -1.0
    start = program.blocks[0]
    lead = Move(start.target - sign * LEAD_IN_MM, None, 0)
    return replace(program, blocks=(lead, Move(start.target, last.feed, 0), Dwell(seconds, 0), *program.blocks[1:]))


def _lead_in_end(velocity_mm_s) -> int:
    """Index of the first sample at rest after the lead-in stroke (0 without motion)."""
    moving = np.abs(np.asarray(velocity_mm_s)) > 0.0
    first = int(np.argmax(moving)) if moving.any() else 0
    after = np.flatnonzero(~moving[first:])
    return first + int(after[0]) if moving.any() and after.size else 0


def block_numbers(program: Program, position_mm, velocity_mm_s) -> np.ndarray:
    """The program line of the block being run at each sample, as a control logs it.

    A sample in motion belongs to the move whose stretch of the path it lies on (by the path length travelled
    since the program's first position); a sample at rest to the dwell it waits in, else to the move that
    starts next (after the last move: the last block).

    Parameters
    ----------
    program : Program
        The program run; its first move is the start position.
    position_mm : array_like, shape (n,)
        Axis position [mm or deg] of the run from its first position, without noise.
    velocity_mm_s : array_like, shape (n,)
        Axis velocity [mm/s or deg/s] of the run (exactly 0 at rest).

    Returns
    -------
    ndarray of float, shape (n,)
        The block's line per sample.
    """
    position = program.blocks[0].target
    ends, lines, rest_lines, dwell = [], [], [], None
    for block in program.blocks[1:]:
        if isinstance(block, Dwell):
            dwell = block.line
            continue
        distance = abs(block.target - position)
        position = block.target
        if distance == 0.0:
            continue
        ends.append((ends[-1] if ends else 0.0) + distance)
        lines.append(block.line)
        rest_lines.append(block.line if dwell is None else dwell)
        dwell = None
    if not lines:
        return np.full(np.shape(position_mm), float(dwell or program.blocks[0].line))
    lines.append(lines[-1] if dwell is None else dwell)
    rest_lines.append(lines[-1])
    travelled = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(np.asarray(position_mm, dtype=float))))])
    ends, tolerance = np.asarray(ends), 1e-9 * max(float(ends[-1]), 1.0)  # the sum's rounding
    moving = np.asarray(velocity_mm_s, dtype=float) != 0.0
    on = np.minimum(np.searchsorted(ends, travelled - tolerance, side="left"), ends.size - 1)  # its end not passed
    after = np.searchsorted(ends, travelled + tolerance, side="right")  # the first move whose end lies ahead
    return np.where(moving, np.asarray(lines, dtype=float)[on], np.asarray(rest_lines, dtype=float)[after])


def _part_seed(seed: int, part: int) -> int:
    return int(np.random.SeedSequence([int(seed), int(part)]).generate_state(1)[0])


def make_part_series(spec: PartSeriesSpec, seed: int) -> tuple[list[AxisLog], dict]:
    """The logs of a part series and its truth.

    Parameters
    ----------
    spec : PartSeriesSpec
        The series.
    seed : int
        Master seed: the waits and each part's noise derive from it.

    Returns
    -------
    logs : list of AxisLog
        One per part, time from 0, with a :data:`PART_COLUMN` channel and the truth channels;
        ``attrs["part"]`` holds the part number and its start [s] in the series.
    truth : dict
        Per part: start [s], duration [s], warm-up factor at start and end, cutting-load factor, mean
        cut force [N] and process current [A] over the samples an intact tool cuts; the events with their
        times; the settings.
    """
    geometry = axis_geometry(spec.axis)
    program, cutting = spec.the_program(), spec.the_cutting()
    plant = default_plant_parameters(geometry.name)
    waits = np.random.default_rng([int(seed), 1]).uniform(0.0, spec.jitter_s, spec.parts)
    pauses = {int(part): float(seconds) for part, seconds in spec.pauses}
    warmth, clock = 0.0, 0.0
    logs, parts, events = [], [], []
    for index in range(spec.parts):
        part = index + 1
        if part in pauses:
            warmth = spec.warm_up.paused(warmth, pauses[part])
            clock += pauses[part]
            events.append({"kind": "pause", "part": part, "series_time_s": clock, "seconds": pauses[part]})
        waiting = _waiting(program, spec.loading_s + float(waits[index]))
        trajectory = program_trajectory(waiting, geometry)
        n = int(np.floor(trajectory.duration_s / SAMPLE_TIME_S + 1e-9)) + 1
        time = np.round(np.arange(n) * SAMPLE_TIME_S, 9)
        motion = trajectory.motion.evaluate(time)
        start = _lead_in_end(motion[1])
        blocks = block_numbers(waiting, motion[0], motion[1])[start:]
        time = np.round(time - time[start], 9)
        scale = spec.events.scale(part, time)
        log = make_dataset(geometry.name, "S", _part_seed(seed, part), trajectory=trajectory, cutting=cutting,
                           cutting_scale=scale, plant=WarmPlant(plant, spec.warm_up, warmth), noise=spec.noise)
        force_name = next(name for name in log.extras
                          if name.startswith("truth_process_") and name != "truth_process_A")
        cuts = cutting_current(cutting, time, log.position, log.velocity)[start:] != 0.0  # where an intact tool cuts
        log = log.select(slice(start, None))
        log = log.replace(time=np.round(log.time - log.time[0], 9))
        n = len(log)
        log = log.replace(extras={**log.extras, PART_COLUMN: np.full(n, float(part)), BLOCK_COLUMN: blocks},
                          attrs={**log.attrs, "part": {"number": part, "series_start_s": clock}})
        logs.append(log)
        end_warmth = float(spec.warm_up.running(warmth, log.duration))
        parts.append({"part": part, "series_start_s": clock, "duration_s": log.duration,
                      "wait_s": spec.loading_s + float(waits[index]),
                      "friction_factor_start": float(spec.warm_up.level(warmth)),
                      "friction_factor_end": float(spec.warm_up.level(end_warmth)),
                      "cut_factor": float(spec.events.scale(part, [0.0])[0]),
                      "mean_cut_force": float(np.mean(np.abs(log.extras[force_name][cuts]))) if cuts.any() else 0.0,
                      "force_unit": force_name.rsplit("_", 1)[-1],
                      "mean_cut_current_A": float(np.mean(np.abs(log.extras["truth_process_A"][cuts])))
                      if cuts.any() else 0.0})
        if spec.events.breakage_part == part:
            events.append({"kind": "breakage", "part": part, "time_s": spec.events.breakage_time_s,
                           "series_time_s": clock + spec.events.breakage_time_s})
        if part in spec.events.missing_blank:
            events.append({"kind": "missing blank", "part": part})
        if part in spec.events.oversized_blank:
            events.append({"kind": "oversized blank", "part": part, "factor": spec.events.oversize_factor})
        warmth = end_warmth
        clock += log.duration + SAMPLE_TIME_S
    worn = spec.events.worn_part(15.0)
    truth = {"generator": "greybox.twin.part_series", "seed": int(seed), "axis": geometry.name,
             "warm_up": asdict(spec.warm_up), "events_settings": asdict(spec.events), "cutting": cutting.to_dict(),
             "loading_s": spec.loading_s, "jitter_s": spec.jitter_s, "parts": parts, "events": events,
             "wear_15pct_part": worn}
    return logs, truth


def _series_log(logs: Sequence[AxisLog]) -> AxisLog:
    """The parts one after the other in one log, time continuing."""
    starts = [log.attrs["part"]["series_start_s"] for log in logs]
    time = np.concatenate([np.round(start + log.time, 9) for start, log in zip(starts, logs)])
    extras = {name: np.concatenate([log.extras[name] for log in logs]) for name in logs[0].extras}
    first = logs[0]
    return first.replace(time=time, position=np.concatenate([log.position for log in logs]),
                         effort=np.concatenate([log.effort for log in logs]),
                         velocity=np.concatenate([log.velocity for log in logs]), extras=extras,
                         attrs={**first.attrs, "part": {"parts": len(logs)}})


def synthesize_part_series(spec: PartSeriesSpec, seed: int, out_dir: str | PathLike, *, layout: str = "both",
                           truth_channels: Sequence[str] | None = None, force: bool = False,
                           progress: Callable[[str], None] | None = None, suffix: str = "mcap") -> list[Path]:
    """Write a part series: one log per part and/or one long log, and the truth as JSON.

    Parameters
    ----------
    spec : PartSeriesSpec
        The series.
    seed : int
        Master seed.
    out_dir : str or path-like
        Output directory: ``<axis>_part<NNN>.mcap`` per part, ``<axis>_series.mcap`` (all parts, with the
        :data:`PART_COLUMN` counter), ``<axis>_parts.json`` (the truth) and ``<axis>_part.mpf`` (the program).
    layout : {"parts", "series", "both"}, default "both"
        Which logs to write.
    truth_channels : sequence of str, optional
        Truth channels kept in the logs (default all).
    force : bool, default False
        Overwrite existing files; otherwise an existing file is an error and nothing is written.
    progress : callable, optional
        Called with one line per file written.
    suffix : {"mcap", "parquet"}, default "mcap"
        Format of the logs, by their file suffix (Parquet writes several times faster).

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    GreyboxError
        For an unknown layout or an existing file without ``force``.
    """
    from ..data.io import write_log
    from ..nc.gcode import write_program

    if layout not in ("parts", "series", "both"):
        raise GreyboxError(f"part series layout must be parts, series or both, got {layout!r}")
    if suffix not in ("mcap", "parquet"):
        raise GreyboxError(f"part series format must be mcap or parquet, got {suffix!r}")
    out = Path(out_dir)
    axis = axis_geometry(spec.axis).name
    targets = [out / f"{axis}_parts.json", out / f"{axis}_part.mpf"]
    if layout in ("parts", "both"):
        targets += [out / f"{axis}_part{part:03d}.{suffix}" for part in range(1, spec.parts + 1)]
    if layout in ("series", "both"):
        targets.append(out / f"{axis}_series.{suffix}")
    existing = [path for path in targets if path.exists()]
    if existing and not force:
        raise GreyboxError(f"{existing[0]}: file exists; pass --force to overwrite it")
    logs, truth = make_part_series(spec, seed)
    out.mkdir(parents=True, exist_ok=True)
    counters = (PART_COLUMN, BLOCK_COLUMN)
    kept = [stored(log, truth_channels).replace(extras={**stored(log, truth_channels).extras,
                                                        **{name: log.extras[name] for name in counters}})
            for log in logs]
    written = []
    if layout in ("parts", "both"):
        for log in kept:
            path = out / f"{axis}_part{log.attrs['part']['number']:03d}.{suffix}"
            write_log(log, path)
            written.append(path)
            truth["parts"][log.attrs["part"]["number"] - 1]["file"] = path.name
            if progress:
                progress(f"part {log.attrs['part']['number']}: {log.duration:.1f} s -> {path}")
    if layout in ("series", "both"):
        path = out / f"{axis}_series.{suffix}"
        write_log(_series_log(kept), path)
        written.append(path)
        truth["series_file"] = path.name
        if progress:
            progress(f"series of {len(kept)} parts -> {path}")
    program_path = write_text_atomic(out / f"{axis}_part.mpf", write_program(spec.the_program()))
    truth_path = write_text_atomic(out / f"{axis}_parts.json", json.dumps(jsonable(truth), indent=1) + "\n")
    return [*written, program_path, truth_path]
