"""The two experiments of Rüppel et al. (2024) as data, and running them on axis logs.

Experiment 1 (the paper's Table 3)
    Every model is trained on dataset A (random velocity steps and sines in a
    short position window) and tested on C (the same kind of motion, another
    draw): Coulomb, Stribeck, LuGre, GMS, the sole SVR and the grey-box
    GMS+SVR model, both stages on A.
Experiment 2 (the paper's Table 4)
    Stribeck, GMS and the sole SVR are trained on A + B (B: constant feeds
    over the full travel); the GMS+SVR model in two steps, its GMS stage
    identified on A and its SVR stage trained on B. All are tested on C + D
    (D: one back-and-forth pass over the full travel).

An experiment is a tuple of :class:`ModelSpec` (what to fit on which
datasets) and the test datasets. :func:`run_axis` reads the logs of one axis
(``<axis>_<dataset>.<ext>`` in a directory), fits every model of the
experiments, and returns an :class:`AxisResults` holding the fitted models,
their predictions and the metric records of :mod:`greybox.evaluate.records`.
A fit that two experiments share (the GMS stage on A) is done once.

When the logs carry the noise-free current (the extra channel
``truth_current_A`` of the synthetic axis, :mod:`greybox.twin`), a
``noise_floor`` record per experiment gives the error of that truth against
the measured current: the best any model can do.

:func:`experiment_figures` draws an experiment's figures (the paper's Figs. 3
to 6); :func:`reproduce` runs the experiments for several axes (in parallel
worker processes if asked) and writes the report of ``greybox reproduce``.
Saved models are tested on logs for ``greybox evaluate`` by
:func:`greybox.evaluate.records.evaluate_models`.
"""

from __future__ import annotations

import json
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Mapping, Sequence

import numpy as np

from ..data.log import AxisLog
from ..errors import GreyboxError
from ..evaluate.figures import error_boxplot, residual_vs_position, time_comparison
from ..evaluate.records import NOISE_FLOOR, TRUTH_CHANNEL, metric_record

__all__ = [
    "ModelSpec",
    "Experiment",
    "EXPERIMENTS",
    "MODEL_SETTINGS",
    "QUICK_SETTINGS",
    "GMSSVR_NOTE",
    "GMSSVR_EQ8_NOTE",
    "ModelResult",
    "AxisResults",
    "find_log",
    "load_axis_logs",
    "run_experiments",
    "run_axis",
    "TIME_MODELS",
    "experiment_figures",
    "QUICK_DURATION_S",
    "Reproduction",
    "reproduce",
]

#: Log file extensions :func:`find_log` tries, in this order.
LOG_EXTENSIONS = (".mcap", ".parquet", ".csv")


@dataclass(frozen=True)
class ModelSpec:
    """One model of an experiment: its kind and the datasets it is fitted on.

    Parameters
    ----------
    kind : str
        Model kind of :data:`greybox.models.registry.MODEL_CLASSES`.
    train : tuple of str
        Datasets the model is fitted on (for ``gmssvr`` with ``stage2``: the
        datasets of the GMS stage only).
    stage2 : tuple of str, default ()
        ``gmssvr`` only: datasets of the SVR stage; empty fits both stages on
        ``train``.
    name : str, optional
        The model's name in reports; ``kind`` by default. Two models of one
        kind in an experiment need different names.
    params : dict, optional
        Constructor arguments overriding the settings of the kind.
    """

    kind: str
    train: tuple[str, ...]
    stage2: tuple[str, ...] = ()
    name: str = ""
    params: Mapping = field(default_factory=dict)

    def __post_init__(self):
        if not self.name:
            object.__setattr__(self, "name", self.kind)

    @property
    def fitted_on(self) -> tuple[str, ...]:
        """Every dataset the model sees in training, in order, without repeats."""
        return tuple(dict.fromkeys(self.train + self.stage2))

    @property
    def training(self) -> str:
        """What the model is fitted on, e.g. ``"A+B"`` or ``"GMS on A, SVR on B"``."""
        if self.stage2:
            return f"GMS on {'+'.join(self.train)}, SVR on {'+'.join(self.stage2)}"
        return "+".join(self.train)

    def describe(self) -> str:
        """Short text such as ``"gmssvr (GMS on A, SVR on B)"``."""
        return f"{self.name} ({self.training})"


