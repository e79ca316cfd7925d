"""The process share of the motor current, and the force (or torque) behind it.

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
A lossless drive train would pass ``F v = T omega``, that is
``F = K_0 I`` with ``K_0 = k_t i 2 pi / h``. The screw, nut, bearings and
gear lose a share of the power that grows with the load, and which way the
power flows decides the conversion:

* driving (the drive pushes the table against the load, ``I v > 0``): of the
  motor's power the share ``eta_d`` reaches the table, ``F v = eta_d T omega``,

      F = eta_d K_0 I;

* back-driven (the load pushes the table along its motion and the motor
  brakes, ``I v < 0``, e.g. climb milling pulling the table): of the table's
  power the share ``eta_b`` reaches the motor, ``T omega = eta_b F v``,

      F = K_0 I / eta_b.

At rest (``v = 0``) no power flows and ``eta_d`` is used. With one efficiency
for both directions the back-driven force comes out ``eta^2`` too small.

Example: ``k_t = 1.35 Nm/A``, ``h = 10 mm``, ``i = 1``, ``eta_d = 0.9`` give
``0.9 * 1.35 * 2 pi / 0.010 m = 763.4 N/A`` while driving.

A rotary axis has no screw: a gear of ratio ``i`` (motor revolutions per
revolution of the axis) gives the torque on the axis ``M = K_0 I`` with
``K_0 = k_t i`` [Nm/A], and the efficiencies apply the same way
(``M = eta_d K_0 I`` driving, ``M = K_0 I / eta_b`` back-driven); the output
is ``torque_process_Nm``.

Conventions. The efficiencies cover the losses that grow with the load; the
load-independent friction is already in the model and removed with it. The
force has the sign of the current: the current models are fitted with a
non-negative inertia ``J``, so a positive current accelerates the axis
towards positive positions, and ``force_process_N > 0`` is a force the drive
exerts on the table towards positive positions. The process force on the
table (e.g. the cutting force along the axis) is its opposite.
"""

from __future__ import annotations

from concurrent.futures import wait
from dataclasses import dataclass, field, replace
from typing import Callable, Iterable, Iterator, Sequence

import numpy as np
from threadpoolctl import threadpool_limits

from ..data.axis_config import AxisConfig
from ..data.effort import EFFORT_UNITS, column_stem, effort_quantity
from ..data.log import AxisLog, as_log_list
from ..data.quantities import MOTIONS, Motion
from ..data.units import MOTOR_TORQUE
from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S, chunk_slices, samples_per_chunk
from ..models.estimator import EXTRAPOLATION_WARNING_SHARE, outside_any
from ..models.registry import model_kind
from ..threads import shared_pool
from .interval import ProcessInterval
from .relevel import Relevel

__all__ = ["ProcessResult", "ProcessTally", "check_process_inputs",
           "extrapolation_summary", "join_results", "predict_process", "process_attrs", "process_blocks"]


