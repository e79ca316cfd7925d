"""The ARTS friction benchmark: greybox's friction models on a real dry-friction device with backlash.

Data: the harmonic tests of the ARTS-Lab friction device (D. Coble,
"Physics-Informed Machine Learning for Dry Friction and Backlash Modeling in
Structural Control Systems", ARTS-Lab, 2024; CC BY-SA 4.0; cite it when using
the data): ``test0.npy`` ... ``test12.npy``, 1024 Hz, displacement [mm],
velocity [mm/s] and measured friction force [N] as read by
:func:`studies.arts_data.read_arts`. Amplitudes about 19 mm (test0-4), 39 mm
(test5-8) and 59 mm (test9-12); at each amplitude the tests run at 0.1, 0.25,
0.5, 1 and 2 Hz (the 39 and 59 mm series without 2 Hz), seven periods each
under a tapered envelope (two periods rising, three at full amplitude, two
falling).

Protocol:

1. the recorded position and velocity are kept, the acceleration is zero:
   the force is measured on the device, so the models fit no inertia (see
   :func:`benchmark_log`); no sample is dropped (every file starts at rest);
2. split by excitation: every model is fitted on :data:`TRAIN_FILES`, the
   0.25 Hz test of each amplitude, and scored on :data:`TEST_FILES`, the
   other frequencies (0.1 Hz below the training speed, 0.5-2 Hz above);
3. each model is simulated from rest over each whole file at 1024 Hz; the
   figures of merit, on all samples of a role pooled (and per file), are
   ``RE = 100 RMSE / mean|F|`` (:func:`greybox.metrics.relative_error`) and
   the EMPS benchmark's ``relerr = 100 ||F - F_hat|| / ||F||``
   (:func:`greybox.metrics.relerr`), without the EMPS decimation.

Every kind of model runs symmetric and asymmetric (:data:`MODELS`). The
symmetric ones fit a constant offset: the device has no gravity load, but its
sliding levels differ between the directions (about 14 kN in positive and
20 kN in negative motion), and an offset is the only term by which a symmetric model can shift
its two levels; the asymmetric ones have a level per direction and take no
offset (it would not be identifiable). :func:`arts_benchmark` runs the whole
protocol and writes its files; ``scripts/arts_benchmark.py`` is its command::

    python scripts/arts_benchmark.py --json arts.json --markdown arts.md --plot arts.png
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

from greybox.atomic import check_output_path, write_text_atomic
from greybox.data.log import AxisLog
from greybox.errors import GreyboxError
from greybox.evaluate.plots import import_pyplot, save_figure
from greybox.metrics import metrics_table
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.provenance import provenance, provenance_line
from studies.arts_data import read_arts
from studies.auto import HeldOutChoice
from studies.emps import learned_parameters

__all__ = ["TRAIN_FILES", "TEST_FILES", "FAST_FILES", "PLOT_FILES", "MODELS", "MODEL_NAMES", "benchmark_log",
           "run_benchmark", "band_split", "markdown_table", "plot_loops", "arts_benchmark"]

#: Training files: the 0.25 Hz test of each amplitude (19, 39, 59 mm).
TRAIN_FILES = ("test1.npy", "test6.npy", "test10.npy")
#: Test files: every other excitation (0.1, 0.5, 1 and 2 Hz at each amplitude).
TEST_FILES = ("test0.npy", "test2.npy", "test3.npy", "test4.npy", "test5.npy", "test7.npy", "test8.npy",
              "test9.npy", "test11.npy", "test12.npy")
#: Test files of the speed split: the 1 and 2 Hz tests, at 1.4-3 times the fastest training speed.
FAST_FILES = ("test3.npy", "test4.npy", "test8.npy", "test12.npy")
#: Test files drawn in the figure: the 0.5 Hz test of each amplitude.
PLOT_FILES = ("test2.npy", "test7.npy", "test11.npy")
#: Band of the motion [Hz]: ten times the fastest excitation (2 Hz). The measured force above it (the
#: ripple of sliding, most of its power at 40-60 Hz) is not a response to the motion a model is given.
MOTION_BAND_HZ = 20.0


#: Models: name -> (constructor taking the seed, description). Symmetric ones fit an offset, asymmetric ones cannot.
MODELS = {
    "coulomb": (lambda seed: CoulombModel(fit_offset=True), "Coulomb + viscous + offset"),
    "coulomb_asym": (lambda seed: CoulombModel(asymmetric=True), "Coulomb + viscous per direction"),
    "stribeck": (lambda seed: StribeckModel(fit_offset=True), "Stribeck + viscous + offset"),
    "stribeck_asym": (lambda seed: StribeckModel(asymmetric=True), "Stribeck + viscous per direction"),
    "lugre": (lambda seed: LuGreModel(fit_offset=True, random_state=seed), "LuGre + offset"),
    "lugre_asym": (lambda seed: LuGreModel(asymmetric=True, random_state=seed), "LuGre per direction"),
    "gms": (lambda seed: GMSModel(fit_offset=True, random_state=seed), "GMS, N = 4, + offset"),
    "gms_asym": (lambda seed: GMSModel(asymmetric=True, random_state=seed), "GMS, N = 4, per direction"),
    "gms_backlash": (lambda seed: BacklashModel(base=GMSModel(fit_offset=True, random_state=seed)),
                     "GMS, N = 4, + offset, behind an identified backlash"),
    "gms_asym_backlash": (lambda seed: BacklashModel(base=GMSModel(asymmetric=True, random_state=seed)),
                          "GMS, N = 4, per direction, behind an identified backlash"),
    "auto": (HeldOutChoice, "chosen by `greybox train --model auto` (each training file held out in turn)"),
}
MODEL_NAMES = tuple(MODELS)


def benchmark_log(path: str | os.PathLike) -> AxisLog:
    """Read an ARTS file for the protocol (step 1): the recorded motion, and no acceleration.

    The force is the friction force measured on the device itself, so the
    models are given no acceleration and fit no inertia (their ``J a`` term
    is zero). Fitted on one excitation frequency, an inertia is not a mass but
    a stand-in for a term proportional to ``-x`` (for a sine ``a = -w^2 x``),
    which grows with the frequency squared on the faster tests: the protocol
    of the first results had it, with ``J`` of 3.7 t for GMS.

    Parameters
    ----------
    path : path-like
        One of the ``test<k>.npy`` files.

    Returns
    -------
    AxisLog
        Position [mm], recorded velocity [mm/s], zero acceleration, force [N]; all samples.
    """
    log = read_arts(path)
    return log.replace(acceleration=np.zeros(len(log)))


def _check_split(names, train, test) -> None:
    """Raise :class:`GreyboxError` for an unknown model name or a split that is empty or not disjoint."""
    unknown = [name for name in names if name not in MODELS]
    if unknown:
        raise GreyboxError(f"unknown model(s) {', '.join(unknown)}; known: {', '.join(MODEL_NAMES)}")
    if not names:
        raise GreyboxError("no model to run")
    if not train or not test:
        raise GreyboxError("the split needs at least one training file and one test file")
    shared = sorted(set(train) & set(test))
    if shared:
        raise GreyboxError(f"{', '.join(shared)}: both a training and a test file; the split must be disjoint")


def _file_info(log: AxisLog, role: str) -> dict:
    """Role, length and excitation of one prepared file, JSON-ready."""
    return {
        "role": role,
        "samples": len(log),
        "amplitude_mm": float(np.ptp(log.position) / 2.0),
        "peak_speed_mm_s": float(np.max(np.abs(log.velocity))),
        "mean_abs_force_N": float(np.mean(np.abs(log.effort))),
    }


# ---------------------------------------------------------------- bands
def _above_band(signal: np.ndarray, sample_time: float) -> np.ndarray:
    """The part of a signal above :data:`MOTION_BAND_HZ`: the signal less its zero-phase low-pass.

    The low-pass is a 4th-order Butterworth run forward and backward
    (``scipy.signal.sosfiltfilt``), so it neither delays nor scales the band of the motion.
    """
    sos = butter(4, MOTION_BAND_HZ, fs=1.0 / sample_time, output="sos")
    return signal - sosfiltfilt(sos, signal)


def band_split(logs, predictions) -> dict[str, float]:
    """How much of a model's error lies in the band of the motion, and how much no model of it could predict.

    Each file is split on its own (the filter does not run across files),
    then the samples are pooled. With ``e = F - F_hat`` and ``mean|F|`` over
    the pooled samples:

    - ``re_band``: ``100 RMS(e below the band) / mean|F|`` [%], the error of
      the model in the band of the motion;
    - ``re_above``: the same for ``e`` above the band [%]; the two add in
      quadrature to the role's RE (the bands are orthogonal up to the
      filter's edge);
    - ``floor``: ``100 RMS(F above the band) / mean|F|`` [%], the RE of a
      model that got the band of the motion exactly right and nothing above:
      the measured ripple sets this floor.

    Parameters
    ----------
    logs : sequence of AxisLog
        Measured files (force [N], uniform time step [s]).
    predictions : sequence of ndarray
        Modelled force of each file [N].

    Returns
    -------
    dict
        ``{"band_hz", "re_band", "re_above", "floor"}``, JSON-ready.
    """
    above_error, above_force, forces = [], [], []
    for log, prediction in zip(logs, predictions, strict=True):
        step = float(np.median(np.diff(log.time)))
        above_error.append(_above_band(log.effort - prediction, step))
        above_force.append(_above_band(log.effort, step))
        forces.append(log.effort)
    force = np.concatenate(forces)
    error = force - np.concatenate(predictions)
    above = np.concatenate(above_error)
    scale = 100.0 / float(np.mean(np.abs(force)))
    return {
        "band_hz": MOTION_BAND_HZ,
        "re_band": scale * float(np.sqrt(np.mean((error - above) ** 2))),
        "re_above": scale * float(np.sqrt(np.mean(above ** 2))),
        "floor": scale * float(np.sqrt(np.mean(np.concatenate(above_force) ** 2))),
    }


# ---------------------------------------------------------------- running
def run_benchmark(data: Path, names=MODEL_NAMES, seed: int = 0, progress=None, *, train=TRAIN_FILES,
                  test=TEST_FILES) -> tuple[dict, dict]:
    """Fit every named model on the training files and score it on every file.

    Parameters
    ----------
    data : Path
        Folder holding the ARTS files.
    names : sequence of str, default :data:`MODEL_NAMES`
        Models to run, in this order. All are constructed before the first
        fit, so a model whose constructor fails stops the run at once.
    seed : int, default 0
        Seed of the multi-start identifications.
    progress : None, bool or callable, optional
        Progress of every fit (see :meth:`greybox.models.estimator.CurrentModel.fit`).
    train, test : sequence of str, default :data:`TRAIN_FILES`, :data:`TEST_FILES`
        File names of the split (disjoint); smaller subsets give a quick run.

    Returns
    -------
    results : dict
        The JSON document: ``{"models": {name: {...}}, "files": ..., "protocol": ...}``.
    curves : dict
        Per file: time [s], position [mm], measured and modelled force [N], for the figure.

    Raises
    ------
    GreyboxError
        For an unknown model name, an empty or overlapping split, or a missing file.
    """
    names, train, test = list(names), list(train), list(test)
    _check_split(names, train, test)
    roles = {**{name: "train" for name in train}, **{name: "test" for name in test}}
    for name in roles:
        if not (data / name).is_file():
            raise GreyboxError(f"{data / name}: ARTS data file not found (give the folder with --data)")
    models = {name: MODELS[name][0](seed) for name in names}
    logs = {name: benchmark_log(data / name) for name in roles}
    curves = {name: {"time_s": log.time, "position_mm": log.position, "measured_N": log.effort, "models": {}}
              for name, log in logs.items()}
    results = {}
    for name, model in models.items():
        started = time.perf_counter()
        model = model.fit([logs[file] for file in train], progress=progress)  # auto: the model it chose
        predictions = {file: model.predict(log) for file, log in logs.items()}
        values, units = learned_parameters(model)
        settings = model.get_params(deep=True)  # a model behind a backlash has its settings under base__
        entry = {"description": MODELS[name][1],
                 "fit_offset": bool(settings.get("fit_offset", settings.get("base__fit_offset")))}
        if getattr(model, "selection_", None) is not None:
            entry["selection"] = model.selection_
        fast = [file for file in test if file in FAST_FILES]
        for role, files in (("train", train), ("test", test), ("fast", fast)):
            if files:
                entry[role] = metrics_table(np.concatenate([logs[file].effort for file in files]),
                                            np.concatenate([predictions[file] for file in files]))
                entry[role]["bands"] = band_split([logs[file] for file in files],
                                                  [predictions[file] for file in files])
        entry["files"] = {file: {**metrics_table(logs[file].effort, prediction),
                                 "bands": band_split([logs[file]], [prediction])}
                          for file, prediction in predictions.items()}
        entry.update(params=values, units=units, n_params=int(model.n_params),
                     seconds=round(time.perf_counter() - started, 2))
        results[name] = entry
        for file, prediction in predictions.items():
            curves[file]["models"][name] = prediction
    document = {
        "models": results,
        "files": {file: _file_info(log, roles[file]) for file, log in logs.items()},
        "protocol": {
            "data": str(data),
            "train": train,
            "test": test,
            "fast": [file for file in test if file in FAST_FILES],
            "velocity": "recorded v, in mm/s",
            "acceleration": "zero: the force is measured on the device, no inertia is fitted",
            "simulation": "from rest over each whole file at its 1024 Hz samples",
            "offset": "fitted by the symmetric models, not by the asymmetric ones",
            "re": "100 * RMSE / mean(|F|) over the pooled samples of the role [%]",
            "relerr": "100 * ||F - F_hat|| / ||F|| over the pooled samples of the role [%], not decimated",
            "metrics": "per role and per file: n, rmse [N], re [%], nmse [%], relerr [%], max_error [N]",
            "bands": (f"per role and per file: re_band and re_above, the RE of the error below and above "
                      f"{MOTION_BAND_HZ:g} Hz (zero-phase 4th-order Butterworth per file), and floor, the RE of "
                      f"the measured force above it [%]"),
            "seed": seed,
        },
    }
    return document, curves


# ---------------------------------------------------------------- outputs
def markdown_table(results: dict) -> str:
    """Markdown summary: RE and relerr per model on the pooled roles, the RE in the band of the motion, RE per file.

    Parameters
    ----------
    results : dict
        The document returned first by :func:`run_benchmark` (``"models"`` and ``"files"`` are read).
    """
    models = results["models"]
    lines = [
        "| model | what | parameters | train RE % | test RE % | 1-2 Hz test RE % | train relerr % | test relerr % |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, entry in models.items():
        fast = f"{entry['fast']['re']:.2f}" if "fast" in entry else "-"
        what = entry["description"] + (f": {entry['selection']['chosen']}" if "selection" in entry else "")
        lines.append(f"| `{name}` | {what} | {entry['n_params']} | {entry['train']['re']:.2f} | "
                     f"{entry['test']['re']:.2f} | {fast} | {entry['train']['relerr']:.2f} | "
                     f"{entry['test']['relerr']:.2f} |")
    first = next(iter(models.values()))  # the floor is the measured force's: every model's entry has the same
    roles = [role for role in ("train", "test", "fast") if role in first]
    titles = {"train": "train", "test": "test", "fast": "1-2 Hz test"}
    band = first["train"]["bands"]["band_hz"]
    lines += ["", f"RE % in the band of the motion (the error below {band:g} Hz), and the floor that the force above "
              f"it sets for any model of the motion:", "",
              "| model | " + " | ".join(f"{titles[role]} RE % below {band:g} Hz" for role in roles) + " |",
              "|---|" + "---|" * len(roles)]
    for name, entry in models.items():
        lines.append(f"| `{name}` | " + " | ".join(f"{entry[role]['bands']['re_band']:.2f}" for role in roles) + " |")
    lines.append("| floor: the measured force above the band | "
                 + " | ".join(f"{first[role]['bands']['floor']:.2f}" for role in roles) + " |")
    lines += ["", "RE % per file:", "",
              "| file | role | amplitude mm | peak speed mm/s | floor | " + " | ".join(f"`{name}`" for name in models)
              + " |",
              "|---|---|---|---|---|" + "---|" * len(models)]
    for file, info in results["files"].items():
        scores = " | ".join(f"{entry['files'][file]['re']:.1f}" for entry in models.values())
        lines.append(f"| {file} | {info['role']} | {info['amplitude_mm']:.1f} | {info['peak_speed_mm_s']:.0f} | "
                     f"{first['files'][file]['bands']['floor']:.1f} | {scores} |")
    return "\n".join(lines) + "\n"


def plot_loops(curves: dict, names, path: Path) -> None:
    """Force against displacement (top) and time (bottom), measured and modelled, on :data:`PLOT_FILES`.

    One column per plotted test file (one per amplitude), all samples of the
    file; the models Stribeck, LuGre, asymmetric GMS and the two GMS behind a backlash, those of them
    that ran (else the first four run).

    Parameters
    ----------
    curves : dict
        Per file: time [s], position [mm], measured and modelled force [N], as returned by :func:`run_benchmark`.
    names : sequence of str
        Models that ran; those drawn are picked from them.
    path : Path
        Image file to write; the format follows its extension.
    """
    plt = import_pyplot(path)
    preferred = ("stribeck", "lugre", "gms_asym", "gms_backlash", "gms_asym_backlash")
    shown = [n for n in preferred if n in names] or list(names)[:4]
    files = [file for file in PLOT_FILES if file in curves] or list(curves)[-3:]
    fig, axes = plt.subplots(2, len(files), figsize=(6 * len(files), 10), constrained_layout=True, squeeze=False)
    for column, file in enumerate(files):
        curve = curves[file]
        for ax, abscissa, label in ((axes[0, column], curve["position_mm"], "displacement [mm]"),
                                    (axes[1, column], curve["time_s"], "time [s]")):
            ax.plot(abscissa, 1e-3 * curve["measured_N"], color="black", lw=1.0, label="measured")
            for name in shown:
                ax.plot(abscissa, 1e-3 * curve["models"][name], lw=0.8, label=name)
            ax.set(title=file, xlabel=label, ylabel="force [kN]")
            ax.legend(loc="lower right", fontsize=8)
            ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=110)


def arts_benchmark(data: str | os.PathLike, json_path: str | os.PathLike, *, markdown_path=None, plot_path=None,
                   names=MODEL_NAMES, seed: int = 0, progress=None, force: bool = False, train=TRAIN_FILES,
                   test=TEST_FILES) -> str:
    """Run the protocol and write its files: the JSON results, optionally the Markdown tables and the figure.

    Parameters
    ----------
    data : path-like
        Folder holding the ARTS files.
    json_path : path-like
        JSON results (:func:`run_benchmark`'s document and the provenance).
    markdown_path : path-like, optional
        :func:`markdown_table`, with the provenance line.
    plot_path : path-like, optional
        PNG of :func:`plot_loops`.
    names : sequence of str, default :data:`MODEL_NAMES`
        Models to run, in this order.
    seed : int, default 0
        Seed of the multi-start identifications.
    progress : None, bool or callable, optional
        Progress of every fit (see :meth:`greybox.models.estimator.CurrentModel.fit`).
    force : bool, default False
        Overwrite existing output files (never the data files).
    train, test : sequence of str, default :data:`TRAIN_FILES`, :data:`TEST_FILES`
        File names of the split.

    Returns
    -------
    str
        The Markdown tables.

    Raises
    ------
    GreyboxError
        If the directory of an output file or a data file does not exist, an
        output is one of the data files, an output exists and ``force`` is
        false (nothing is written then), or for a bad model name or split.
    """
    inputs = [Path(data) / name for name in (*train, *test)]
    for out in (json_path, markdown_path, plot_path):
        if out is not None:
            check_output_path(out, overwrite=force, protect=inputs, inputs_name="one of the ARTS data files")
    results, curves = run_benchmark(Path(data), names, seed, progress=progress, train=train, test=test)
    machine = provenance()
    write_text_atomic(json_path, json.dumps({**results, "provenance": machine}, indent=2) + "\n")
    table = markdown_table(results)
    if markdown_path is not None:
        write_text_atomic(markdown_path, f"{table}\nMeasured with {provenance_line(machine)}.\n")
    if plot_path is not None:
        plot_loops(curves, list(results["models"]), plot_path)
    return table
