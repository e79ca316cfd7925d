"""Synthetic axis logs: trajectory -> truth plant -> effects -> noise -> CNC channels.

:func:`make_dataset` builds one :class:`~greybox.data.log.AxisLog` in memory;
:func:`synthesize` writes a set of them as MCAP files.
"""

from __future__ import annotations

import time as clock
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..data.log import AxisLog
from ..errors import GreyboxError
from .axes import axis_geometry
from .cutting import CuttingSpec, cut_segments, cutting_current
from .effects import EffectInputs, effect_current, effect_parameters
from .noise import CurrentNoise
from .plant import PlantParameters, default_plant_parameters
from .sensors import Sensors, quantise
from .trajectories import DATASETS, DEFAULT_DATASETS, Trajectory, dataset_trajectory

__all__ = [
    "SAMPLE_TIME_S",
    "TRUTH_CHANNELS",
    "ESSENTIAL_TRUTH_CHANNELS",
    "dataset_streams",
    "dataset_motion",
    "make_dataset",
    "dataset_path",
    "stored",
    "synthesize",
]

#: Log sample time [s] (500 Hz, as a SINUMERIK 840D sl trace).
SAMPLE_TIME_S = 0.002

#: Truth channels a synthetic log carries (the last two only with an effect or cutting).
TRUTH_CHANNELS = ("truth_current_A", "truth_friction_A", "truth_inertia_A", "truth_cogging_A", "truth_noise_A",
                  "truth_effect_A", "truth_process_A", "truth_process_force_N", "truth_process_torque_Nm")

#: Truth channels kept in compact files: the noise-free current (for the noise
#: floor) and the injected components.
ESSENTIAL_TRUTH_CHANNELS = ("truth_current_A", "truth_effect_A", "truth_process_A", "truth_process_force_N",
                            "truth_process_torque_Nm")

#: Resolution [A] to which truth channels are rounded when written to files.
TRUTH_STORAGE_RESOLUTION_A = 1e-6


def _check_seed(seed) -> None:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise GreyboxError(f"seed must be a non-negative integer, got {seed!r}")


def dataset_streams(seed: int, axis: str, dataset: str) -> tuple[np.random.Generator, np.random.Generator]:
    """Independent random generators (trajectory, noise) of one dataset.

    They derive from ``numpy.random.SeedSequence([seed, ord(axis), ord(dataset)])``,
    so every dataset of every axis has its own streams for one seed, and
    adding an effect or cutting changes neither the motion nor the noise.

    Parameters
    ----------
    seed : int
        Master seed, a non-negative integer.
    axis : str
        Axis name, one character (e.g. ``"X"``), as given: the case is not normalised here.
    dataset : str
        Dataset id, one character (e.g. ``"A"``), as given: the case is not normalised here.

    Raises
    ------
    GreyboxError
        For a seed that is not a non-negative integer.
    """
    _check_seed(seed)
    sequence = np.random.SeedSequence([int(seed), ord(axis), ord(dataset)])
    return tuple(np.random.default_rng(child) for child in sequence.spawn(2))


def dataset_motion(axis: str, dataset: str, seed: int, duration_s: float | None = None) -> Trajectory:
    """The commanded motion of one dataset, drawn from the same stream as :func:`make_dataset` draws it.

    Cheap (no plant simulation): tells the length [s] a dataset will have before synthesising it.

    Parameters
    ----------
    axis : {"X", "Y", "C"}
        Axis of the synthetic machine.
    dataset : {"A", "B", "C", "D", "P"}
        Dataset id.
    seed : int
        Master seed.
    duration_s : float, optional
        Length [s] asked of A, C (default 120 s) and P (default 60 s); see
        :data:`greybox.twin.trajectories.MIN_DURATION_S` for how it is met.

    Returns
    -------
    Trajectory
        Its ``duration_s`` is the length of the motion [s].

    Raises
    ------
    GreyboxError
        For an unknown axis or dataset, a bad seed or a non-positive duration.
    """
    geometry = axis_geometry(axis)
    key = str(dataset).strip().upper()
    if key not in DATASETS:
        raise GreyboxError(f"unknown dataset {dataset!r}; choose from {', '.join(DATASETS)}")
    trajectory_rng, _ = dataset_streams(seed, geometry.name, key)
    return dataset_trajectory(geometry, key, trajectory_rng, duration_s)


