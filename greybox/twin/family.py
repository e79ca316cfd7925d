"""A family of truth axes: random friction laws with the effects every feed axis has.

Each member composes a truth friction law of :mod:`greybox.twin.laws` (the
family cycles through the four laws) with

* a position dependence of the friction, ``g(x) = 1 + c_pre u^4 + c_tilt u + c_lead sin(2 pi x / lead + phi)``
  (:func:`greybox.twin.plant.position_factor_at`),
* friction rising with the axial load of the screw: ``(1 - eta) |I_inertia + I_process|`` in the friction's
  direction, ``eta`` the screw efficiency,
* viscous friction ``sigma_v v`` and inertia ``J a``,
* a motor cogging current periodic in the motor's pole pitch, ``a_cog sin(2 pi x / lambda_cog + phi_cog)``
  with ``lambda_cog = lead / (pole pairs x harmonic)``,
* AR(1) current-controller noise and quantised position and current channels
  (:class:`~greybox.twin.noise.CurrentNoise`, :class:`~greybox.twin.sensors.Sensors`).

Every parameter is drawn from a documented range (:data:`FAMILY_RANGES` and
each law's ``RANGES``), seeded by the family seed and the member's index, and
the member runs the twin's trajectories A-D (:func:`greybox.twin.datasets.make_dataset`).
"""

from __future__ import annotations

import json
import math
import time as clock
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..atomic import write_text_atomic
from ..data.axis_config import AxisConfig
from ..errors import GreyboxError
from .axes import axis_geometry
from .datasets import _check_seed, _for_storage, _kept_truth_channels, dataset_path, make_dataset
from .drive import drive_config, load_gain_efficiencies
from .laws import TRUTH_LAWS, TruthLaw
from .laws.base import log_uniform
from .noise import CurrentNoise
from .plant import PlantResponse, _position_term_arrays, fine_motion
from .sensors import Sensors
from .trajectories import DATASETS, DEFAULT_DATASETS

__all__ = ["FAMILY_RANGES", "AXIS_FILE", "FamilyPlant", "FamilyMember", "ranges_markdown", "draw_member",
           "member_dataset", "synthesize_family"]

#: ``{parameter: (low, high, unit, how drawn)}`` of the effects every member has.
FAMILY_RANGES = {
    "axis": ("X", "Y", "-", "either, equally likely (travel and window of the paper's axes)"),
    "inertia_A_s2_mm": (1.5e-4, 6e-4, "A s^2/mm", "log-uniform"),
    "viscous_A_s_mm": (2e-3, 1.2e-2, "A s/mm", "uniform"),
    "preload_gain": (0.0, 0.4, "-", "uniform; c_pre"),
    "tilt_gain": (-0.6, 0.6, "-", "uniform; c_tilt"),
    "lead_mm": (5.0, 20.0, "mm", "one of 5, 10, 16, 20"),
    "lead_gain": (0.0, 0.06, "-", "uniform; c_lead"),
    "load_gain": (0.02, 0.08, "-", "uniform; 1 - screw efficiency"),
    "cogging_A": (0.0, 0.15, "A", "uniform"),
    "pole_pairs": (3, 5, "-", "integer, uniform"),
    "cogging_harmonic": (6, 12, "-", "6 or 12 per pole pair"),
    "noise_std_A": (0.04, 0.12, "A", "uniform"),
    "noise_lag1_correlation": (0.3, 0.85, "-", "uniform"),
    "position_resolution_mm": (5e-5, 1e-3, "mm", "one of 0.05, 0.1, 0.5, 1 um"),
    "current_resolution_A": (1e-3, 5e-3, "A", "one of 1, 2, 5 mA"),
}

#: Name of each member's axis file (``greybox predict --axis-config``) beside its logs.
AXIS_FILE = "axis.toml"

_LEADS_MM = (5.0, 10.0, 16.0, 20.0)
_POSITION_RESOLUTIONS_MM = (5e-5, 1e-4, 5e-4, 1e-3)
_CURRENT_RESOLUTIONS_A = (1e-3, 2e-3, 5e-3)


