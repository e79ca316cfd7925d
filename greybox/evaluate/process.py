"""The process share of the motor current, and the force behind it.

A model trained on air cuts predicts what the drive needs to move the axis
without a process: inertia and friction. On a log recorded while cutting, the
rest of the measured current is the share the process caused,

    I_process = I_measured - I_model,

which carries the model's air-cut error and the measurement noise besides the
process.

Force from current
------------------
The motor turns the current into a torque ``T = k_t I`` [Nm]. A gear of ratio
``i`` (motor revolutions per screw revolution) and a screw of lead ``h`` [m]
(table travel per screw revolution) move the table by ``h / i`` per motor
revolution, so ``v = omega h / (2 pi i)`` for a motor speed ``omega`` [rad/s].
Of the motor's mechanical power ``T omega`` the share ``eta`` reaches the
table, ``F v = eta T omega``, hence

    F = T * i * 2 pi * eta / h = k_t * I * i * 2 pi * eta / (h_mm / 1000)   [N].

Example: ``k_t = 1.35 Nm/A``, ``h = 10 mm``, ``i = 1``, ``eta = 0.9`` give
``0.9 * 1.35 * 2 pi / 0.010 m = 763.4 N/A``.

Conventions. ``eta`` covers the losses that grow with the load (screw, nut,
support bearings, gear); the load-independent friction is already in the
model and removed with it. ``eta`` is applied for power flowing from the motor
to the table, which is the case while the drive feeds against a cutting
force; a process that pushes the table along (climb milling pulling the
table) would need ``1 / eta`` instead, a difference of ``eta^2``. The force
has the sign of the current: the current models are fitted with a
non-negative inertia ``J``, so a positive current accelerates the axis
towards positive positions, and ``force_process_N > 0`` is a force the drive
exerts on the table towards positive positions. The cutting force along the
axis is its opposite.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..data.axis_config import AxisConfig
from ..data.log import AxisLog, as_log_list
from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S, chunk_slices, iter_chunks, samples_per_chunk
from ..registry import model_kind

__all__ = ["force_constant_N_per_A", "process_force", "ProcessResult", "predict_process"]


def force_constant_N_per_A(config: AxisConfig) -> float:
    """Force on the table per ampere of motor current [N/A].

    ``k_t * i * 2 pi * eta / h`` with the lead ``h`` in metres (see the module notes).

    Parameters
    ----------
    config : AxisConfig
        Torque constant [Nm/A], screw lead [mm], gear ratio, efficiency.

    Returns
    -------
    float
    """
    lead_m = config.screw_lead_mm * 1e-3
    return config.torque_constant_Nm_per_A * config.gear_ratio * 2.0 * np.pi * config.efficiency / lead_m


def process_force(process_current_A, config: AxisConfig) -> np.ndarray:
    """Force [N] the drive exerts on the table for a process current [A].

    Parameters
    ----------
    process_current_A : array_like
        Process share of the motor current [A].
    config : AxisConfig
        Drive-train constants of the axis.

    Returns
    -------
    ndarray
        ``force_constant_N_per_A(config) * process_current_A`` [N].
    """
    return force_constant_N_per_A(config) * np.asarray(process_current_A, dtype=float)


@dataclass(frozen=True)
class ProcessResult:
    """Measured, modelled and process current of a log, sample by sample.

    Attributes
    ----------
    time : ndarray
        Time [s].
    position : ndarray
        Axis position [mm].
    velocity : ndarray
        Axis velocity [mm/s].
    measured : ndarray
        Measured effort [A] (or [N] for a force log).
    model : ndarray
        Model prediction, inertia + friction [A] (or [N]).
    force : ndarray or None
        Process force [N]: from the axis metadata for a current log, the
        process effort itself for a force log; None for a current log
        without axis metadata.
    effort_unit : str
        "A" or "N".
    force_constant_N_per_A : float or None
        Factor from process current to force [N/A] (None without axis metadata).
    axis : str
        Axis name.
    source : str
        Log file.
    dataset : str
        Dataset id of the log (:attr:`greybox.data.log.AxisLog.dataset`), "" if it has none.
    attrs : dict
        JSON-able description (model kind and file, chunk length, axis constants).
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    force: np.ndarray | None
    effort_unit: str = "A"
    force_constant_N_per_A: float | None = None
    axis: str = ""
    source: str = ""
    attrs: dict = field(default_factory=dict)
    dataset: str = ""

    @property
    def process(self) -> np.ndarray:
        """Process share ``measured - model`` [A] (or [N])."""
        return self.measured - self.model

    def columns(self) -> dict[str, np.ndarray]:
        """The output columns, in order.

        For a current log: ``time_s``, ``current_measured_A``,
        ``current_model_A``, ``current_process_A``, ``force_process_N`` (with
        axis metadata), ``position_mm``, ``velocity_mm_s``. For a force log
        the three effort columns are ``force_measured_N``, ``force_model_N``,
        ``force_process_N``.
        """
        quantity = "current" if self.effort_unit == "A" else "force"
        unit = self.effort_unit
        out = {"time_s": self.time, f"{quantity}_measured_{unit}": self.measured,
               f"{quantity}_model_{unit}": self.model, f"{quantity}_process_{unit}": self.process}
        if self.force is not None:
            out["force_process_N"] = self.force
        out["position_mm"] = self.position
        out["velocity_mm_s"] = self.velocity
        return out

    def to_frame(self):
        """The columns of :meth:`columns` as a :class:`pandas.DataFrame`."""
        import pandas as pd

        return pd.DataFrame(self.columns())