@dataclass(frozen=True)
class ProcessResult:
    """Measured, modelled and process current of a log, sample by sample.

    Attributes
    ----------
    time : ndarray
        Time [s].
    position : ndarray
        Axis position [mm], or [deg] for a rotary axis.
    velocity : ndarray
        Axis velocity [mm/s], or [deg/s].
    measured : ndarray
        Measured effort [A] (or [N] / [Nm] for a log of the load).
    model : ndarray
        Model prediction, inertia + friction [A] (or [N] / [Nm]).
    load : ndarray or None
        Process force [N] (torque [Nm] on a rotary axis): from the axis
        metadata for a current log, the process effort itself for a log of
        the load; None for a current log without axis metadata.
    effort_unit : str
        "A", "N" or "Nm".
    motion : str
        "linear" or "rotary" (:mod:`greybox.data.quantities`).
    load_constants : (float, float) or None
        Factors from process current to load [N/A, or Nm/A], driving and back-driven
        (:attr:`~greybox.data.axis_config.AxisConfig.load_constants`; None without axis metadata).
    axis : str
        Axis name.
    source : str
        Log file.
    dataset : str
        Dataset id of the log (:attr:`greybox.data.log.AxisLog.dataset`), "" if it has none.
    attrs : dict
        JSON-able description (model kind and file, chunk length, axis constants, interval).
    half_width : ndarray or None
        Half-width of the calibrated interval of the process current per sample [A] (or [N], [Nm]),
        :class:`~greybox.predict.interval.ProcessInterval`; None without calibration.
    load_bounds : (ndarray, ndarray) or None
        Lower and upper bound of the process force [N] (torque [Nm]) of a current log, the current's
        bounds converted like the current; None without calibration or without axis metadata.
    outside : ndarray of bool or None
        True where the log leaves the region the model's training runs covered
        (:meth:`~greybox.models.estimator.CurrentModel.outside_training`); None for a model file that
        predates the record of that region.
    effort_quantity : str, default ""
        What the effort is (:func:`~greybox.data.effort.effort_quantity`): ``"motor torque"`` for a servo
        trace's torque [Nm] read as a current; "" for the quantity ``effort_unit`` names.
    standstill : ndarray of bool or None
        True where a memoryless model sees the axis at standstill (part of ``outside``): the friction the
        drive holds there is unknown to it, so ``process`` and ``load`` there are no process figures.
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    load: np.ndarray | None
    effort_unit: str = "A"
    motion: str = "linear"
    load_constants: tuple[float, float] | None = None
    axis: str = ""
    source: str = ""
    attrs: dict = field(default_factory=dict)
    dataset: str = ""
    half_width: np.ndarray | None = None
    load_bounds: tuple | None = None
    outside: np.ndarray | None = None
    effort_quantity: str = ""
    standstill: np.ndarray | None = None

    @property
    def quantity(self) -> str:
        """What the effort is: ``"current"``, ``"motor torque"``, ``"force"`` or ``"torque"``."""
        return self.effort_quantity or ("current" if self.effort_unit == "A" else self.units.load)

    @property
    def shown_unit(self) -> str:
        """Unit of the effort as shown and written: A, Nm (a motor torque or a rotary load) or N."""
        return EFFORT_UNITS[self.quantity]

    @property
    def process(self) -> np.ndarray:
        """Process share ``measured - model`` [A] (or [N])."""
        return self.measured - self.model

    @property
    def process_bounds(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Lower and upper bound of the process share [A] (or [N]); None without calibration."""
        if self.half_width is None:
            return None
        return self.process - self.half_width, self.process + self.half_width

    @property
    def units(self) -> Motion:
        """Units of the axis: mm and N, or deg and Nm."""
        return MOTIONS[self.motion]

    def columns(self) -> dict[str, np.ndarray]:
        """The output columns, in order.

        For a current log: ``time_s``, ``current_measured_A``,
        ``current_model_A``, ``current_process_A`` (with an interval also
        ``current_process_lower_A`` and ``current_process_upper_A``),
        ``force_process_N`` (with axis metadata; with an interval also
        ``force_process_lower_N`` and ``force_process_upper_N``),
        ``position_mm``, ``velocity_mm_s`` and ``outside_training`` (1 where
        the log leaves the training region, else 0; absent for a model file
        that predates the record). For a force log the effort columns are
        ``force_measured_N``, ``force_model_N``, ``force_process_N`` (and its
        bounds). A rotary axis writes ``torque_..._Nm``, ``position_deg`` and
        ``velocity_deg_s`` instead; a linear axis's motor torque ``motor_torque_..._Nm``. A memoryless
        model adds ``standstill`` (1 where the axis stands, else 0).
        """
        units = self.units
        quantity, unit = column_stem(self.quantity), self.shown_unit
        out = {"time_s": self.time, f"{quantity}_measured_{unit}": self.measured,
               f"{quantity}_model_{unit}": self.model, f"{quantity}_process_{unit}": self.process}
        if self.half_width is not None:
            out[f"{quantity}_process_lower_{unit}"], out[f"{quantity}_process_upper_{unit}"] = self.process_bounds
        if self.load is not None and self.effort_unit == "A":
            load, load_unit = units.load, units.load_unit
            out[f"{load}_process_{load_unit}"] = self.load
            if self.load_bounds is not None:
                out[f"{load}_process_lower_{load_unit}"], out[f"{load}_process_upper_{load_unit}"] = self.load_bounds
        out[units.position_column] = self.position
        out[units.velocity_column] = self.velocity
        if self.outside is not None:
            out["outside_training"] = self.outside.astype(np.float64)
        if self.standstill is not None:
            out["standstill"] = self.standstill.astype(np.float64)
        return out

    def to_frame(self):
        """The columns of :meth:`columns` as a :class:`pandas.DataFrame`."""
        import pandas as pd

        return pd.DataFrame(self.columns())