@dataclass(frozen=True)
class Experiment:
    """An experiment of the paper: models, their training data, the test data.

    Parameters
    ----------
    number : int
        1 or 2.
    title : str
        One line describing it.
    paper_table : str
        The table of Rüppel et al. (2024) it reproduces.
    models : tuple of ModelSpec
        Models in the order reports list them.
    test : tuple of str
        Test datasets; their runs are concatenated for the ``test`` record.
    notes : tuple of str, default ()
        Sentences printed under the experiment's table.
    """

    number: int
    title: str
    paper_table: str
    models: tuple[ModelSpec, ...]
    test: tuple[str, ...]
    notes: tuple[str, ...] = ()

    @property
    def datasets(self) -> tuple[str, ...]:
        """Every dataset the experiment reads, in order, without repeats."""
        names = [d for spec in self.models for d in spec.fitted_on] + list(self.test)
        return tuple(dict.fromkeys(names))

    @property
    def train(self) -> tuple[str, ...]:
        """Every dataset some model of the experiment is trained on."""
        return tuple(dict.fromkeys(d for spec in self.models for d in spec.fitted_on))


#: How the GMS+SVR models of the experiments differ, printed under their tables.
GMSSVR_NOTE = (
    "GMS+SVR: the SVR stage learns the residual of the frozen GMS stage, I = I_GMS + SVR(p, I_GMS, z_1..z_4), "
    "with the default search intervals (chosen on the training runs of a development family of truth axes)."
)
GMSSVR_EQ8_NOTE = (
    "GMS+SVR (eq. 8): the SVR stage learns the current itself, I = SVR(p, I_GMS, z_1..z_4), as the paper's "
    "eq. 8 is printed, with the default search intervals."
)

#: The paper's experiments (Rüppel et al. 2024, Tables 3 and 4), plus LuGre,
#: Coulomb and a one-dataset GMS+SVR model in experiment 1 and the paper's
#: form of the GMS+SVR model (SVR on the current) beside ours in experiment 2.
EXPERIMENTS: tuple[Experiment, ...] = (
    Experiment(
        number=1,
        title="train on A, test on C",
        paper_table="Table 3",
        models=(
            ModelSpec("coulomb", ("A",)),
            ModelSpec("stribeck", ("A",)),
            ModelSpec("lugre", ("A",)),
            ModelSpec("gms", ("A",)),
            ModelSpec("svr", ("A",)),
            ModelSpec("gmssvr", ("A",)),
        ),
        test=("C",),
        notes=(GMSSVR_NOTE,),
    ),
    Experiment(
        number=2,
        title="train on A + B (GMS+SVR: GMS on A, SVR on B), test on C + D",
        paper_table="Table 4",
        models=(
            ModelSpec("stribeck", ("A", "B")),
            ModelSpec("gms", ("A", "B")),
            ModelSpec("svr", ("A", "B")),
            ModelSpec("gmssvr", ("A",), stage2=("B",)),
            ModelSpec("gmssvr", ("A",), stage2=("B",), name="gmssvr_eq8",
                      params={"target": "current", "bounds": None}),
        ),
        test=("C", "D"),
        notes=(GMSSVR_NOTE, GMSSVR_EQ8_NOTE),
    ),
)

#: Hyperparameters of each model kind in ``greybox reproduce``: the models'
#: defaults (for GMS+SVR the SVR stage learns the GMS residual, see
#: :data:`GMSSVR_NOTE` and docs/svr.md for why) with SVR
#: budgets that keep both experiments on both shipped axes within a few minutes
#: on two cores.
MODEL_SETTINGS: dict[str, dict] = {
    "coulomb": {},
    "stribeck": {},
    "lugre": {},
    "gms": {},
    "svr": {"n_subset": 1000, "n_calls": 12},
    "gmssvr": {"n_subset": 1500, "n_calls": 15},
}

#: Smaller budgets of ``greybox reproduce --quick`` (a smoke run, not the paper's figures).
QUICK_SETTINGS: dict[str, dict] = {
    "coulomb": {},
    "stribeck": {},
    "lugre": {"n_starts": 1, "max_iter": 100},
    "gms": {"n_starts": 1, "max_iter": 100},
    "svr": {"n_subset": 300, "n_calls": 6, "cv_blocks": 6},
    "gmssvr": {"n_subset": 300, "n_calls": 6, "cv_blocks": 6, "gms": {"n_starts": 1, "max_iter": 100}},
}