@dataclass(frozen=True)
class FamilyPlant:
    """A truth law with position dependence, load-dependent friction, viscous friction, inertia and cogging.

    Parameters
    ----------
    law : TruthLaw
        The friction law.
    inertia_A_s2_mm : float
        Inertia ``J`` [A s^2/mm] of the axis.
    viscous_A_s_mm : float
        ``sigma_v`` [A s/mm].
    travel_mm : tuple of float
        Ends [mm] of the travel that shape the position factor.
    preload_gain, tilt_gain : float
        ``c_pre`` and ``c_tilt`` of the position factor.
    lead_mm, lead_gain, lead_phase_rad : float
        Screw lead [mm], ``c_lead`` and its phase [rad].
    load_gain : float
        ``1 - eta``: friction current per ampere of axial load.
    cogging_A, cogging_period_mm, cogging_phase_rad : float
        Cogging amplitude [A], period [mm] and phase [rad].
    internal_step_s : float, default 0.25e-3
        Fine integration step [s].
    """

    law: TruthLaw
    inertia_A_s2_mm: float
    viscous_A_s_mm: float
    travel_mm: tuple
    preload_gain: float
    tilt_gain: float
    lead_mm: float
    lead_gain: float
    lead_phase_rad: float
    load_gain: float
    cogging_A: float
    cogging_period_mm: float
    cogging_phase_rad: float
    internal_step_s: float = 0.25e-3

    def __post_init__(self):
        if abs(self.tilt_gain) + abs(self.lead_gain) >= 1.0 or self.preload_gain < 0:
            raise GreyboxError("family plant: the position factor must stay positive "
                               "(|tilt_gain| + |lead_gain| < 1, preload_gain >= 0)")
        if self.load_gain < 0 or self.cogging_A < 0 or self.inertia_A_s2_mm <= 0:
            raise GreyboxError("family plant: load gain and cogging must be non-negative, inertia positive")

    def position_terms(self, position_mm) -> tuple[np.ndarray, np.ndarray]:
        """Position factor ``g(x)`` and cogging current [A] at positions [mm].

        Parameters
        ----------
        position_mm : array_like, shape (n,)
            Positions [mm], a one-dimensional array.
        """
        x = np.ascontiguousarray(position_mm, dtype=float)
        return _position_term_arrays(x, float(self.travel_mm[0]), float(self.travel_mm[1]), float(self.preload_gain),
                                     float(self.tilt_gain), float(self.lead_mm), float(self.lead_gain),
                                     float(self.lead_phase_rad), float(self.cogging_A), float(self.cogging_period_mm),
                                     float(self.cogging_phase_rad))

    def simulate(self, motion, n_samples: int, sample_time_s: float = 0.002) -> PlantResponse:
        """Motion and noise-free currents at the log samples along ``motion`` (air cut: inertial axial load only).

        Parameters
        ----------
        motion : object
            Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
        n_samples : int
            Number of log samples, at times ``k * sample_time_s``.
        sample_time_s : float, default 0.002
            Log sample time [s].
        """
        stride, x, v, a = fine_motion(self, motion, n_samples, sample_time_s)
        law = self.law.respond(x, v, a, self.internal_step_s, stride, self.inertia_A_s2_mm)
        x_log, v_log, a_log = x[::stride], v[::stride], a[::stride]
        factor, cogging = self.position_terms(x_log)
        friction = (factor * law.friction_A + self.viscous_A_s_mm * v_log
                    + self.load_gain * np.abs(law.inertia_A) * law.direction)
        return PlantResponse(x_log, v_log, a_log, friction, law.inertia_A, cogging, load_gain=float(self.load_gain),
                             friction_direction=law.direction)

    def axis_config(self, name: str = "") -> AxisConfig:
        """The axis file of this member: the twin's motor, this screw lead, the efficiencies of its load friction.

        Parameters
        ----------
        name : str, default ""
            Axis name written into the axis file.
        """
        return drive_config(self.lead_mm, load_gain_efficiencies(self.load_gain), name)

    def process_load(self, process_A, velocity_mm_s) -> np.ndarray:
        """Process force [N] on the table behind a process current [A] (losses booked in the friction).

        Parameters
        ----------
        process_A : array_like
            Process current [A].
        velocity_mm_s : array_like
            Axis velocity [mm/s]; not used (the lossless constant applies in either direction of power flow),
            taken for the same call as :meth:`PlantParameters.process_load
            <greybox.twin.plant.PlantParameters.process_load>`.
        """
        return self.axis_config().lossless_load_constant * np.asarray(process_A, dtype=float)

    def to_dict(self) -> dict:
        """JSON-serialisable parameters, the law's under ``"law"``."""
        values = {name: getattr(self, name) for name in self.__dataclass_fields__ if name != "law"}
        values["travel_mm"] = list(self.travel_mm)
        return {"law": self.law.to_dict(), **values}