def extrapolation_summary(counts: dict, n_outside: int | None, n_samples: int) -> dict:
    """JSON-able shares of samples outside the training region, overall and per quantity.

    Parameters
    ----------
    counts : dict of str to int
        Samples outside the training region per quantity (of
        :meth:`~greybox.models.estimator.CurrentModel.outside_training`); empty for a model without the record.
    n_outside : int or None
        Samples outside in any quantity (None without the record).
    n_samples : int
        Samples of the log.

    Returns
    -------
    dict
        ``{"share": float or None, "by": {quantity: share}, "warn_above": float}``; ``share`` is None
        (with a ``"reason"``) when the model carries no training region.
    """
    if not counts:
        return {"share": None, "by": {}, "warn_above": EXTRAPOLATION_WARNING_SHARE,
                "reason": "the model file predates the record of its training region; retrain to get one"}
    return {"share": n_outside / n_samples, "by": {name: count / n_samples for name, count in counts.items()},
            "warn_above": EXTRAPOLATION_WARNING_SHARE}


@dataclass
class ProcessTally:
    """Running figures of a process result given block by block: what ``greybox predict`` reports.

    :meth:`add` each block (or the whole result once); the figures are those of all samples added.

    Attributes
    ----------
    n_samples : int
        Samples added.
    sum_squares : dict of str to float
        Sums of squares of ``measured``, ``model``, ``process`` and ``load`` (A^2, N^2 or Nm^2), and of
        ``load_moving``: the load outside standstill (:attr:`ProcessResult.standstill`).
    largest : dict of str to float
        Largest ``|process|``, ``|load|`` and ``|load|`` outside standstill (``load_moving``).
    n_moving : int
        Samples outside standstill (all samples of a model that carries the friction at rest).
    half_width_sum : float
        Sum of the interval half-widths (0 without an interval).
    outside_counts : dict of str to int
        Samples outside the training region per quantity.
    n_outside : int
        Samples outside in any quantity.
    _regions : bool, default False
        Whether any block came with training-region flags (internal: set by :meth:`add`; without it
        :meth:`extrapolation` reports no training region).
    """

    n_samples: int = 0
    sum_squares: dict = field(default_factory=lambda: dict.fromkeys(("measured", "model", "process", "load",
                                                                     "load_moving"), 0.0))
    largest: dict = field(default_factory=lambda: dict.fromkeys(("process", "load", "load_moving"), 0.0))
    n_moving: int = 0
    half_width_sum: float = 0.0
    outside_counts: dict = field(default_factory=dict)
    n_outside: int = 0
    _regions: bool = False

    def add(self, result: ProcessResult, regions: dict | None = None) -> None:
        """Count in one block (or a whole result) and its training-region flags per quantity.

        Parameters
        ----------
        result : ProcessResult
            The block (or whole result) to count in.
        regions : dict of str to ndarray of bool, optional
            Per quantity, True at the samples of the block outside the training region
            (:meth:`~greybox.models.estimator.CurrentModel.outside_training`); None or empty when the model
            carries no training region.
        """
        self.n_samples += len(result.time)
        values = {"measured": result.measured, "model": result.model, "process": result.process,
                  "load": result.load}
        for name, array in values.items():
            if array is not None and len(array):
                self.sum_squares[name] += float(np.einsum("i,i->", array, array))  # no BLAS: its threads spin
                if name in self.largest:
                    self.largest[name] = max(self.largest[name], float(np.max(np.abs(array))))
        moving = result.load if result.standstill is None or result.load is None else result.load[~result.standstill]
        self.n_moving += len(result.time) if result.standstill is None else int(np.count_nonzero(~result.standstill))
        if moving is not None and len(moving):
            self.sum_squares["load_moving"] += float(np.einsum("i,i->", moving, moving))
            self.largest["load_moving"] = max(self.largest["load_moving"], float(np.max(np.abs(moving))))
        if result.half_width is not None:
            self.half_width_sum += float(np.sum(result.half_width))
        if regions:
            self._regions = True
            for name, flags in regions.items():
                self.outside_counts[name] = self.outside_counts.get(name, 0) + int(np.count_nonzero(flags))
            self.n_outside += int(np.count_nonzero(outside_any(regions)))

    def rms(self, name: str) -> float:
        """Root mean square of ``measured``, ``model``, ``process`` or ``load`` over the samples added.

        Parameters
        ----------
        name : {"measured", "model", "process", "load", "load_moving"}
            Which signal [A] (or [N], [Nm]); ``load_moving`` over the samples outside standstill (NaN
            when every sample stands).
        """
        count = self.n_moving if name == "load_moving" else self.n_samples
        return float(np.sqrt(self.sum_squares[name] / count)) if count else float("nan")

    def extrapolation(self) -> dict:
        """:func:`extrapolation_summary` of the samples added."""
        return extrapolation_summary(self.outside_counts if self._regions else {},
                                     self.n_outside if self._regions else None, self.n_samples)