# ---------------------------------------------------------------- reading logs
def find_log(data_dir: str | Path, axis: str, dataset: str) -> Path:
    """Return the log file ``<axis>_<dataset>.<ext>`` in ``data_dir``.

    Extensions are tried in the order of :data:`LOG_EXTENSIONS`.

    Parameters
    ----------
    data_dir : str or Path
        Folder holding the logs.
    axis : str
        Axis name, the part of the file name before ``_`` (e.g. ``"X"``).
    dataset : str
        Dataset id, the part after ``_`` (e.g. ``"A"``).

    Raises
    ------
    GreyboxError
        If the directory does not exist or holds no such file.
    """
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise GreyboxError(f"{data_dir}: data directory does not exist")
    for extension in LOG_EXTENSIONS:
        path = data_dir / f"{axis}_{dataset}{extension}"
        if path.is_file():
            return path
    tried = ", ".join(f"{axis}_{dataset}{e}" for e in LOG_EXTENSIONS)
    raise GreyboxError(f"{data_dir}: no log of axis {axis}, dataset {dataset} (looked for {tried})")


def load_axis_logs(
    data_dir: str | Path,
    axis: str,
    datasets: Iterable[str],
    *,
    max_duration_s: float | None = None,
) -> dict[str, AxisLog]:
    """Read and prepare the logs of one axis, one run per dataset (default derivative filter).

    Parameters
    ----------
    data_dir : path-like
        Directory of ``<axis>_<dataset>.mcap`` (or ``.parquet``, ``.csv``) files.
    axis : str
        Axis name, e.g. ``"X"``.
    datasets : iterable of str
        Dataset names, e.g. ``"ABCD"``.
    max_duration_s : float, optional
        Keep only the first ``max_duration_s`` seconds of every log (quick runs).

    Returns
    -------
    dict
        ``{dataset: prepared AxisLog}``.
    """
    from ..data.io import read_log
    from ..data.prepare import prepare, trim

    logs = {}
    for dataset in dict.fromkeys(datasets):
        log = read_log(find_log(data_dir, axis, dataset))
        if max_duration_s is not None:
            log = trim(log, stop_s=float(log.time[0]) + max_duration_s)
        logs[dataset] = prepare(log)[0]
    return logs


# ---------------------------------------------------------------- results
@dataclass
class ModelResult:
    """A fitted model of an experiment and its predictions.

    Attributes
    ----------
    spec : ModelSpec
    model : CurrentModel
        The fitted model.
    fit_seconds : float
        Wall time of the fit [s] (0 for a fit shared with an earlier experiment).
    train_prediction : dict
        ``{dataset: predicted current [A]}`` on every training run.
    test_prediction : dict
        ``{dataset: predicted current [A]}`` on every test run.
    notes : list of str
        Warnings the fit issued (e.g. a hyperparameter at the end of its search interval).
    """

    spec: ModelSpec
    model: object
    fit_seconds: float
    train_prediction: dict[str, np.ndarray]
    test_prediction: dict[str, np.ndarray]
    notes: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.spec.name


@dataclass
class AxisResults:
    """Everything one axis's experiments produced.

    Attributes
    ----------
    axis : str
    logs : dict
        ``{dataset: prepared AxisLog}``.
    experiments : dict
        ``{experiment number: list of ModelResult}``.
    records : list of dict
        Metric records (see :func:`metric_record`), noise floor included.
    hyperparameters : list of dict
        Table-2 rows of the SVR-based models: ``experiment``, ``axis``,
        ``model`` and the model's ``hyperparameters_table()``.
    seconds : float
        Wall time of reading, fitting and predicting [s].
    """

    axis: str
    logs: dict[str, AxisLog]
    experiments: dict[int, list[ModelResult]] = field(default_factory=dict)
    records: list[dict] = field(default_factory=list)
    hyperparameters: list[dict] = field(default_factory=list)
    seconds: float = 0.0


