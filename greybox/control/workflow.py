"""The compensation study as one library call: plant, feed-forward models, references -> tracking errors.

``greybox compensate`` wires its options to :func:`compensation_study`; a
script or a notebook calls it with a plant (:class:`~greybox.control.plants.TwinPlant`
or :class:`~greybox.control.plants.ModelPlant`) and fitted current models.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Callable, Mapping, Sequence

from ..data.log import AxisLog
from ..data.prepare import prepare
from ..errors import GreyboxError
from ..models.files import load_model
from ..models.registry import model_kind
from ..train import train_logs
from ..twin import CurrentNoise, axis_geometry, make_dataset
from .feedforward import InertiaFeedForward, ModelFeedForward
from .loop import LoopResult, compare_feedforwards, controller_periods
from .pid import PIDGains
from .plants import TwinPlant
from .references import STROKES_MM, Reference, reference_from_log, stroke_reference
from .tuning import default_bandwidth_hz, pole_placement_gains

__all__ = ["DEFAULT_REFERENCE_STEP_S", "CompensationResult", "check_axis_kind", "compensation_study",
           "feedforward_models", "synthesises_training", "twin_training_runs"]

#: Step [s] of generated references when no feed-forward model says otherwise.
DEFAULT_REFERENCE_STEP_S = 0.002

#: Datasets of the twin a twin plant's feed-forward models are fitted on: random windows and pre-sliding.
TWIN_TRAINING_DATASETS = "AP"


@dataclass
class CompensationResult:
    """Outcome of :func:`compensation_study`.

    Attributes
    ----------
    results : list of LoopResult
        One closed-loop run per reference and feed-forward.
    gains : PIDGains
        The one set of PID gains every run used.
    controller_period_s : float
        Controller period [s].
    bandwidth_hz : float
        Closed-loop bandwidth of the pole placement [Hz].
    settings : dict
        JSON-ready description of the plant, feed-forwards, references and loop.
    """

    results: list[LoopResult]
    gains: PIDGains
    controller_period_s: float
    bandwidth_hz: float
    settings: dict


def synthesises_training(plant) -> bool:
    """Whether models for ``plant`` can be fitted without training logs (on its synthetic datasets).

    Parameters
    ----------
    plant : TwinPlant or ModelPlant
        The plant of the loop.

    Returns
    -------
    bool
        True for a twin plant of a named axis.
    """
    return isinstance(plant, TwinPlant) and plant.axis is not None


def twin_training_runs(plant: TwinPlant, *, seed: int = 0, duration_s: float = 60.0) -> list[AxisLog]:
    """Prepared synthetic training runs (datasets A and P) of a twin plant's axis.

    Parameters
    ----------
    plant : TwinPlant
        Twin plant of a named axis (``plant.axis`` set, e.g. by :meth:`TwinPlant.for_axis`).
    seed : int, default 0
        Master seed of the synthetic datasets.
    duration_s : float, default 60.0
        Length [s] of each dataset.

    Raises
    ------
    GreyboxError
        If the plant is not a twin of a named axis.
    """
    if not synthesises_training(plant):
        raise GreyboxError("feed-forward models for a model plant need training logs")
    return prepare([make_dataset(plant.axis, dataset, seed, duration_s=duration_s)
                    for dataset in TWIN_TRAINING_DATASETS])


def check_axis_kind(source, motion: str, plant) -> None:
    """Refuse a model, log or reference of another kind of axis than the plant's (mm against deg).

    Parameters
    ----------
    source : str or path-like
        What the message names: the file of the model or log.
    motion : str
        Its kind of axis: ``"linear"`` (mm) or ``"rotary"`` (deg).
    plant : TwinPlant or ModelPlant
        The plant of the loop.

    Raises
    ------
    GreyboxError
        If ``motion`` is not the plant's.
    """
    if motion != plant.motion:
        raise GreyboxError(f"{source}: a {motion} axis, the plant {plant.name} is a {plant.motion} one; feed-forward "
                           "models, training logs and references must be of the plant's kind of axis")


def feedforward_models(plant, *, model_files: Sequence[str | PathLike] = (), kinds: Sequence[str] = (),
                       build: Callable[[str], object] | None = None, train_runs: Sequence[AxisLog] | None = None,
                       seed: int = 0, train_duration_s: float = 60.0,
                       progress: Callable[[str], None] | None = None) -> dict:
    """The feed-forward models of a compensation study by name: loaded from files and fitted by kind.

    Parameters
    ----------
    plant : TwinPlant or ModelPlant
        The plant of the loop; every model must be of its kind of axis.
    model_files : sequence of str or path-like, default ()
        Model files (``.gbm``) to load.
    kinds : sequence of str, default ()
        Model kinds to fit (:data:`greybox.models.registry.MODEL_CLASSES`), each once.
    build : callable, optional
        ``build(kind)`` returns an unfitted model of that kind (with the caller's hyperparameters);
        required with ``kinds``.
    train_runs : sequence of AxisLog, optional
        Prepared training runs of the ``kinds``; without them, a twin plant's synthetic datasets A and P
        (:func:`twin_training_runs`).
    seed : int, default 0
        Seed of the synthetic training data.
    train_duration_s : float, default 60.0
        Length [s] of each synthetic training dataset.
    progress : callable, optional
        Called with a line of text as the work advances.

    Returns
    -------
    dict
        ``{name: fitted model}``: named by kind, or ``"kind (origin)"`` (the file's stem, or ``fitted``) when
        two models are of one kind.

    Raises
    ------
    GreyboxError
        If there is no model, a model or training run is of another kind of axis than the plant, a
        model plant has no training runs, or two models end up with one name.
    ModelFileError
        If a model file does not load (the message names it).
    """
    say = progress or (lambda text: None)
    entries = []
    for path in model_files:
        model = load_model(path)
        check_axis_kind(path, model.units_.name, plant)
        entries.append((model_kind(model), Path(path).stem, model))
    kinds = list(dict.fromkeys(kinds))
    if kinds:
        if build is None:
            raise GreyboxError("fitting models by kind needs build(kind), a builder of unfitted models")
        if train_runs is not None:
            for run in train_runs:
                check_axis_kind(run.source or "training log", run.motion, plant)
            runs = list(train_runs)
        else:
            if not synthesises_training(plant):
                raise GreyboxError("feed-forward models for a model plant need training logs")
            say(f"synthesising training data: axis {plant.axis}, datasets A and P, {train_duration_s:g} s each, "
                f"seed {seed}")
            runs = twin_training_runs(plant, seed=seed, duration_s=train_duration_s)
        for kind in kinds:
            started = time.perf_counter()
            model = train_logs(build(kind), runs, intervals="none")
            say(f"fitted {kind} on {len(runs)} run(s) in {time.perf_counter() - started:.1f} s")
            entries.append((kind, "fitted", model))
    if not entries:
        raise GreyboxError("no feed-forward model: give model files or model kinds to fit")
    counts = {}
    for kind, _, _ in entries:
        counts[kind] = counts.get(kind, 0) + 1
    models = {}
    for kind, origin, model in entries:
        name = kind if counts[kind] == 1 else f"{kind} ({origin})"
        if name in models:
            raise GreyboxError(f"two feed-forward models are both named {name!r}; give distinct file names")
        models[name] = model
    return models


def _feedforwards(plant, models: Mapping[str, object], inertia) -> list:
    if isinstance(inertia, str):
        choice = inertia.strip().lower()
        if choice not in ("plant", "model"):
            raise GreyboxError(f"inertia must be 'plant', 'model' or a number [A s^2/mm], got {inertia!r}")
        inertia = plant.inertia_A_s2_mm if choice == "plant" else None
    baseline = InertiaFeedForward(plant.inertia_A_s2_mm if inertia is None else inertia)
    return [baseline] + [ModelFeedForward(model, inertia, name) for name, model in models.items()]


def _reference_step(models: Mapping[str, object], reference_step_s: float | None) -> float:
    if reference_step_s is not None:
        return reference_step_s
    steps = {round(float(model.sample_time_), 12) for model in models.values()}
    return steps.pop() if len(steps) == 1 else DEFAULT_REFERENCE_STEP_S


def _references(plant, references, *, step: float, duration_s: float, seed: int, start_mm: float | None
                ) -> list[Reference]:
    if start_mm is None:
        start_mm = axis_geometry(plant.axis).window_centre_mm if isinstance(plant, TwinPlant) and plant.axis else 0.0
    out = []
    for reference in references:
        if isinstance(reference, Reference):
            out.append(reference)
        elif isinstance(reference, AxisLog):
            out.append(reference_from_log(reference))
        elif reference in STROKES_MM:
            out.append(stroke_reference(reference, duration_s, seed, sample_time_s=step, start_mm=start_mm))
        else:
            raise GreyboxError(f"unknown reference {reference!r}: low, high, a Reference or a log")
    names = [reference.name for reference in out]
    if len(set(names)) != len(names):
        raise GreyboxError(f"references with the same name: {', '.join(names)}")
    return out


def compensation_study(plant, models: Mapping[str, object], *, references: Sequence = ("low", "high"),
                       duration_s: float = 60.0, seed: int = 0, start_mm: float | None = None,
                       reference_step_s: float | None = None, inertia="plant", bandwidth_hz: float | None = None,
                       controller_period_s: float | None = None, current_limit_A: float = 10.0,
                       resolution_mm: float = 1e-4, disturbance_std_A: float = 0.0,
                       progress: Callable[[str], None] | None = None) -> CompensationResult:
    """Run the position loop around ``plant`` with the feed-forward of each model on each reference.

    Parameters
    ----------
    plant : TwinPlant or ModelPlant
        The plant of the loop.
    models : mapping of str to CurrentModel
        Fitted feed-forward models by name; an inertia-only feed-forward is added as the baseline.
    references : sequence, default ("low", "high")
        ``"low"``/``"high"`` (filtered random references of :data:`~greybox.control.references.STROKES_MM`),
        :class:`Reference` objects or prepared logs whose position is the reference.
    duration_s : float, default 60.0
        Length of the generated references [s].
    seed : int, default 0
        Seed of the generated references and of the disturbance.
    start_mm : float, optional
        Start of the generated references [mm]; the middle of the twin's
        measurement window, or 0 for a model plant.
    reference_step_s : float, optional
        Step of the generated references [s]; default the models' common
        sample time, else :data:`DEFAULT_REFERENCE_STEP_S`.
    inertia : {"plant", "model"} or float, default "plant"
        Inertia of the feed-forwards: the plant's for every one, each model's
        own, or a value [A s^2/mm].
    bandwidth_hz : float, optional
        Closed-loop bandwidth of the PID pole placement [Hz].
    controller_period_s : float, optional
        Controller period [s], a divisor of the reference step (default at most 0.25 ms).
    current_limit_A, resolution_mm : float
        Motor current saturation [A] and encoder resolution [mm].
    disturbance_std_A : float, default 0.0
        Standard deviation of an AR(1) disturbance current [A]; none if 0.
    progress : callable, optional
        Receives one line of text per stage.

    Returns
    -------
    CompensationResult
    """
    if not disturbance_std_A >= 0.0:
        raise GreyboxError(f"disturbance standard deviation must be non-negative, got {disturbance_std_A} A")
    say = progress or (lambda text: None)
    feedforwards = _feedforwards(plant, models, inertia)
    runs = _references(plant, references, step=_reference_step(models, reference_step_s), duration_s=duration_s,
                       seed=seed, start_mm=start_mm)
    step = runs[0].sample_time
    period = step / controller_periods(step, controller_period_s)
    bandwidth = bandwidth_hz if bandwidth_hz is not None else default_bandwidth_hz(period)
    gains = pole_placement_gains(plant.inertia_A_s2_mm, bandwidth)
    say(f"plant {plant.name}, controller period {period * 1e3:g} ms, bandwidth {bandwidth:.3g} Hz: "
        f"kp = {gains.kp:.4g} A/mm, ki = {gains.ki:.4g} A/(mm s), kd = {gains.kd:.4g} A s/mm")
    disturbance = CurrentNoise(disturbance_std_A) if disturbance_std_A > 0 else None
    results = compare_feedforwards(plant, runs, feedforwards, gains, controller_period_s=controller_period_s,
                                   current_limit_A=current_limit_A, resolution_mm=resolution_mm,
                                   disturbance=disturbance, seed=seed)
    settings = {
        "plant": plant.describe(),
        "feedforwards": [ff.describe() for ff in feedforwards],
        "references": [{"name": r.name, "duration_s": r.duration, "step_s": r.sample_time, **r.attrs} for r in runs],
        "bandwidth_hz": bandwidth,
    }
    return CompensationResult(results, gains, period, bandwidth, settings)