def predict_process(model, log: AxisLog, *, axis_config: AxisConfig | None = None,
                    chunk_s: float = DEFAULT_CHUNK_S,
                    progress: Callable[[int, int, float], None] | None = None) -> ProcessResult:
    """Process share of the current of a cutting log, and its force.

    Parameters
    ----------
    model : CurrentModel
        A fitted model (trained on air cuts) of a registered kind.
    log : AxisLog
        One prepared run recorded while cutting.
    axis_config : AxisConfig, optional
        Drive-train constants; gives ``force`` for a current log.
    chunk_s : float, default 60.0
        The model runs over chunks of this length [s], carrying its state
        (see :mod:`greybox.models.chunked`).
    progress : callable, optional
        Called after each chunk as ``progress(done, chunks, time_s)``: chunks
        done, chunks in all, and the log time [s] reached.

    Returns
    -------
    ProcessResult

    Raises
    ------
    GreyboxError
        For several runs, or axis metadata given with a log that already
        carries force.
    """
    runs = as_log_list(log)
    if len(runs) != 1:
        raise GreyboxError(f"predict_process takes one run, got {len(runs)}; call it once per log")
    (run,) = runs
    n_chunks = len(chunk_slices(len(run), samples_per_chunk(run.sample_time, chunk_s)))
    predicted = np.empty(len(run))
    for done, (samples, current) in enumerate(iter_chunks(model, run, chunk_s=chunk_s), start=1):
        predicted[samples] = current
        if progress is not None:
            progress(done, n_chunks, float(run.time[samples.stop - 1]))
    force = None
    factor = None
    attrs: dict = {"model_kind": model_kind(model), "chunk_s": float(chunk_s)}
    if run.effort_unit == "N":
        if axis_config is not None:
            raise GreyboxError(f"{run.source or '<in-memory log>'}: the log carries force in N already; "
                               "axis metadata convert a current and do not apply")
        force = run.effort - predicted
    elif axis_config is not None:
        force = process_force(run.effort - predicted, axis_config)
        factor = force_constant_N_per_A(axis_config)
        attrs["axis_config"] = {"source": axis_config.source,
                                "torque_constant_Nm_per_A": axis_config.torque_constant_Nm_per_A,
                                "screw_lead_mm": axis_config.screw_lead_mm, "gear_ratio": axis_config.gear_ratio,
                                "efficiency": axis_config.efficiency,
                                "force_constant_N_per_A": factor}
    return ProcessResult(time=run.time, position=run.position, velocity=run.velocity, measured=run.effort,
                         model=predicted, force=force, effort_unit=run.effort_unit,
                         force_constant_N_per_A=factor,
                         axis=run.axis or (axis_config.name if axis_config is not None else ""),
                         source=run.source, attrs=attrs, dataset=run.dataset or "")