@dataclass(frozen=True)
class FamilyMember:
    """One drawn axis of the family.

    Parameters
    ----------
    index : int
        Position in the family.
    family_seed : int
        Seed of the family.
    axis : str
        Geometry (``"X"`` or ``"Y"``).
    plant : FamilyPlant
        The truth plant.
    noise : CurrentNoise
        Current noise.
    sensors : Sensors
        Resolutions of the logged channels.
    dataset_seed : int
        Seed of the member's trajectories and noise (:func:`~greybox.twin.datasets.make_dataset`).
    """

    index: int
    family_seed: int
    axis: str
    plant: FamilyPlant
    noise: CurrentNoise
    sensors: Sensors
    dataset_seed: int

    @property
    def law(self) -> str:
        """Name of the member's friction law."""
        return self.plant.law.name

    @property
    def name(self) -> str:
        """``member_NNN``: the member's directory in a written family."""
        return f"member_{self.index:03d}"

    def to_dict(self) -> dict:
        """JSON-serialisable description."""
        return {"index": self.index, "family_seed": self.family_seed, "axis": self.axis, "law": self.law,
                "dataset_seed": self.dataset_seed, "plant": self.plant.to_dict(), "noise": self.noise.to_dict(),
                "sensors": self.sensors.to_dict()}


def ranges_markdown() -> str:
    """The documented ranges of the family (:data:`FAMILY_RANGES` and every law's ``RANGES``) as Markdown tables."""
    def table(title, ranges):
        rows = [f"**{title}**", "", "| parameter | low | high | unit | drawn |", "|---|---|---|---|---|"]
        for name, (low, high, unit, how) in ranges.items():
            ends = (low, high) if isinstance(low, str) else (f"{low:g}", f"{high:g}")
            rows.append(f"| `{name}` | {ends[0]} | {ends[1]} | {unit} | {how} |")
        return "\n".join(rows)

    parts = [table("every member", FAMILY_RANGES)]
    parts += [table(f"law `{name}`", law.RANGES) for name, law in TRUTH_LAWS.items()]
    return "\n\n".join(parts) + "\n"


def draw_member(index: int, family_seed: int) -> FamilyMember:
    """Draw member ``index`` of the family of seed ``family_seed``.

    The law cycles through :data:`~greybox.twin.laws.TRUTH_LAWS` with the
    index; every other parameter comes from one stream seeded by
    ``(family_seed, index)``, so a member does not depend on how many are drawn.

    Parameters
    ----------
    index : int
        Position of the member in the family, a non-negative integer.
    family_seed : int
        Seed of the family, a non-negative integer.

    Raises
    ------
    GreyboxError
        For a negative index or a bad seed.
    """
    _check_seed(family_seed)
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or index < 0:
        raise GreyboxError(f"family member index must be a non-negative integer, got {index!r}")
    sequence = np.random.SeedSequence([int(family_seed), int(index), 0x6661])
    rng = np.random.default_rng(sequence)
    laws = list(TRUTH_LAWS.values())
    law = laws[int(index) % len(laws)].draw(rng)
    r = FAMILY_RANGES
    axis = "X" if rng.random() < 0.5 else "Y"
    lead = float(rng.choice(_LEADS_MM))
    poles = int(rng.integers(r["pole_pairs"][0], r["pole_pairs"][1] + 1))
    harmonic = int(rng.choice((6, 12)))
    plant = FamilyPlant(
        law=law,
        inertia_A_s2_mm=log_uniform(rng, *r["inertia_A_s2_mm"][:2]),
        viscous_A_s_mm=rng.uniform(*r["viscous_A_s_mm"][:2]),
        travel_mm=axis_geometry(axis).travel_mm,
        preload_gain=rng.uniform(*r["preload_gain"][:2]),
        tilt_gain=rng.uniform(*r["tilt_gain"][:2]),
        lead_mm=lead,
        lead_gain=rng.uniform(*r["lead_gain"][:2]),
        lead_phase_rad=rng.uniform(0.0, 2.0 * math.pi),
        load_gain=rng.uniform(*r["load_gain"][:2]),
        cogging_A=rng.uniform(*r["cogging_A"][:2]),
        cogging_period_mm=lead / (poles * harmonic),
        cogging_phase_rad=rng.uniform(0.0, 2.0 * math.pi),
    )
    noise = CurrentNoise(std_A=rng.uniform(*r["noise_std_A"][:2]),
                         lag1_correlation=rng.uniform(*r["noise_lag1_correlation"][:2]))
    sensors = Sensors(position_resolution_mm=float(rng.choice(_POSITION_RESOLUTIONS_MM)),
                      current_resolution_A=float(rng.choice(_CURRENT_RESOLUTIONS_A)))
    dataset_seed = int(sequence.generate_state(1, dtype=np.uint32)[0])
    return FamilyMember(int(index), int(family_seed), axis, plant, noise, sensors, dataset_seed)