def _settings_for(spec: ModelSpec, settings: Mapping[str, Mapping]) -> dict:
    """Constructor arguments of a model: its kind's settings and its own.

    A hyperparameter named after a registered kind is a stage of that kind (the ``gms`` of ``gmssvr``):
    it is built from that kind's settings unless given as a model.
    """
    from ..models.registry import MODEL_CLASSES, model_class

    params = {**settings.get(spec.kind, {}), **spec.params}
    for name in model_class(spec.kind)().get_params(deep=False):
        if name in MODEL_CLASSES:
            stage = params.get(name, settings.get(name, {}))
            params[name] = stage if hasattr(stage, "get_params") else model_class(name)(**dict(stage))
    return params


def _key(model, train: tuple[str, ...], stage2: tuple[str, ...] = ()) -> str:
    """Cache key of a fit: the model's class and hyperparameters, and the datasets."""
    params = {name: (value.get_params() if hasattr(value, "get_params") else value)
              for name, value in model.get_params(deep=False).items()}
    return json.dumps([type(model).__name__, params, train, stage2], sort_keys=True, default=repr)


class _FitCache:
    """Fits already done in this run, so that experiments sharing one fit do it once."""

    def __init__(self):
        self.models: dict[str, object] = {}

    def fit(self, spec: ModelSpec, settings, logs, model_progress) -> tuple[object, float, list[Warning]]:
        """The fitted model, the fit's wall time [s] (0 when shared) and the warnings it issued (each once)."""
        from ..models.registry import model_class

        model = model_class(spec.kind)(**_settings_for(spec, settings))
        key = _key(model, spec.train, spec.stage2)
        if key in self.models:
            return self.models[key], 0.0, []
        started = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            template = model.first_stage()
            first = None if template is None else self._stage(template, spec.train, logs, model_progress)
            model.fit_staged([logs[d] for d in spec.train], [logs[d] for d in spec.stage2] if spec.stage2 else None,
                             progress=model_progress, first_stage=first)
        self.models[key] = model
        notes = list({str(w.message): w.message for w in caught}.values())
        return model, time.perf_counter() - started, notes

    def _stage(self, template, train, logs, model_progress):
        """The first stage ``template`` fitted on ``train`` (shared with a fit of that stage's kind alone)."""
        key = _key(template, tuple(train))
        if key not in self.models:
            self.models[key] = template.fit([logs[d] for d in train], progress=model_progress)
        return self.models[key]


def run_experiments(
    logs: Mapping[str, AxisLog],
    axis: str,
    experiments: Sequence[Experiment] = EXPERIMENTS,
    *,
    settings: Mapping[str, Mapping] | None = None,
    progress: Callable[[str | Warning], None] | None = None,
    model_progress=None,
) -> AxisResults:
    """Fit and test every model of ``experiments`` on the prepared logs of one axis.

    Parameters
    ----------
    logs : dict
        ``{dataset: prepared AxisLog}`` holding every dataset the experiments name.
    axis : str
        Axis name for the records.
    experiments : sequence of Experiment, default :data:`EXPERIMENTS`
    settings : dict, optional
        ``{kind: constructor arguments}``; default :data:`MODEL_SETTINGS`. For
        ``gmssvr`` the entry ``"gms"`` (a dict, or an unfitted GMSModel) sets
        the GMS stage, by default the ``gms`` entry.
    progress : callable, optional
        Receives one line of text per step (model fitted, with its time), and each warning a fit
        issued (a :class:`Warning`; a :class:`~greybox.errors.SettingWarning` names the settings it
        concerns), to be shown as a note.
    model_progress : None, bool or callable, optional
        Passed to every model's ``fit`` (see :meth:`greybox.models.estimator.CurrentModel.fit`).

    Returns
    -------
    AxisResults
    """
    settings = MODEL_SETTINGS if settings is None else settings
    missing = sorted({d for e in experiments for d in e.datasets} - set(logs))
    if missing:
        raise GreyboxError(f"axis {axis}: no log of dataset(s) {', '.join(missing)}")
    started = time.perf_counter()
    results = AxisResults(axis=axis, logs=dict(logs))
    cache = _FitCache()
    say = progress or (lambda line: None)
    for experiment in experiments:
        models = []
        for spec in experiment.models:
            model, seconds, notes = cache.fit(spec, settings, logs, model_progress)
            train = {d: model.predict(logs[d]) for d in spec.fitted_on}
            test = {d: model.predict(logs[d]) for d in experiment.test}
            result = ModelResult(spec, model, seconds, train, test, [str(note) for note in notes])
            models.append(result)
            results.records += _model_records(experiment, axis, result, logs)
            if hasattr(model, "hyperparameters_table"):
                results.hyperparameters.append({"experiment": experiment.number, "axis": axis,
                                                "model": spec.name, **model.hyperparameters_table()})
            test_re = results.records[-1]["re"]
            shared = " (shared fit)" if seconds == 0.0 else f" in {seconds:.1f} s"
            say(f"axis {axis}, experiment {experiment.number}: {spec.describe()}{shared}, "
                f"test RE {test_re:.2f} %")
            for note in notes:
                say(note)
        results.experiments[experiment.number] = models
        results.records += _noise_floor_records(experiment, axis, logs)
    results.seconds = time.perf_counter() - started
    return results