def check_process_inputs(runs: Sequence[AxisLog], axis_config: AxisConfig | None) -> None:
    """Refuse runs of mixed effort units, axis metadata with a load log, or of the other kind of axis.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs of one log; the first sets the effort unit and the kind of axis.
    axis_config : AxisConfig or None
        Drive-train constants to be applied, if any.

    Raises
    ------
    GreyboxError
        See :func:`predict_process`.
    """
    unit = runs[0].effort_unit
    units = runs[0].units
    name = runs[0].source or "<in-memory log>"
    for run in runs:
        if run.effort_unit != unit:
            raise GreyboxError(f"{run.source or '<in-memory log>'}: the runs mix effort units")
    if unit != "A" and axis_config is not None:
        raise GreyboxError(f"{name}: the log carries {units.load} in {unit} already; "
                           "axis metadata convert a current and do not apply")
    if axis_config is not None and axis_config.motion != runs[0].motion:
        raise GreyboxError(f"{name}: the log is of a {runs[0].motion} axis ({units.length}), the axis file "
                           f"{axis_config.source or '(in memory)'} describes a {axis_config.motion} one")


def process_attrs(model, *, axis_config: AxisConfig | None, interval: ProcessInterval | None, chunk_s: float,
                  motion: str, effort_unit: str, tally: ProcessTally, runs: list | None = None,
                  effort: str = "") -> dict:
    """The JSON-able description of a process result (``ProcessResult.attrs``).

    Parameters
    ----------
    model : CurrentModel
        The model.
    axis_config : AxisConfig, optional
        Drive-train constants used.
    interval : ProcessInterval, optional
        Calibrated interval used.
    chunk_s : float
        Chunk length [s].
    motion, effort_unit : str
        Kind of axis and effort unit of the log.
    tally : ProcessTally
        The figures of the whole result (for the extrapolation summary).
    runs : list of dict, optional
        ``{"start_s", "samples"}`` of each run of a log split at gaps.
    effort : str, default ""
        What the effort is (:func:`~greybox.data.effort.effort_quantity`); "" for the quantity
        ``effort_unit`` names. A motor torque's load constants are per Nm (``k_t = 1``).
    """
    quantity = effort or ("current" if effort_unit == "A" else MOTIONS[motion].load)
    attrs: dict = {"model_kind": model_kind(model), "chunk_s": float(chunk_s),
                   "effort": {"quantity": quantity, "unit": EFFORT_UNITS[quantity]}}
    if runs is not None and len(runs) > 1:
        attrs["runs"] = runs
    if effort_unit == "A" and axis_config is not None:
        units = MOTIONS[motion]
        per_ampere = f"{units.load_unit}_per_{EFFORT_UNITS[quantity]}"
        if quantity == "motor torque":  # the effort is k_t I already
            axis_config = axis_config.without_torque_constant()
        factors = axis_config.load_constants
        constants = {key: value for key, value in axis_config.to_dict().items() if key not in ("name", "channels")}
        attrs["axis_config"] = {"source": axis_config.source, **constants,
                                f"{units.load}_constant_driving_{per_ampere}": factors[0],
                                f"{units.load}_constant_backdriven_{per_ampere}": factors[1]}
    attrs["extrapolation"] = tally.extrapolation()
    if interval is not None:
        attrs["interval"] = interval.to_dict()
    return attrs