def make_dataset(axis: str = "X", dataset: str = "A", seed: int = 0, *, effect: str | None = None,
                 effect_strength: float = 0.2, effect_params: dict | None = None,
                 cutting: bool | CuttingSpec | None = None, duration_s: float | None = None,
                 plant: PlantParameters | None = None, noise: CurrentNoise | None = None,
                 sensors: Sensors | None = None, trajectory: Trajectory | None = None,
                 cutting_scale=None) -> AxisLog:
    """Synthesise one axis log.

    Parameters
    ----------
    axis : {"X", "Y", "C"}, default "X"
        Axis of the synthetic machine.
    dataset : {"A", "B", "C", "D", "P"}, default "A"
        Dataset id (see :data:`greybox.twin.trajectories.DATASETS`).
    seed : int, default 0
        Master seed; each axis and dataset derives its own streams from it.
    effect : str, optional
        Name of a hidden effect of :data:`greybox.twin.effects.EFFECTS`.
    effect_strength : float, default 0.2
        Strength [A] of the effect.
    effect_params : dict, optional
        Further keyword parameters of the effect.
    cutting : bool or CuttingSpec, optional
        Inject a cutting-force current (``True``: default :class:`CuttingSpec`).
    duration_s : float, optional
        Length [s] of the datasets A, C (default 120 s) and P (default 60 s).
    plant : PlantParameters or FamilyPlant, optional
        Truth plant (anything with ``simulate(motion, n_samples, sample_time_s)`` and ``to_dict()``); default
        :func:`default_plant_parameters` of the axis. With cutting, the process current is added to the
        screw's axial load (:meth:`~greybox.twin.plant.PlantResponse.under_load`).
    noise : CurrentNoise, optional
        Current noise; default ``CurrentNoise()`` (0.09 A, lag-1 correlation 0.7).
    sensors : Sensors, optional
        Resolutions of the logged channels.
    trajectory : Trajectory, optional
        The motion to run instead of the dataset's (e.g. an NC program,
        :func:`greybox.twin.nc_run.program_trajectory`); ``dataset`` then only labels the log and
        seeds its noise.
    cutting_scale : array_like, shape (n,), optional
        Factor of the cutting load at each log sample (tool events of a part series,
        :mod:`greybox.twin.part_series`: 0 after a breakage); default 1.

    Returns
    -------
    AxisLog
        Time [s] at 2 ms steps from 0, encoder position [mm], actual velocity
        [mm/s], noisy quantised current [A]; acceleration is not logged.
        Extras: ``truth_current_A`` (noise-free current), ``truth_friction_A``,
        ``truth_inertia_A``, ``truth_cogging_A``, ``truth_noise_A`` (logged minus noise-free current),
        and ``truth_effect_A`` / ``truth_process_A`` when injected; with cutting also
        ``truth_process_force_N``, the process force on the table [N] behind ``truth_process_A``
        (``truth_process_torque_Nm`` on the rotary C axis)
        (:mod:`greybox.twin.drive`; the axis file that converts one into the other is in
        ``attrs["cutting"]["axis_config"]``).
        ``attrs`` holds the seed, plant, trajectory, noise, sensors, effect and cutting settings.

    Raises
    ------
    GreyboxError
        For an unknown axis, dataset or effect, or invalid settings.
    """
    geometry = axis_geometry(axis)
    key = str(dataset).strip().upper()
    if trajectory is None:
        trajectory = dataset_motion(geometry.name, dataset, seed, duration_s)
    elif len(key) != 1:
        raise GreyboxError(f"dataset label {dataset!r} of a given trajectory must be one letter")
    _, noise_rng = dataset_streams(seed, geometry.name, key)
    plant = plant if plant is not None else default_plant_parameters(geometry.name)
    noise = noise if noise is not None else CurrentNoise()
    sensors = sensors if sensors is not None else Sensors()

    n = int(np.floor(trajectory.duration_s / SAMPLE_TIME_S + 1e-9)) + 1
    time = np.round(np.arange(n) * SAMPLE_TIME_S, 9)
    response = plant.simulate(trajectory.motion, n, SAMPLE_TIME_S)
    process = None
    if cutting:
        spec = cutting if isinstance(cutting, CuttingSpec) else CuttingSpec()
        process = cutting_current(spec, time, response.position_mm, response.velocity_mm_s)
        if cutting_scale is not None:
            process = process * np.broadcast_to(np.asarray(cutting_scale, dtype=float), process.shape)
        response = response.under_load(process)
    truth = {"truth_friction_A": response.friction_A, "truth_inertia_A": response.inertia_A,
             "truth_cogging_A": response.cogging_A}
    attrs = {
        "generator": "greybox.twin",
        "seed": int(seed),
        "sample_time_s": SAMPLE_TIME_S,
        "plant": plant.to_dict(),
        "trajectory": {"dataset": key, "description": DATASETS.get(key, trajectory.description.get("kind", "")),
                       **trajectory.description},
        "noise": noise.to_dict(),
        "sensors": sensors.to_dict(),
        "effect": None,
        "cutting": None,
    }
    if effect is not None:
        params = dict(effect_params or {})
        inputs = EffectInputs(time, response.position_mm, response.velocity_mm_s,
                              response.acceleration_mm_s2, geometry.travel_mm)
        truth["truth_effect_A"] = effect_current(effect, inputs, effect_strength, **params)
        attrs["effect"] = {"name": effect, "strength_A": float(effect_strength),
                           **effect_parameters(effect), **params}
    if process is not None:
        truth["truth_process_A"] = process
        attrs["cutting"] = {**spec.to_dict(), "workpiece_mm": list(spec.workpiece(response.position_mm)),
                            "cut_segments": len(cut_segments(process))}

    noise_free = sum(truth.values())
    current = sensors.current(noise_free + noise.sample(n, noise_rng))
    position = sensors.position(response.position_mm)
    extras = {"truth_current_A": noise_free, **truth, "truth_noise_A": current - noise_free}
    if process is not None:
        config = plant.axis_config(geometry.name)
        extras[f"truth_process_{config.units.load}_{config.units.load_unit}"] = plant.process_load(
            process, response.velocity_mm_s)
        attrs["cutting"]["axis_config"] = config.to_dict()
    return AxisLog(
        time=time,
        position=position,
        effort=current,
        velocity=sensors.velocity(position, SAMPLE_TIME_S),
        effort_unit="A",
        motion=geometry.motion,
        axis=geometry.name,
        dataset=key,
        extras=extras,
        attrs=attrs,
    )