def _model_records(experiment: Experiment, axis: str, result: ModelResult, logs) -> list[dict]:
    """The train and test records of one fitted model."""
    records = []
    for dataset, predictions in (("train", result.train_prediction), ("test", result.test_prediction)):
        names = list(predictions)
        measured = np.concatenate([logs[d].effort for d in names])
        modelled = np.concatenate([predictions[d] for d in names])
        per_log = {d: (logs[d].effort, predictions[d]) for d in names}
        records.append(metric_record(experiment.number, axis, result.name, dataset, measured, modelled,
                                     names, per_log))
    return records


def _noise_floor_records(experiment: Experiment, axis: str, logs) -> list[dict]:
    """Train and test records of the noise-free current, when every log carries it."""
    records = []
    for dataset, names in (("train", experiment.train), ("test", experiment.test)):
        if not all(TRUTH_CHANNEL in logs[d].extras for d in names):
            continue
        measured = np.concatenate([logs[d].effort for d in names])
        truth = np.concatenate([logs[d].extras[TRUTH_CHANNEL] for d in names])
        per_log = {d: (logs[d].effort, logs[d].extras[TRUTH_CHANNEL]) for d in names}
        records.append(metric_record(experiment.number, axis, NOISE_FLOOR, dataset, measured, truth,
                                     list(names), per_log))
    return records


def run_axis(
    data_dir: str | Path,
    axis: str,
    experiments: Sequence[Experiment] = EXPERIMENTS,
    *,
    settings: Mapping[str, Mapping] | None = None,
    max_duration_s: float | None = None,
    progress: Callable[[str | Warning], None] | None = None,
    model_progress=None,
) -> AxisResults:
    """Read the logs of one axis from ``data_dir`` and run the experiments on them.

    Parameters
    ----------
    data_dir : path-like
        Directory of ``<axis>_<dataset>.mcap`` files (the shipped ``data/``).
    axis : str
        Axis name, e.g. ``"X"``.
    experiments, settings, progress, model_progress
        See :func:`run_experiments`.
    max_duration_s : float, optional
        Use only the first ``max_duration_s`` seconds of every log.

    Returns
    -------
    AxisResults
        ``seconds`` includes reading and preparing the logs.
    """
    started = time.perf_counter()
    datasets = dict.fromkeys(d for e in experiments for d in e.datasets)
    logs = load_axis_logs(data_dir, axis, datasets, max_duration_s=max_duration_s)
    if progress is not None:
        progress(f"axis {axis}: read {len(logs)} logs in {time.perf_counter() - started:.1f} s")
    results = run_experiments(logs, axis, experiments, settings=settings, progress=progress,
                              model_progress=model_progress)
    results.seconds = time.perf_counter() - started
    return results


# ---------------------------------------------------------------- figures
#: Models drawn in the time-domain comparisons (the paper's Figs. 4 and 6), when present.
TIME_MODELS = ("stribeck", "svr", "gms", "gmssvr")