def process_blocks(model, blocks: Iterable[AxisLog], *, sample_time: float,
                   axis_config: AxisConfig | None = None, interval: ProcessInterval | None = None,
                   chunk_s: float = DEFAULT_CHUNK_S, tally: ProcessTally | None = None,
                   progress: Callable[[float], None] | None = None,
                   relevel: Relevel | None = None, read_ahead: bool = False) -> Iterator[ProcessResult]:
    """The process result of one run given block by block, one block at a time.

    The model runs over each block in chunks of ``chunk_s``, carrying its state (and the state of its
    training-region check) from chunk to chunk and block to block, so that the blocks of a run give
    what the run gives whole.

    Parameters
    ----------
    model : CurrentModel
        A fitted model (trained on air cuts) of a registered kind.
    blocks : iterable of AxisLog
        Consecutive prepared blocks of one run.
    sample_time : float
        Step [s] of the whole run (its median step).
    axis_config : AxisConfig, optional
        Drive-train constants; gives ``load`` for a current log.
    interval : ProcessInterval, optional
        Calibrated half-widths; gives the bounds.
    chunk_s : float, default 60.0
        Chunk length [s].
    tally : ProcessTally, optional
        Counts in every block with its training-region flags.
    progress : callable, optional
        Called after each chunk with the log time [s] reached.
    relevel : Relevel, optional
        Scales the model's current of each chunk per direction to the chunk's air moves
        (:mod:`greybox.predict.relevel`).
    read_ahead : bool, default False
        Predict block k on a thread of its own (the ``"model"`` pool) while ``blocks`` gives block k + 1 and
        the consumer takes block k - 1's result: a file's reading and writing overlap the model's work. The
        results are the same; block k's result comes out only after block k + 1 was taken from ``blocks``
        (so not for a live stream, which needs each block's result before it has the next).

    Yields
    ------
    ProcessResult
        One per block, ``attrs`` empty.
    """
    carried = [model.initial_state(), model.region_state()]

    per_chunk = samples_per_chunk(sample_time, chunk_s)

    def chunks(block: AxisLog) -> list[slice]:
        # a live message's few samples make one chunk: no need to cut it
        return [slice(0, len(block))] if len(block) <= per_chunk else chunk_slices(len(block), per_chunk)

    def predict(block: AxisLog):
        """The prediction and the training-region flags of one block, its chunks in turn (the state carried)."""
        predicted = np.empty(len(block))
        parts = []
        for samples in chunks(block):
            chunk = block if samples.stop - samples.start == len(block) else block.select(samples)
            predicted[samples], carried[0], flags, carried[1] = model.predict_flag_chunk(
                chunk, carried[0], carried[1], sample_time=sample_time)
            if relevel is not None and chunk.effort_unit == "A":
                predicted[samples] = relevel.model(chunk.time, chunk.effort, predicted[samples], chunk.velocity)
            parts.append(flags)
        regions = parts[0] if len(parts) == 1 else \
            {name: np.concatenate([flags[name] for flags in parts]) for name in parts[0]}
        return predicted, regions

    def finished(block: AxisLog, predicted: np.ndarray, regions: dict) -> ProcessResult:
        if progress is not None:
            for samples in chunks(block):
                progress(float(block.time[samples.stop - 1]))
        result = _block_result(block, predicted, regions, axis_config, interval)
        if tally is not None:
            tally.add(result, regions)
        return result

    if not read_ahead:
        for block in blocks:
            yield finished(block, *predict(block))
        return
    # The model runs over block k on its own thread while this one takes block k + 1 from ``blocks`` and the
    # consumer writes block k - 1 (at ``yield``): the blocks are predicted in order, one at a time, each from
    # the state the one before ended in, so the results are those of one block after the other.
    pending = None  # (block, future of its prediction)
    try:
        for block in blocks:
            done = None
            if pending is not None:
                done = (pending[0], *pending[1].result())
            pending = (block, shared_pool(1, "model").submit(predict, block))
            if done is not None:
                yield finished(*done)
        if pending is not None:
            done, pending = (pending[0], *pending[1].result()), None
            yield finished(*done)
    finally:
        if pending is not None:  # the consumer stopped early or reading failed: let the model's work end first
            wait([pending[1]])


def _block_result(block: AxisLog, predicted: np.ndarray, regions: dict, axis_config: AxisConfig | None,
                  interval: ProcessInterval | None) -> ProcessResult:
    """The process result of one prepared block from its prediction and training-region flags."""
    process = block.effort - predicted
    load = factors = load_bounds = half_width = None
    if axis_config is not None and block.attrs.get(MOTOR_TORQUE):  # the effort is k_t I already
        axis_config = axis_config.without_torque_constant()
    if block.effort_unit != "A":
        load = process
    elif axis_config is not None:
        load = axis_config.process_load(process, block.velocity)
        factors = axis_config.load_constants
    if interval is not None:
        half_width = interval.half_widths(block)
        if factors is not None:
            load_bounds = (axis_config.process_load(process - half_width, block.velocity),
                           axis_config.process_load(process + half_width, block.velocity))
    outside = outside_any(regions)
    return ProcessResult(time=block.time, position=block.position, velocity=block.velocity, measured=block.effort,
                         model=predicted, load=load, effort_unit=block.effort_unit, motion=block.motion,
                         load_constants=factors,
                         axis=block.axis or (axis_config.name if axis_config is not None else ""),
                         source=block.source, dataset=block.dataset or "", half_width=half_width,
                         load_bounds=load_bounds, outside=outside, effort_quantity=effort_quantity(block),
                         standstill=regions.get("standstill") if regions else None)


