"""The EMPS benchmark: greybox's friction models on a real ball-screw drive.

Data: the Electro-Mechanical Positioning System benchmark of Janot, Gautier and
Brunot (2019, nonlinearbenchmark.org; cite it when using the data):
``DATA_EMPS.mat`` (training) and ``DATA_EMPS_PULSES.mat`` (cross-test), 1 kHz,
position [mm] and load-side force ``gtau * vir`` [N] as read by
:func:`greybox.data.io.read_log`.

Protocol (the benchmark's own, ``Script_IDIM_LS.m``):

1. the position is low-pass filtered (4th-order Butterworth at 100 Hz, run
   forward and backward) and differentiated twice by central differences
   (:func:`greybox.data.prepare.derive` with ``cutoff_hz=100``);
2. the first 49 samples are dropped (edge effects);
3. the figure of merit is ``relerr = 100 ||y - y_hat|| / ||y||`` on the
   force *decimated by 10* with a zero-phase IIR anti-alias filter
   (:func:`scipy.signal.decimate`, ``ftype="iir"``, ``zero_phase=True``; 2480
   samples at 10 ms), the same operator applied to the modelled force.

``coulomb_idim_ls`` and ``coulomb_asym_idim_ls`` are the benchmark's IDIM-LS
estimators exactly: least squares on the decimated columns of the observation
matrix ``[ddq, dq, sign(dq), 1]`` (parallel decimation). All other entries are
greybox models fitted by their own ``fit`` on the 1 kHz benchmark log of step
1-2 (no decimation in the fit), simulated at 1 kHz over the whole run from
rest, and scored through step 3 on exactly the benchmark's samples. Since the
decimation is linear, this scoring equals the benchmark's for the linear
models. The symmetric greybox models fit a constant offset, as the benchmark's
model does; the asymmetric ones (``*_asym``: a sliding curve and a viscous
coefficient per direction of motion) take none, as the benchmark's asymmetric
model (its two Coulomb levels absorb the offset). ``gms_2ms`` uses every
second raw sample (2 ms, greybox's usual step), prepared the same way at 2 ms;
its prediction is interpolated linearly onto the 1 kHz time base before step 3.

The learned parameters of the greybox models are their parameter tables
(:meth:`greybox.base.ModelProtocol.parameter_table`: values in greybox units,
N and mm, with the unit of each). :func:`emps_benchmark` runs the whole
protocol and writes its files; ``scripts/emps_benchmark.py`` is its command::

    python scripts/emps_benchmark.py --json emps.json --markdown emps.md --plot emps.png
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
from scipy.signal import decimate

from greybox.atomic import check_output_path, write_text_atomic
from greybox.data.io import read_log
from greybox.data.log import AxisLog
from greybox.data.prepare import derive, trim
from greybox.errors import GreyboxError
from greybox.evaluate.plots import import_pyplot, save_figure
from greybox.metrics import relerr
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.provenance import provenance, provenance_line
from studies.auto import HeldOutChoice

__all__ = ["TRAIN_FILE", "TEST_FILE", "PUBLISHED", "GREYBOX_MODELS", "IDIM_LS_MODELS", "MODEL_NAMES",
           "benchmark_log", "decimate_benchmark", "benchmark_relerr", "idim_ls", "learned_parameters",
           "run_benchmark", "markdown_table", "plot_curves", "emps_benchmark"]

TRAIN_FILE = "DATA_EMPS.mat"
TEST_FILE = "DATA_EMPS_PULSES.mat"

CUTOFF_HZ = 100.0  # Butterworth cut-off of the benchmark [Hz]
FILTER_ORDER = 4
BORDER = 49  # samples dropped at the start
DECIMATION = 10

#: Published IDIM-LS results (Janot, Gautier & Brunot 2019), SI units.
PUBLISHED = {
    "coulomb_idim_ls": {
        "params": {"M_kg": 95.1089, "Fv_N_s_per_m": 203.5034, "Fc_N": 20.3935, "offset_N": -3.1648},
        "train_relerr": 4.0834,
        "test_relerr": 5.9824,
    },
    "coulomb_asym_idim_ls": {
        "params": {
            "M_kg": 95.1540,
            "Fv_pos_N_s_per_m": 166.7061,
            "Fc_pos_N": 20.1440,
            "Fv_neg_N_s_per_m": 240.4236,
            "Fc_neg_N": 20.6277,
        },
        "train_relerr": 3.1117,
        "test_relerr": None,
    },
}

#: greybox models: name -> (constructor taking the seed, sample step [ms], description).
GREYBOX_MODELS = {
    "coulomb": (lambda seed: CoulombModel(fit_offset=True), 1, "Coulomb + viscous + offset, greybox fit"),
    "coulomb_asym": (lambda seed: CoulombModel(asymmetric=True), 1, "asymmetric Coulomb + viscous, greybox fit"),
    "stribeck": (lambda seed: StribeckModel(fit_offset=True), 1, "Stribeck + viscous + offset"),
    "stribeck_asym": (lambda seed: StribeckModel(asymmetric=True), 1, "asymmetric Stribeck + viscous"),
    "lugre": (lambda seed: LuGreModel(fit_offset=True, random_state=seed), 1, "LuGre + offset"),
    "lugre_asym": (lambda seed: LuGreModel(asymmetric=True, random_state=seed), 1, "asymmetric LuGre"),
    "gms": (lambda seed: GMSModel(fit_offset=True, random_state=seed), 1, "GMS, N = 4, + offset"),
    "gms_asym": (lambda seed: GMSModel(asymmetric=True, random_state=seed), 1, "asymmetric GMS, N = 4"),
    "gms_2ms": (lambda seed: GMSModel(fit_offset=True, random_state=seed), 2, "GMS, N = 4, + offset, 2 ms step"),
    "gms_asym_backlash": (lambda seed: BacklashModel(base=GMSModel(asymmetric=True, random_state=seed)), 1,
                          "asymmetric GMS, N = 4, behind an identified backlash"),
    "auto": (HeldOutChoice, 1, "chosen by `greybox train --model auto` (three stretches held out in turn)"),
}
IDIM_LS_MODELS = {
    "coulomb_idim_ls": (False, "benchmark IDIM-LS: Coulomb + viscous + offset"),
    "coulomb_asym_idim_ls": (True, "benchmark IDIM-LS, asymmetric friction"),
}
MODEL_NAMES = tuple(IDIM_LS_MODELS) + tuple(GREYBOX_MODELS)

# ---------------------------------------------------------------- protocol
def benchmark_log(path: str | os.PathLike, step_ms: int = 1) -> AxisLog:
    """Read an EMPS file and apply the benchmark's preprocessing (steps 1-2).

    Parameters
    ----------
    path : path-like
        ``DATA_EMPS.mat`` or ``DATA_EMPS_PULSES.mat``.
    step_ms : {1, 2}
        1: the file's 1 kHz samples. 2: every second raw sample (those on the
        benchmark's sample grid), filtered and differentiated at 2 ms.

    Returns
    -------
    AxisLog
        Position [mm], velocity [mm/s], acceleration [mm/s^2], force [N], from
        the 50th sample of the file on.
    """
    raw = read_log(path)
    start = raw.time[BORDER]
    if step_ms == 2:
        raw = raw.select(slice(BORDER % 2, None, 2))
    elif step_ms != 1:
        raise ValueError(f"step must be 1 or 2 ms, got {step_ms}")
    return trim(derive(raw, cutoff_hz=CUTOFF_HZ, order=FILTER_ORDER), start_s=start)


def decimate_benchmark(values: np.ndarray) -> np.ndarray:
    """The benchmark's decimation by 10: zero-phase Chebyshev-I IIR low-pass, every 10th sample.

    Parameters
    ----------
    values : array_like, shape (n,)
        Signal at 1 kHz (a force [N], a column of the observation matrix, the time [s], ...).
    """
    return decimate(np.asarray(values, dtype=float), DECIMATION, ftype="iir", zero_phase=True)


def benchmark_relerr(log: AxisLog, prediction: np.ndarray, times: np.ndarray | None = None) -> float:
    """relerr [%] of a modelled force on the benchmark's decimated samples of ``log``.

    Parameters
    ----------
    log : AxisLog
        Benchmark log at 1 kHz (:func:`benchmark_log` with ``step_ms=1``).
    prediction : ndarray
        Modelled force [N] at ``times``.
    times : ndarray, optional
        Sample times of ``prediction`` [s]; the log's own by default. Other
        time bases are interpolated linearly onto the log's.
    """
    if times is not None:
        prediction = np.interp(log.time, times, prediction)
    return relerr(decimate_benchmark(log.effort), decimate_benchmark(prediction))


def _observation_matrix(log: AxisLog, asymmetric: bool) -> tuple[np.ndarray, list[str]]:
    """IDIM observation matrix in SI units (positions in m) and its parameter names."""
    dq = log.velocity * 1e-3
    ddq = log.acceleration * 1e-3
    if not asymmetric:
        columns = [ddq, dq, np.sign(dq), np.ones_like(dq)]
        return np.column_stack(columns), ["M_kg", "Fv_N_s_per_m", "Fc_N", "offset_N"]
    positive, negative = (dq > 0).astype(float), (dq < 0).astype(float)
    columns = [ddq, dq * positive, positive, dq * negative, -negative]
    return np.column_stack(columns), ["M_kg", "Fv_pos_N_s_per_m", "Fc_pos_N", "Fv_neg_N_s_per_m", "Fc_neg_N"]


def idim_ls(log: AxisLog, asymmetric: bool = False) -> dict:
    """The benchmark's IDIM-LS estimate: least squares on the decimated observation matrix.

    Parameters
    ----------
    log : AxisLog
        Benchmark log at 1 kHz.
    asymmetric : bool, default False
        Direction-dependent Coulomb and viscous friction, no offset
        (``Script_IDIM_LS_Asym_Fric.m``); otherwise symmetric with offset.

    Returns
    -------
    dict
        ``params`` (SI units: kg, N s/m, N), ``relative_std`` of each estimate
        [%], ``condition_number`` of the decimated observation matrix,
        ``train_relerr`` [%], and ``predict``, a function of a benchmark log
        giving the modelled force [N] at its samples.
    """
    matrix, names = _observation_matrix(log, asymmetric)
    decimated = np.column_stack([decimate_benchmark(column) for column in matrix.T])
    target = decimate_benchmark(log.effort)
    theta = np.linalg.lstsq(decimated, target, rcond=None)[0]
    error = target - decimated @ theta
    std = np.std(error, ddof=1) * np.sqrt(np.diag(np.linalg.inv(decimated.T @ decimated)))
    return {
        "params": dict(zip(names, (float(v) for v in theta))),
        "relative_std": dict(zip(names, (float(v) for v in 100 * std / np.abs(theta)))),
        "condition_number": float(np.linalg.cond(decimated)),
        "train_relerr": relerr(target, decimated @ theta),
        "predict": lambda other: _observation_matrix(other, asymmetric)[0] @ theta,
    }


def _json_value(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    return value


def learned_parameters(model) -> tuple[dict, dict]:
    """The identified parameters of a fitted greybox model and their units, from its parameter table.

    Parameters
    ----------
    model : CurrentModel
        A fitted greybox model.

    Returns
    -------
    values : dict
        ``{name: value}``, JSON-ready (greybox units: N and mm for force logs).
    units : dict
        ``{name: unit}``.
    """
    table = model.parameter_table()
    return ({row.name: _json_value(row.value) for row in table}, {row.name: row.unit for row in table})


# ---------------------------------------------------------------- running
def run_benchmark(data: Path, names=MODEL_NAMES, seed: int = 0, progress=None) -> tuple[dict, dict]:
    """Fit every named model on the training file and score it on both files.

    Parameters
    ----------
    data : Path
        Folder holding :data:`TRAIN_FILE` and :data:`TEST_FILE`.
    names : sequence of str, default :data:`MODEL_NAMES`
        Models to run, in this order: keys of :data:`IDIM_LS_MODELS` or :data:`GREYBOX_MODELS`.
    seed : int, default 0
        Seed of the multi-start identifications.
    progress : None, bool or callable, optional
        Progress of every greybox fit (see :meth:`greybox.models.estimator.CurrentModel.fit`).

    Returns
    -------
    results : dict
        The JSON document: ``{"models": {name: {...}}, "published": ..., "protocol": ...}``.
    curves : dict
        Decimated time [s], measured and modelled force [N] per file, for the plot.

    Raises
    ------
    GreyboxError
        For an unknown model name, before any file is read, or for a missing data file.
    """
    unknown = [name for name in names if name not in IDIM_LS_MODELS and name not in GREYBOX_MODELS]
    if unknown:
        raise GreyboxError(f"unknown model(s) {', '.join(unknown)}; known: {', '.join(MODEL_NAMES)}")
    paths = {"train": data / TRAIN_FILE, "test": data / TEST_FILE}
    for path in paths.values():
        if not path.is_file():
            raise GreyboxError(f"{path}: EMPS data file not found (give the folder with --data)")
    logs = {step: {role: benchmark_log(path, step) for role, path in paths.items()} for step in (1, 2)}
    reference = logs[1]
    curves = {
        role: {
            "time_s": decimate_benchmark(log.time),
            "velocity_mm_s": decimate_benchmark(log.velocity),
            "measured_N": decimate_benchmark(log.effort),
            "models": {},
        }
        for role, log in reference.items()
    }
    models = {}
    for name in names:
        started = time.perf_counter()
        if name in IDIM_LS_MODELS:
            asymmetric, description = IDIM_LS_MODELS[name]
            fit = idim_ls(reference["train"], asymmetric)
            predictions = {role: (fit["predict"](log), None) for role, log in reference.items()}
            entry = {
                "description": description,
                "fitted_on": "decimated observation matrix (benchmark IDIM-LS)",
                "step_ms": 1,
                "params": fit["params"],
                "relative_std_percent": fit["relative_std"],
                "condition_number": fit["condition_number"],
            }
        else:
            factory, step, description = GREYBOX_MODELS[name]
            model = factory(seed).fit(logs[step]["train"], progress=progress)  # auto: the model it chose
            predictions = {role: (model.predict(log), log.time) for role, log in logs[step].items()}
            values, units = learned_parameters(model)
            entry = {
                "description": description,
                "fitted_on": f"benchmark log at {step} ms, {len(logs[step]['train'])} samples (greybox fit)",
                "step_ms": step,
                "params": values,
                "units": units,
                "n_params": int(model.n_params),
            }
            if getattr(model, "selection_", None) is not None:  # the entry auto: the table it chose from
                entry["selection"] = model.selection_
        for role, (prediction, times) in predictions.items():
            entry[f"{role}_relerr"] = benchmark_relerr(reference[role], prediction, times)
            on_grid = prediction if times is None else np.interp(reference[role].time, times, prediction)
            curves[role]["models"][name] = decimate_benchmark(on_grid)
        entry["seconds"] = round(time.perf_counter() - started, 2)
        models[name] = {"train_relerr": entry.pop("train_relerr"), "test_relerr": entry.pop("test_relerr"), **entry}
    results = {
        "models": models,
        "published": PUBLISHED,
        "protocol": {
            "data": {role: str(path) for role, path in paths.items()},
            "position_filter": f"Butterworth order {FILTER_ORDER}, {CUTOFF_HZ:g} Hz, forward-backward",
            "derivatives": "central differences",
            "dropped_samples": BORDER,
            "decimation": f"scipy.signal.decimate q={DECIMATION}, iir, zero_phase",
            "relerr": "100 * ||y - y_hat|| / ||y|| on the decimated force [%]",
            "seed": seed,
        },
    }
    return results, curves


# ---------------------------------------------------------------- outputs
def markdown_table(results: dict) -> str:
    """Markdown summary: relerr per model beside the published IDIM-LS, and the IDIM-LS parameters.

    Parameters
    ----------
    results : dict
        The document returned first by :func:`run_benchmark`.
    """
    published = results["published"]["coulomb_idim_ls"]
    lines = [
        "| model | what | step | train relerr % | cross-test relerr % |",
        "|---|---|---|---|---|",
        f"| published IDIM-LS (Janot et al. 2019) | Coulomb + viscous + offset | 1 ms | "
        f"{published['train_relerr']:.2f} | {published['test_relerr']:.2f} |",
        f"| published IDIM-LS, asymmetric | | 1 ms | "
        f"{results['published']['coulomb_asym_idim_ls']['train_relerr']:.2f} | - |",
    ]
    for name, entry in results["models"].items():
        what = entry["description"] + (f": {entry['selection']['chosen']}" if "selection" in entry else "")
        lines.append(
            f"| `{name}` | {what} | {entry['step_ms']} ms | "
            f"{entry['train_relerr']:.2f} | {entry['test_relerr']:.2f} |"
        )
    for name in ("coulomb_idim_ls", "coulomb_asym_idim_ls"):
        if name not in results["models"]:
            continue
        ours = results["models"][name]["params"]
        reference = results["published"][name]["params"]
        lines += ["", f"`{name}` parameters (SI):", "", "| parameter | ours | published | deviation % |",
                  "|---|---|---|---|"]
        for key, value in reference.items():
            deviation = 100 * (ours[key] - value) / abs(value)
            lines.append(f"| {key} | {ours[key]:.4f} | {value:.4f} | {deviation:+.2f} |")
    return "\n".join(lines) + "\n"


def plot_curves(curves: dict, names, path: Path) -> None:
    """Measured against modelled (decimated) force on the cross-test file, a zoom on a reversal, and the errors.

    Parameters
    ----------
    curves : dict
        Per file: decimated time [s], velocity [mm/s], measured and modelled force [N], as returned by
        :func:`run_benchmark`.
    names : sequence of str
        Models that ran; those drawn are picked from them.
    path : Path
        Image file to write; the format follows its extension.
    """
    plt = import_pyplot(path)
    shown = [n for n in ("coulomb_idim_ls", "stribeck", "lugre", "gms", "gms_asym") if n in names] or list(names)[:4]
    test = curves["test"]
    t = test["time_s"]
    moving = np.flatnonzero((t > 5.0) & (np.abs(test["velocity_mm_s"]) > 1.0))
    direction = np.sign(test["velocity_mm_s"][moving])
    reversal = t[moving[np.flatnonzero(direction[1:] != direction[:-1])[0]]] if moving.size > 1 else 5.0
    zoom = (t > reversal - 0.6) & (t < reversal + 0.6)
    fig, axes = plt.subplots(4, 1, figsize=(11, 13), constrained_layout=True)
    panels = [
        (axes[0], np.ones_like(t, dtype=bool), f"{TEST_FILE} (cross-test): force decimated to 10 ms"),
        (axes[1], zoom, f"{TEST_FILE}: zoom on the reversal at {reversal:.2f} s"),
    ]
    for ax, mask, title in panels:
        ax.plot(t[mask], test["measured_N"][mask], color="black", lw=1.4, label="measured")
        for name in shown:
            ax.plot(t[mask], test["models"][name][mask], lw=0.9, label=name)
        ax.set(title=title, ylabel="force [N]")
        ax.legend(loc="upper right", ncol=len(shown) + 1, fontsize=8)
        ax.grid(alpha=0.3)
    for ax, role, title in ((axes[2], "train", TRAIN_FILE), (axes[3], "test", TEST_FILE)):
        c = curves[role]
        for name in shown:
            ax.plot(c["time_s"], c["measured_N"] - c["models"][name], lw=0.7, label=name)
        ax.set(title=f"{title}: error", ylabel="measured - model [N]")
        ax.legend(loc="upper right", ncol=len(shown), fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    save_figure(fig, path, dpi=110)


def emps_benchmark(data: str | os.PathLike, json_path: str | os.PathLike, *, markdown_path=None, plot_path=None,
                   names=MODEL_NAMES, seed: int = 0, progress=None, force: bool = False) -> str:
    """Run the protocol and write its files: the JSON results, optionally the Markdown table and the figure.

    Parameters
    ----------
    data : path-like
        Folder holding :data:`TRAIN_FILE` and :data:`TEST_FILE`.
    json_path : path-like
        JSON results (:func:`run_benchmark`'s document).
    markdown_path : path-like, optional
        :func:`markdown_table`.
    plot_path : path-like, optional
        PNG of :func:`plot_curves`.
    names : sequence of str, default :data:`MODEL_NAMES`
        Models to run, in this order.
    seed : int, default 0
        Seed of the multi-start identifications.
    progress : None, bool or callable, optional
        Progress of every greybox fit (see :meth:`greybox.models.estimator.CurrentModel.fit`).
    force : bool, default False
        Overwrite existing output files (never the data files).

    Returns
    -------
    str
        The Markdown table.

    Raises
    ------
    GreyboxError
        If the directory of an output file or a data file does not exist, an
        output is one of the data files, or an output exists and ``force`` is
        false; nothing is written then.
    """
    inputs = [Path(data) / TRAIN_FILE, Path(data) / TEST_FILE]
    for out in (json_path, markdown_path, plot_path):
        if out is not None:
            check_output_path(out, overwrite=force, protect=inputs, inputs_name="one of the EMPS data files")
    results, curves = run_benchmark(Path(data), names, seed, progress=progress)
    machine = provenance()
    write_text_atomic(json_path, json.dumps({**results, "provenance": machine}, indent=2) + "\n")
    table = markdown_table(results)
    if markdown_path is not None:
        write_text_atomic(markdown_path, f"{table}\nMeasured with {provenance_line(machine)}.\n")
    if plot_path is not None:
        plot_curves(curves, names, plot_path)
    return table