def dataset_path(out_dir, axis: str, dataset: str) -> Path:
    """File ``out_dir/<axis>_<dataset>.mcap`` of a synthetic dataset.

    Parameters
    ----------
    out_dir : str or path-like
        Output directory.
    axis : str
        Axis name, used as given in the file name.
    dataset : str
        Dataset id, used as given in the file name.
    """
    return Path(out_dir) / f"{axis}_{dataset}.mcap"


def _kept_truth_channels(truth_channels: Sequence[str] | None) -> tuple[str, ...]:
    keep = TRUTH_CHANNELS if truth_channels is None else tuple(truth_channels)
    unknown = sorted(set(keep) - set(TRUTH_CHANNELS))
    if unknown:
        raise GreyboxError(f"unknown truth channel {', '.join(unknown)}; choose from {', '.join(TRUTH_CHANNELS)}")
    return keep


def _for_storage(log: AxisLog, keep: Sequence[str]) -> AxisLog:
    extras = {name: quantise(values, TRUTH_STORAGE_RESOLUTION_A)
              for name, values in log.extras.items() if name in keep}
    return log.replace(extras=extras)


def stored(log: AxisLog, truth_channels: Sequence[str] | None = None) -> AxisLog:
    """The log as synthesised logs are written: only the given truth channels (default all), rounded to 1 uA.

    Parameters
    ----------
    log : AxisLog
        A synthesised log, e.g. from :func:`make_dataset`.
    truth_channels : sequence of str, optional
        Names from :data:`TRUTH_CHANNELS` to keep among the log's extras; default all of them.
        Any other extra channel is dropped.

    Raises
    ------
    GreyboxError
        For an unknown truth channel.
    """
    return _for_storage(log, _kept_truth_channels(truth_channels))


