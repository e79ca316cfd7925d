"""What one :func:`~greybox.predict.run.predict_logs` call asks for and what it gives back.

:class:`Request` holds the call's options as given and does what every model source needs of them:
checking the outputs before any work, calibrating the interval, reporting progress and writing the
table. :class:`Prediction` is the result (also of a fleet run, :func:`greybox.fleet.predict.predict_fleet`):
the lines to show, the figures of each axis (:class:`AxisFigures`) and what was written;
:class:`ChunkProgress` is what the progress callback receives after each chunk.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..errors import GreyboxError, Setting
from ..provenance import training_file_warning
from .interval import DEFAULT_COVERAGE, ProcessInterval, calibrate_interval
from .output import check_output_path, output_paths, write_process
from .process import ProcessTally

__all__ = ["PLOT_SUFFIXES", "AxisFigures", "ChunkProgress", "Prediction", "Request", "named"]

#: Extensions of the picture.
PLOT_SUFFIXES = (".png", ".svg", ".pdf")


@dataclass(frozen=True)
class ChunkProgress:
    """Where a prediction stands, after each chunk: given to the ``progress`` callback of a prediction.

    Attributes
    ----------
    done : int
        Chunks done.
    chunks : int
        Chunks in all (of the axis being predicted).
    time_s : float
        Log time reached [s].
    end_s : float
        Log time of the last sample [s].
    elapsed_s : float
        Wall time since the prediction of the axis started [s].
    """

    done: int
    chunks: int
    time_s: float
    end_s: float
    elapsed_s: float


@dataclass(frozen=True)
class AxisFigures:
    """The figures of one axis's prediction that are reported: rms, largest values, extrapolation, interval.

    Attributes
    ----------
    tally : ProcessTally
        Running figures of the process table (:class:`~greybox.predict.process.ProcessTally`).
    effort_unit : str
        "A", "N" or "Nm".
    motion : str
        "linear" or "rotary".
    load_constants : (float, float) or None
        Factors from process current to load, driving and back-driven [N/A or Nm/A]; None without
        axis metadata.
    extrapolation : dict
        Share of samples outside the training region (:func:`~greybox.predict.process.extrapolation_summary`).
    interval : ProcessInterval or None
        The calibrated interval.
    axis_file : str or None
        Name of the file the load constants came from.
    log_name : str
        Name of the log.
    calibration_logs : int
        Calibration logs the interval was calibrated on.
    quantity : str
        What the effort is (:func:`~greybox.data.effort.effort_quantity`): "current", "motor torque",
        "force" or "torque".
    """

    tally: ProcessTally
    effort_unit: str
    motion: str
    load_constants: tuple[float, float] | None
    extrapolation: dict
    interval: ProcessInterval | None = None
    axis_file: str | None = None
    log_name: str = ""
    calibration_logs: int = 0
    quantity: str = "current"

    @property
    def units(self):
        """Units of the axis (:class:`~greybox.data.quantities.Motion`)."""
        from ..data.quantities import MOTIONS

        return MOTIONS[self.motion]


@dataclass(frozen=True)
class Prediction:
    """What :func:`~greybox.predict.run.predict_logs` did, in the order to report it.

    Attributes
    ----------
    summary : list of str
        Lines before the figures (which model predicted which log, samples, chunks).
    axes : list of (str or None, AxisFigures)
        Each axis's figures, with a heading line where the log has several axes.
    closing : list of str
        Lines after the figures (interpolated axes, resultant force; a fleet's summary and failures).
    written : list of str
        Files written, in order (table, its metadata sidecar, picture); a fleet's dataset is in ``closing``.
    elapsed_s : float or None
        Wall time of the prediction itself [s] (reading, predicting, writing of a streamed log); None for
        a fleet run.
    status : int
        Exit status: 0, or 2 when a log of a fleet failed.
    result : ProcessResult or MachineProcessResult or None
        The result of a log read whole; None when it was streamed or for a fleet run.
    manifest : dict or None
        The manifest of a fleet run.
    """

    summary: list = field(default_factory=list)
    axes: list = field(default_factory=list)
    closing: list = field(default_factory=list)
    written: list = field(default_factory=list)
    elapsed_s: float | None = None
    status: int = 0
    result: object = None
    manifest: dict | None = None


@dataclass(frozen=True)
class Request:
    """The options of one :func:`~greybox.predict.run.predict_logs` call, as given.

    Parameters
    ----------
    out : Path
        The process table of the log.
    axis_config, machine : str or None
        Axis file of a model file's axis; machine file of a machine model (TOML).
    calibration : list of str or None
        Air-cut logs that calibrate the bounds of the process current.
    coverage : float or None
        Nominal coverage of the bounds, in (0, 1).
    plot : str or None
        Picture to draw (.png, .svg, .pdf).
    plot_mean_s : float
        Window of the moving mean drawn over the process current [s].
    plot_window : (float, float) or None
        Time window of the picture [s].
    chunk_s : float
        Chunk length of the model [s].
    read : dict
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    force : bool
        Replace outputs that exist (never an input).
    progress : callable or None
        ``progress(ChunkProgress)`` after each chunk.
    notify : callable
        ``notify(line)`` with each note or warning line.
    relevel : bool
        Scale the model's current per chunk and direction to the log's air moves (:mod:`greybox.predict.relevel`).
    """

    out: Path
    axis_config: str | None
    machine: str | None
    calibration: list | None
    coverage: float | None
    plot: str | None
    plot_mean_s: float
    plot_window: tuple | None
    chunk_s: float
    read: dict
    force: bool
    progress: Callable | None
    notify: Callable[[str], None]
    relevel: bool = False

    def warn(self, line: str | None) -> None:
        """Pass ``line`` (a note or warning, or None for nothing to say) to ``notify``.

        Parameters
        ----------
        line : str or None
            The line.
        """
        if line is not None:
            self.notify(line)

    def check_outputs(self, log: str, inputs: list) -> None:
        """Refuse, before any work, outputs that must not or cannot be written.

        Parameters
        ----------
        log : str
            The log to predict (it may not also calibrate the interval).
        inputs : list of str
            Every file the call reads: none of them is ever written.

        Raises
        ------
        GreyboxError
            For an output that exists (without ``force``) or is an input, an unknown picture extension,
            options that need another, a calibration log that is the log itself.
        """
        out = self.out
        for target in output_paths(out):  # the table, and for CSV its metadata sidecar
            check_output_path(target, overwrite=self.force, protect=inputs)
        if self.plot:
            plot = Path(self.plot)
            if plot.suffix.lower() not in PLOT_SUFFIXES:
                raise GreyboxError(f"{plot}: unknown picture extension '{plot.suffix}'; use {', '.join(PLOT_SUFFIXES)}")
            if plot.resolve() == out.resolve():
                raise GreyboxError(f"{plot}: ", named("plot"), " and ", named("out"), " name the same file")
            check_output_path(plot, overwrite=self.force, protect=inputs)
        elif self.plot_window is not None:
            raise GreyboxError(named("plot_window"), " needs ", Setting("plot"))
        if self.calibration is None and self.coverage is not None:
            raise GreyboxError(named("coverage"), " needs ", Setting("calibration"),
                               " (air-cut logs the model was not trained on)")
        own = [path for path in self.calibration or () if Path(path).resolve() == Path(log).resolve()]
        if own:
            raise GreyboxError(named("calibration"), f": {own[0]} is the cutting log itself; calibrate on air cuts "
                               "the model was not trained on")

    def interval(self, model, read: Callable[[str], list], records: dict | None = None,
                 model_name: str = "the model") -> ProcessInterval | None:
        """The calibrated interval of ``model`` from the calibration logs, or None without them.

        A calibration log that is one of the model's training files (by its SHA-256 in the training
        record) gets a warning.

        Parameters
        ----------
        model : fitted model
            The model whose process current the interval bounds.
        read : callable
            ``read(path)`` gives the prepared runs of a calibration log.
        records : dict, optional
            The model file's records (its training files).
        model_name : str, default "the model"
            Name of the model file, for the warning.
        """
        if not self.calibration:
            return None
        for path in self.calibration:
            self.warn(training_file_warning(records or {}, path, model_name))
        return calibrate_interval(model, [run for path in self.calibration for run in read(path)],
                                  coverage=DEFAULT_COVERAGE if self.coverage is None else self.coverage,
                                  chunk_s=self.chunk_s)

    def chunk_progress(self, end_s: Callable[[], float]) -> Callable[[int, int, float], None] | None:
        """The chunk callback of the predictors, reporting :class:`ChunkProgress`; None without ``progress``.

        Parameters
        ----------
        end_s : callable
            ``end_s()`` gives the log's end [s]; called once, at the first chunk (a streamed log's end is
            known once its time stamps have been read).
        """
        if self.progress is None:
            return None
        started = time.perf_counter()
        end: list = []

        def step(done: int, chunks: int, time_s: float) -> None:
            if not end:  # a streamed log's end is known once its time stamps have been read
                end.append(end_s())
            self.progress(ChunkProgress(done, chunks, time_s, end[0], time.perf_counter() - started))

        return step

    def write(self, result, inputs: list, window, draw) -> list[str]:
        """Write the table (atomically) and, when asked, the picture; return the paths written.

        Parameters
        ----------
        result : process result
            What :mod:`~greybox.predict.process` computed for the log.
        inputs : list of str
            Every file the call reads: none of them is ever written.
        window : (float, float) or None
            Time window of the picture [s].
        draw : callable
            ``draw(result, path, mean_s=, window=)`` draws the picture.
        """
        write_process(result, self.out, overwrite=self.force, protect=inputs)
        written = [str(target) for target in output_paths(self.out)]
        if self.plot:
            draw(result, self.plot, mean_s=self.plot_mean_s, window=window)
            written.append(str(self.plot))
        return written


def named(name: str) -> Setting:
    """The setting ``name`` of :func:`~greybox.predict.run.predict_logs`, named in a message.

    The command line spells it as its option (``coverage`` as ``--interval``).

    Parameters
    ----------
    name : str
        The keyword of :func:`~greybox.predict.run.predict_logs`.
    """
    return Setting(name, assign=False)