def experiment_figures(results, experiment, out_dir: str | os.PathLike) -> list[tuple[str, Path]]:
    """The figures of one experiment over all axes: box plot, time comparisons, residual maps.

    Parameters
    ----------
    results : sequence of AxisResults
        One per axis.
    experiment : Experiment
    out_dir : path-like
        Directory of the PNG files (``exp<n>_*.png``).

    Returns
    -------
    list of (caption, path)
    """
    out_dir = Path(out_dir)
    n = experiment.number
    test = "+".join(experiment.test)
    figures = []
    panels = []
    for axis_results in results:
        runs = [axis_results.logs[d] for d in experiment.test]
        predictions = {m.name: [m.test_prediction[d] for d in experiment.test]
                       for m in axis_results.experiments[n]}
        if all(TRUTH_CHANNEL in run.extras for run in runs):
            predictions["noise_floor"] = [run.extras[TRUTH_CHANNEL] for run in runs]
        panels.append((f"axis {axis_results.axis}, test on {test}", runs, predictions))
    figure_number = {1: "Fig. 3", 2: "Fig. 5"}.get(n, "")
    path = error_boxplot(panels, out_dir / f"exp{n}_error_boxplot.png",
                         title=f"Experiment {n}: absolute error on {test}")
    figures.append((f"Experiment {n}: absolute error of each model on {test} "
                    f"(boxes: quartiles, whiskers: 5th-95th percentile; like the paper's {figure_number})", path))
    figure_number = {1: "Fig. 4", 2: "Fig. 6"}.get(n, "")
    for axis_results, (_, runs, predictions) in zip(results, panels):
        axis = axis_results.axis
        shown = {m: predictions[m] for m in TIME_MODELS if m in predictions}
        path = time_comparison(runs, shown, out_dir / f"exp{n}_time_{axis}.png",
                               title=f"Experiment {n}, axis {axis}: measured and modelled current")
        figures.append((f"Experiment {n}, axis {axis}: measured and modelled current on {test} "
                        f"(like the paper's {figure_number})", path))
        models = {m: p for m, p in predictions.items() if m != "noise_floor"}
        path = residual_vs_position(runs, models, out_dir / f"exp{n}_residual_position_{axis}.png",
                                    title=f"Experiment {n}, axis {axis}: residual against position on {test}")
        figures.append((f"Experiment {n}, axis {axis}: measured minus modelled current against position, "
                        f"by direction of motion, on {test}", path))
    return figures


# ---------------------------------------------------------------- the whole reproduction
#: Seconds of every log used by ``greybox reproduce --quick``.
QUICK_DURATION_S = 30.0


@dataclass
class Reproduction:
    """What :func:`reproduce` wrote and measured.

    Attributes
    ----------
    results : list of AxisResults
        One per axis, in the order asked.
    records : list of dict
        Metric records of all axes.
    hyperparameters : list of dict
        Table-2 rows.
    timings : list of dict
        ``experiment``, ``axis``, ``model``, ``trained_on``, ``fit_seconds``.
    files : dict
        Written report files (``metrics_json``, ``metrics_csv``, ``tables``, ``html``),
        plus ``figures`` (list of paths) and ``models`` (list of model files).
    seconds : float
        Wall time of the whole run [s].
    """

    results: list[AxisResults]
    records: list[dict]
    hyperparameters: list[dict]
    timings: list[dict]
    files: dict
    seconds: float


class _QueueProgress:
    """Picklable progress callback that forwards to a queue (for worker processes)."""

    def __init__(self, queue, kind: str):
        self.queue = queue
        self.kind = kind

    def __call__(self, item) -> None:
        self.queue.put((self.kind, item))


def _run_axes(data_dir, axes, experiments, settings, max_duration_s, jobs, progress, model_progress):
    """:func:`run_axis` for every axis, in ``jobs`` worker processes when more than one."""
    from ..identify.progress import make_progress

    model_progress = make_progress(model_progress)
    kwargs = {"settings": settings, "max_duration_s": max_duration_s}
    if jobs <= 1 or len(axes) <= 1:
        return [run_axis(data_dir, axis, experiments, progress=progress, model_progress=model_progress, **kwargs)
                for axis in axes]

    import multiprocessing
    import threading
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("spawn")
    with context.Manager() as manager, ProcessPoolExecutor(max_workers=min(jobs, len(axes)),
                                                           mp_context=context) as pool:
        queue = manager.Queue()
        sinks = {"line": progress, "event": model_progress}

        def forward():
            while (item := queue.get()) is not None:
                kind, payload = item
                if sinks[kind] is not None:
                    sinks[kind](payload)

        forwarder = threading.Thread(target=forward, daemon=True)
        forwarder.start()
        futures = [pool.submit(run_axis, data_dir, axis, experiments,
                               progress=_QueueProgress(queue, "line") if progress else None,
                               model_progress=_QueueProgress(queue, "event") if model_progress else None,
                               **kwargs)
                   for axis in axes]
        try:
            return [future.result() for future in futures]
        finally:
            queue.put(None)
            forwarder.join()