def join_results(parts: Sequence[ProcessResult], attrs: dict) -> ProcessResult:
    """One result of consecutive block results (of one or several runs), with ``attrs``.

    Parameters
    ----------
    parts : sequence of ProcessResult
        Consecutive block results, in time order; the first gives the fields that are not per sample.
    attrs : dict
        JSON-able description of the whole result (e.g. from :func:`process_attrs`).
    """
    first = parts[0]

    def joined(name):
        values = [getattr(part, name) for part in parts]
        return None if values[0] is None else np.concatenate(values)

    bounds = None
    if first.load_bounds is not None:
        bounds = tuple(np.concatenate([part.load_bounds[k] for part in parts]) for k in (0, 1))
    return replace(first, time=joined("time"), position=joined("position"), velocity=joined("velocity"),
                   measured=joined("measured"), model=joined("model"), load=joined("load"),
                   half_width=joined("half_width"), outside=joined("outside"), standstill=joined("standstill"),
                   load_bounds=bounds, attrs=attrs)


def predict_process(model, log: AxisLog | Sequence[AxisLog], *, axis_config: AxisConfig | None = None,
                    interval: ProcessInterval | None = None, chunk_s: float = DEFAULT_CHUNK_S,
                    progress: Callable[[int, int, float], None] | None = None,
                    relevel: bool = False) -> ProcessResult:
    """Process share of the current of a cutting log, and its force (torque on a rotary axis).

    Parameters
    ----------
    model : CurrentModel
        A fitted model (trained on air cuts) of a registered kind.
    log : AxisLog or sequence of AxisLog
        One prepared run recorded while cutting, or the consecutive runs of one log split at gaps
        (:func:`greybox.data.prepare.split_at_gaps`): each is predicted from the model's initial state,
        and the result holds them one after the other.
    axis_config : AxisConfig, optional
        Drive-train constants; gives ``load`` for a current log. Its kind of axis must be the log's.
    interval : ProcessInterval, optional
        Calibrated half-widths (:func:`~greybox.predict.interval.calibrate_interval`); gives the bounds
        of the process current and force.
    chunk_s : float, default 60.0
        The model runs over chunks of this length [s], carrying its state
        (see :mod:`greybox.models.chunked`).
    progress : callable, optional
        Called after each chunk as ``progress(done, chunks, time_s)``: chunks
        done, chunks in all, and the log time [s] reached.
    relevel : bool, default False
        Scale the model's current per chunk and direction of motion to the chunk's air moves
        (:mod:`greybox.predict.relevel`); the factors are in ``attrs["relevel"]``.

    Returns
    -------
    ProcessResult

    Raises
    ------
    GreyboxError
        For runs of different effort units, axis metadata given with a log that already carries its load,
        or axis metadata of a linear axis with a rotary log (or the other way round).
    """
    runs = as_log_list(log)
    check_process_inputs(runs, axis_config)
    n_chunks = sum(len(chunk_slices(len(run), samples_per_chunk(run.sample_time, chunk_s))) for run in runs)
    done = [0]

    def step(time_s: float) -> None:
        done[0] += 1
        progress(done[0], n_chunks, time_s)

    tally = ProcessTally()
    levels = [Relevel(sample_time=run.sample_time) if relevel else None for run in runs]
    with threadpool_limits(limits=1, user_api="blas"):  # idle BLAS threads spin, taking the kernels' cores
        parts = [part for run, level in zip(runs, levels)
                 for part in process_blocks(model, [run], sample_time=run.sample_time, axis_config=axis_config,
                                            interval=interval, chunk_s=chunk_s, tally=tally,
                                            progress=None if progress is None else step, relevel=level)]
    attrs = process_attrs(model, axis_config=axis_config, interval=interval, chunk_s=chunk_s,
                          motion=runs[0].motion, effort_unit=runs[0].effort_unit, tally=tally,
                          runs=[{"start_s": float(run.time[0]), "samples": len(run)} for run in runs],
                          effort=effort_quantity(runs[0]))
    if relevel:
        attrs["relevel"] = [chunk for level in levels for chunk in level.chunks_]
    return join_results(parts, attrs)
