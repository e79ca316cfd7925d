"""Discrete-time position loop: PID feedback plus model-based feed-forward around a plant.

The reference and the feed-forward come at the reference's step (2 ms for
the generated references and the synthetic logs: the step the models were
identified at, so that every model runs as it was fitted). The controller
runs at a shorter period (default: the longest divisor of the reference step
not above 0.25 ms, i.e. 8 periods per 2 ms; a servo drive's position and
speed loops run at such rates): every period the encoder position is read
(rounded to the encoder resolution), the PID of :mod:`greybox.control.pid`
acts on the error to the set-point ``x_k + v_k t + a_k t^2/2`` interpolated
within the reference sample, the feed-forward of the sample is added, and
the saturated motor current is held over the period while the plant
(:mod:`greybox.control.plants`) is integrated at its fine internal step. An
optional disturbance current (seeded AR(1) noise,
:class:`greybox.twin.CurrentNoise`, one value per reference sample) is added
to the motor current; it is the same for every feed-forward of one comparison.

The tracking error is ``e = r - x`` [mm] of the *true* position ``x`` at the
reference samples.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.quantities import MOTIONS, Motion
from ..errors import GreyboxError
from ..twin.noise import CurrentNoise
from .feedforward import InertiaFeedForward
from .pid import ControllerSettings, PIDGains
from .references import Reference
from .tuning import default_bandwidth_hz, pole_placement_gains

__all__ = ["DEFAULT_CURRENT_LIMIT_A", "DEFAULT_RESOLUTION_MM", "DEFAULT_CONTROLLER_PERIOD_S", "LoopResult",
           "controller_periods", "simulate_loop", "compare_feedforwards"]

#: Longest default controller period [s].
DEFAULT_CONTROLLER_PERIOD_S = 0.25e-3

#: Default saturation of the motor current [A]: a few times the friction plus
#: the inertial current of a feed axis at several m/s^2 (the synthetic axis
#: needs about 1.3 A of friction and 0.28 A per m/s^2).
DEFAULT_CURRENT_LIMIT_A = 10.0

#: Default encoder resolution [mm] (0.1 um, as the synthetic axis's sensors).
DEFAULT_RESOLUTION_MM = 1e-4


@dataclass(frozen=True, eq=False)
class LoopResult:
    """One closed-loop run: reference, commands and response at every reference sample.

    Parameters
    ----------
    reference : Reference
        The reference.
    feedforward_name, plant_name : str
        Labels of the feed-forward and the plant.
    feedforward_A : ndarray
        Feed-forward current [A].
    current_A : ndarray
        Saturated motor current command, mean over each reference sample [A].
    position_mm : ndarray
        True position [mm].
    plant_friction_A : ndarray
        Friction current of the plant [A].
    saturated : ndarray
        Fraction of the controller periods of each sample at the current limit.
    settings : dict
        Gains, period, limits and disturbance of the run (JSON-serialisable).
    motion : str, default "linear"
        Kind of axis of the plant: positions and errors in mm, or deg for ``"rotary"``.
    """

    reference: Reference
    feedforward_name: str
    plant_name: str
    feedforward_A: np.ndarray
    current_A: np.ndarray
    position_mm: np.ndarray
    plant_friction_A: np.ndarray
    saturated: np.ndarray
    settings: dict = field(default_factory=dict)
    motion: str = "linear"

    @property
    def units(self) -> Motion:
        """Units of the plant's axis (mm or deg)."""
        return MOTIONS[self.motion]

    @property
    def error_mm(self) -> np.ndarray:
        """Tracking error ``r - x`` [mm]."""
        return self.reference.position - self.position_mm

    @property
    def rms_error_mm(self) -> float:
        """Root mean square of the tracking error [mm]."""
        return float(np.sqrt(np.mean(self.error_mm**2)))

    @property
    def peak_error_mm(self) -> float:
        """Largest absolute tracking error [mm]."""
        return float(np.max(np.abs(self.error_mm)))

    @property
    def saturated_fraction(self) -> float:
        """Fraction of the controller periods at which the current command is at its limit."""
        return float(np.mean(self.saturated))

    def summary(self) -> dict:
        """Row of the comparison table (errors ``rms_error_mm``, ``peak_error_mm`` in mm, or
        ``rms_error_deg``, ``peak_error_deg`` for a rotary axis; JSON-serialisable)."""
        relabel = self.units.relabel
        return {"reference": self.reference.name, "feedforward": self.feedforward_name, "plant": self.plant_name,
                relabel("rms_error_mm"): self.rms_error_mm, relabel("peak_error_mm"): self.peak_error_mm,
                "rms_current_A": float(np.sqrt(np.mean(self.current_A**2))),
                "saturated_fraction": self.saturated_fraction}


def _disturbance(disturbance: CurrentNoise | None, n: int, seed: int) -> np.ndarray:
    if disturbance is None:
        return np.zeros(n)
    return disturbance.sample(n, np.random.default_rng(seed))