def reproduce(
    out_dir: str | Path,
    data_dir: str | Path,
    *,
    axes: Sequence[str] = ("X", "Y"),
    experiments: Sequence[Experiment] = EXPERIMENTS,
    quick: bool = False,
    settings: Mapping[str, Mapping] | None = None,
    jobs: int = 1,
    save_models: bool = True,
    progress: Callable[[str | Warning], None] | None = None,
    model_progress=None,
    intro: str = "",
) -> Reproduction:
    """Run the paper's experiments on the logs of every axis and write the report into ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Report directory, created if missing; existing report files in it are replaced.
    data_dir : path-like
        Directory of the ``<axis>_<dataset>.mcap`` logs (the shipped ``data/``).
    axes : sequence of str, default ("X", "Y")
    experiments : sequence of Experiment, default :data:`EXPERIMENTS`
    quick : bool, default False
        Use only the first :data:`QUICK_DURATION_S` seconds of every log and
        :data:`QUICK_SETTINGS` (a smoke run: its figures are not the paper's).
    settings : dict, optional
        Model settings (see :func:`run_experiments`); overrides the choice made by ``quick``.
    jobs : int, default 1
        Worker processes; the axes run in parallel when more than one.
    save_models : bool, default True
        Write every fitted model to ``out_dir/models/exp<n>_<axis>_<model>.gbm``.
    progress : callable, optional
        Receives one line of text per step, and each warning a fit issued (see :func:`run_experiments`).
    model_progress : None, bool or callable, optional
        Progress of every model fit (see :meth:`greybox.models.estimator.CurrentModel.fit`).
    intro : str
        Text placed under the report's title (e.g. the command that made it).

    Returns
    -------
    Reproduction
    """
    from ..evaluate.report import report_tables, write_report
    from ..models.files import save_model

    started = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if settings is None:
        settings = QUICK_SETTINGS if quick else MODEL_SETTINGS
    say = progress or (lambda line: None)
    results = _run_axes(data_dir, list(axes), experiments, settings, QUICK_DURATION_S if quick else None,
                        jobs, progress, model_progress)

    records = [r for axis_results in results for r in axis_results.records]
    hyperparameters = [h for axis_results in results for h in axis_results.hyperparameters]
    timings = []
    model_files = []
    for experiment in experiments:
        for axis_results in results:
            for result in axis_results.experiments[experiment.number]:
                timings.append({"experiment": experiment.number, "axis": axis_results.axis, "model": result.name,
                                "trained_on": result.spec.training, "fit_seconds": result.fit_seconds,
                                "notes": result.notes})
                if save_models:
                    path = out_dir / "models" / f"exp{experiment.number}_{axis_results.axis}_{result.name}.gbm"
                    path.parent.mkdir(exist_ok=True)
                    model_files.append(save_model(result.model, path, overwrite=True))

    say("drawing figures")
    figures = []
    for experiment in experiments:
        figures += experiment_figures(results, experiment, out_dir)
    training = {e.number: {spec.name: spec.training for spec in e.models} for e in experiments}
    titles = {e.number: f"Experiment {e.number} ({e.paper_table}): {e.title}" for e in experiments}
    notes = {e.number: list(e.notes) for e in experiments}
    tables = report_tables(records, hyperparameters, timings, titles=titles, training=training, notes=notes)
    seconds = time.perf_counter() - started
    text = intro.rstrip() + "\n\n" if intro else ""
    text += (f"Axes {', '.join(axes)}; logs from {data_dir}"
             f"{f' (first {QUICK_DURATION_S:g} s of each, quick settings)' if quick else ''}. "
             f"Fitting, testing and drawing took {seconds:.0f} s.")
    files = write_report(out_dir, records, tables, figures, title="greybox: the paper's experiments reproduced",
                         intro=text)
    files["figures"] = [path for _, path in figures]
    files["models"] = model_files
    say(f"wrote {files['html']} in {seconds:.0f} s")
    return Reproduction(results, records, hyperparameters, timings, files, time.perf_counter() - started)