def synthesize(axis: str | Sequence[str], seed: int, out_dir, datasets: Sequence[str] = DEFAULT_DATASETS, *,
               force: bool = False, truth_channels: Sequence[str] | None = None,
               progress: Callable[[str], None] | None = None, one_file: str | None = None,
               **options) -> list[Path]:
    """Synthesise datasets and write each to ``out_dir/<axis>_<dataset>.mcap`` (or all axes to one file).

    Parameters
    ----------
    axis : str or sequence of str
        Axis or axes (``"X"``, ``"Y"``).
    seed : int
        Master seed (see :func:`make_dataset`).
    out_dir : str or path-like
        Output directory, created if missing.
    datasets : sequence of str, default ("A", "B", "C", "D")
        Dataset ids.
    force : bool, default False
        Overwrite existing files; otherwise an existing target is an error and nothing is written.
    truth_channels : sequence of str, optional
        Truth channels to keep (default all); e.g. :data:`ESSENTIAL_TRUTH_CHANNELS`
        for compact files. Kept channels are rounded to 1 uA.
    progress : callable, optional
        Called with one line of text per written file.
    one_file : {"csv", "parquet", "mcap"}, optional
        Write each dataset of all axes to one file ``out_dir/<dataset>.<one_file>``, as a machine
        logs its axes together: the axes move at once, each on its own trajectory, cut to the
        shortest; CSV and Parquet name the columns ``X_position_mm``, ``Y_current_A``, ...,
        MCAP holds a channel per axis.
    **options
        Passed to :func:`make_dataset` (effect, effect_strength, effect_params,
        cutting, duration_s, plant, noise, sensors).

    Returns
    -------
    list of Path
        The written files, in order.

    Raises
    ------
    GreyboxError
        For bad settings or when a target file exists and ``force`` is false.
    """
    from ..data.io import write_log

    axes = [axis] if isinstance(axis, str) else list(axis)
    geometries = [axis_geometry(name) for name in axes]
    ids = [str(d).strip().upper() for d in datasets]
    for key in ids:
        if key not in DATASETS:
            raise GreyboxError(f"unknown dataset {key!r}; choose from {', '.join(DATASETS)}")
    _check_seed(seed)
    keep = _kept_truth_channels(truth_channels)
    if options.get("effect") is not None:
        effect_parameters(options["effect"])
    if one_file is not None:
        if one_file not in ("csv", "parquet", "mcap"):
            raise GreyboxError(f"unknown format {one_file!r} of the one file per dataset; choose csv, parquet or mcap")
        targets = [(None, key, Path(out_dir) / f"{key}.{one_file}") for key in ids]
    else:
        targets = [(g.name, key, dataset_path(out_dir, g.name, key)) for g in geometries for key in ids]
    existing = [str(path) for _, _, path in targets if path.exists()]
    if existing and not force:
        raise GreyboxError(f"{existing[0]}: file exists ({len(existing)} of {len(targets)} targets exist); "
                           "nothing was written. Choose another directory or pass --force to overwrite")
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    written = []
    for name, key, path in targets:
        start = clock.perf_counter()
        if name is None:  # every axis in one file, cut to the shortest
            logs = [make_dataset(g.name, key, seed, **options) for g in geometries]
            shortest = min(len(log) for log in logs)
            logs = [log.select(slice(0, shortest)) for log in logs]
            write_log([_for_storage(log, keep) for log in logs], path)
            label, log = f"{'+'.join(g.name for g in geometries)} {key}", logs[0]
        else:
            log = make_dataset(name, key, seed, **options)
            write_log(_for_storage(log, keep), path)
            label = f"{name}_{key}"
        written.append(path)
        if progress is not None:
            noise_floor = float(np.std(log.extras["truth_noise_A"]))
            progress(f"{label}: {log.duration:7.1f} s, {len(log):6d} samples, "
                     f"noise floor {noise_floor:.4f} A -> {path} "
                     f"({path.stat().st_size / 1e6:.2f} MB, {clock.perf_counter() - start:.1f} s)")
    return written