def controller_periods(sample_time_s: float, controller_period_s: float | None = None) -> int:
    """Controller periods per reference sample.

    Parameters
    ----------
    sample_time_s : float
        Reference step [s].
    controller_period_s : float, optional
        Controller period [s]; it must divide the reference step. Default the
        longest divisor not above :data:`DEFAULT_CONTROLLER_PERIOD_S`.
    """
    if controller_period_s is None:
        return max(1, int(np.ceil(sample_time_s / DEFAULT_CONTROLLER_PERIOD_S * (1.0 - 1e-9))))
    if not (np.isfinite(controller_period_s) and controller_period_s > 0.0):
        raise GreyboxError(f"controller period must be positive, got {controller_period_s} s")
    ratio = sample_time_s / controller_period_s
    periods = int(round(ratio))
    if periods < 1 or abs(ratio - periods) > 1e-6 * ratio:
        raise GreyboxError(f"controller period {controller_period_s * 1e3:g} ms must divide the reference step "
                           f"{sample_time_s * 1e3:g} ms")
    return periods


def simulate_loop(plant, reference: Reference, feedforward=None, gains: PIDGains | None = None, *,
                  controller_period_s: float | None = None, current_limit_A: float = DEFAULT_CURRENT_LIMIT_A,
                  resolution_mm: float = DEFAULT_RESOLUTION_MM, disturbance: CurrentNoise | None = None,
                  seed: int = 0) -> LoopResult:
    """Run the position loop around ``plant`` on ``reference``, from rest at the reference's start.

    Parameters
    ----------
    plant : TwinPlant or ModelPlant
        The controlled axis (:mod:`greybox.control.plants`).
    reference : Reference
        Position reference; its step is the step of the feed-forward.
    feedforward : InertiaFeedForward or ModelFeedForward, optional
        Feed-forward; default none at all (``InertiaFeedForward(0)``).
    gains : PIDGains, optional
        Controller; default :func:`~greybox.control.tuning.pole_placement_gains`
        for the plant's inertia at :func:`~greybox.control.tuning.default_bandwidth_hz`
        of the controller period.
    controller_period_s : float, optional
        Controller period [s], a divisor of the reference step (see :func:`controller_periods`).
    current_limit_A : float, default 10.0
        Saturation of the motor current [A].
    resolution_mm : float, default 1e-4
        Encoder resolution [mm] (0: exact position measurement).
    disturbance : CurrentNoise, optional
        Disturbance current added to the motor current [A].
    seed : int, default 0
        Seed of the disturbance.

    Returns
    -------
    LoopResult
    """
    feedforward = feedforward if feedforward is not None else InertiaFeedForward(0.0, name="off")
    unit = getattr(feedforward, "effort_unit", None)
    if unit is not None and unit != plant.effort_unit:
        raise GreyboxError(f"feed-forward {feedforward.name!r} gives effort in {unit}, "
                           f"the plant {plant.name!r} takes {plant.effort_unit}")
    periods = controller_periods(reference.sample_time, controller_period_s)
    period = reference.sample_time / periods
    if gains is None:
        gains = pole_placement_gains(plant.inertia_A_s2_mm, default_bandwidth_hz(period))
    settings = ControllerSettings.from_gains(gains, period, current_limit_A, resolution_mm)
    current_ff = np.asarray(feedforward.current(reference), dtype=float)
    if current_ff.shape != reference.position.shape or not np.all(np.isfinite(current_ff)):
        raise GreyboxError(f"feed-forward {feedforward.name!r} is not finite along reference {reference.name!r}")
    trace = plant.run(reference, current_ff, _disturbance(disturbance, len(reference), seed), settings, periods)
    if not np.all(np.isfinite(trace.position_mm)):
        raise GreyboxError(f"the loop around {plant.name!r} diverged on reference {reference.name!r} with "
                           f"feed-forward {feedforward.name!r}; lower the bandwidth")
    info = {"gains": gains.to_dict(), "controller_period_s": period, "reference_step_s": reference.sample_time,
            "current_limit_A": float(current_limit_A), "resolution_mm": float(resolution_mm),
            "disturbance": None if disturbance is None else {**disturbance.to_dict(), "seed": int(seed)}}
    return LoopResult(reference, feedforward.name, plant.name, current_ff, trace.current_A, trace.position_mm,
                      trace.friction_A, trace.saturated, info, motion=plant.motion)


def compare_feedforwards(plant, references, feedforwards, gains: PIDGains | None = None, **options
                         ) -> list[LoopResult]:
    """Run every feed-forward on every reference with one set of gains.

    Parameters
    ----------
    plant : TwinPlant or ModelPlant
        The controlled axis.
    references : sequence of Reference
        References (one table each).
    feedforwards : sequence
        Feed-forwards (one row each).
    gains : PIDGains, optional
        The one controller of all runs; default tuned once for the plant's
        inertia at the default bandwidth of the controller period of the
        first reference.
    **options
        Passed to :func:`simulate_loop` (controller_period_s,
        current_limit_A, resolution_mm, disturbance, seed).

    Returns
    -------
    list of LoopResult
        Reference-major order.
    """
    references = list(references)
    if not references or not feedforwards:
        raise GreyboxError("a comparison needs at least one reference and one feed-forward")
    if gains is None:
        step = references[0].sample_time
        period = step / controller_periods(step, options.get("controller_period_s"))
        gains = pole_placement_gains(plant.inertia_A_s2_mm, default_bandwidth_hz(period))
    return [simulate_loop(plant, reference, feedforward, gains, **options)
            for reference in references for feedforward in feedforwards]