def member_dataset(member: FamilyMember, dataset: str, *, repeat: int = 0, **options):
    """One log of a family member (:func:`~greybox.twin.datasets.make_dataset` with the member's plant,
    noise, sensors and seed); ``options`` are the other arguments of ``make_dataset`` (cutting, duration_s,
    effect ...). ``repeat`` > 0 runs the dataset again on the same axis with other draws of its noise and of
    the random parts of its trajectory (the seed ``dataset_seed + repeat``). The log's ``attrs`` carry the
    member under ``"family_member"``.

    Parameters
    ----------
    member : FamilyMember
        The member, e.g. from :func:`draw_member`.
    dataset : {"A", "B", "C", "D", "P"}
        Dataset id.
    repeat : int, default 0
        Repetition number; the log's seed is ``(dataset_seed + repeat) mod 2**32``.
    **options
        Further keyword arguments of :func:`~greybox.twin.datasets.make_dataset`, except ``plant``,
        ``noise`` and ``sensors``, which come from the member.
    """
    seed = (member.dataset_seed + int(repeat)) % 2**32
    log = make_dataset(member.axis, dataset, seed, plant=member.plant, noise=member.noise,
                       sensors=member.sensors, **options)
    attrs = dict(log.attrs)
    attrs["family_member"] = {"index": member.index, "family_seed": member.family_seed, "law": member.law,
                              "repeat": int(repeat)}
    return log.replace(attrs=attrs)


def synthesize_family(count: int, family_seed: int, out_dir, datasets: Sequence[str] = DEFAULT_DATASETS, *,
                      first: int = 0, force: bool = False, truth_channels: Sequence[str] | None = None,
                      progress: Callable[[str], None] | None = None, **options) -> list[Path]:
    """Write ``count`` family members as ``out_dir/member_NNN/<axis>_<dataset>.mcap`` plus ``out_dir/family.json``.

    Beside each member's logs, ``member_NNN/axis.toml`` is its axis file (:data:`AXIS_FILE`): the drive-train
    constants and the efficiencies its load-dependent friction implies, for ``greybox predict --axis-config``.

    Parameters
    ----------
    count : int
        Number of members.
    family_seed : int
        Seed of the family.
    out_dir : path-like
        Output directory, created if missing.
    datasets : sequence of str, default ("A", "B", "C", "D")
        Dataset ids.
    first : int, default 0
        Index of the first member.
    force : bool, default False
        Overwrite existing files; otherwise an existing target is an error and nothing is written.
    truth_channels : sequence of str, optional
        Truth channels to keep (default all).
    progress : callable, optional
        Called with one line per member.
    **options
        Passed to :func:`member_dataset` (cutting, duration_s).

    Returns
    -------
    list of Path
        The written log files, in order; ``family.json`` describes every member (law and all parameters).
    """
    from ..data.io import write_log

    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise GreyboxError(f"family size must be a positive integer, got {count!r}")
    ids = [str(d).strip().upper() for d in datasets]
    for key in ids:
        if key not in DATASETS:
            raise GreyboxError(f"unknown dataset {key!r}; choose from {', '.join(DATASETS)}")
    keep = _kept_truth_channels(truth_channels)
    members = [draw_member(index, family_seed) for index in range(first, first + count)]
    out = Path(out_dir)
    targets = [(m, key, dataset_path(out / m.name, m.axis, key)) for m in members for key in ids]
    catalogue = out / "family.json"
    existing = [str(path) for _, _, path in targets if path.exists()] + ([str(catalogue)] if catalogue.exists() else [])
    if existing and not force:
        raise GreyboxError(f"{existing[0]}: file exists ({len(existing)} of {len(targets) + 1} targets exist); "
                           "nothing was written. Choose another directory or pass --force to overwrite")
    written = []
    for member in members:
        start = clock.perf_counter()
        (out / member.name).mkdir(parents=True, exist_ok=True)
        for m, key, path in targets:
            if m is member:
                write_log(_for_storage(member_dataset(member, key, **options), keep), path)
                written.append(path)
        write_text_atomic(out / member.name / AXIS_FILE, member.plant.axis_config(member.axis).to_toml())
        if progress is not None:
            progress(f"{member.name}: {member.law}, axis {member.axis}, noise {member.noise.std_A:.3f} A -> "
                     f"{out / member.name} ({len(ids)} logs, {clock.perf_counter() - start:.1f} s)")
    description = {"family_seed": int(family_seed), "datasets": ids, "members": [m.to_dict() for m in members]}
    write_text_atomic(catalogue, json.dumps(description, indent=1) + "\n")
    return written
