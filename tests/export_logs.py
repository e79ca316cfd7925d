"""Home-made logs shaped like controller exports, with a known injected cutting force (issue 31).

:func:`write_export_logs` writes, into a directory, what a user brings from a machine:

``aircut_1.csv``
    A servo trace as a controller exports it: lines of metadata before the header, German headers
    (``Zeit;Lageistwert;Stromistwert``) with a units row under them (``ms;mm;A``), semicolons and
    decimal commas, time in ms.
``aircut_2.csv``
    Commas, decimal points, bracketed units in the headers (``time [ms]``, ``position [mm]``,
    ``velocity [mm/min]``, ``current [A]``).
``cut.csv``
    The cutting log: ISO date-time stamps (``Zeitstempel``), ``Lageistwert [mm]``, ``Strom [A]``,
    semicolons and decimal commas, and the truth beside it (``truth_force [N]``: the injected force on
    the table, ``truth_process [A]``).
``torque_aircut.csv``, ``torque_cut.csv``
    The same motions as a drive's own trace of a linear axis: motor speed ``Drehzahl [1/min]`` and motor
    torque ``Drehmoment [Nm]`` instead of a current (``k_t`` times it, with the sensor's offset in Nm).
``axis.toml``
    The axis file: torque constant, screw lead, efficiencies (no gear ratio: a direct coupling).

Every current carries the same current-sensor offset (:data:`OFFSET_A`), as a real drive does (or a
vertical axis carrying its weight). The friction is Stribeck + viscous with a smooth sign, so a friction
model of the package can represent it: the logs test the intake and the defaults, not a model's reach.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: Sample time of the exports [s].
SAMPLE_TIME_S = 0.002
#: The current sensor's offset [A].
OFFSET_A = 0.08
#: Injected cutting force on the table [N] while the tool is in the workpiece (negative strokes).
CUT_FORCE_N = -400.0
#: Drive train of the axis file.
AXIS = {"torque_constant_Nm_per_A": 1.2, "screw_lead_mm": 10.0, "efficiency_driving": 0.9,
        "efficiency_backdriven": 0.85}
#: Truth of the friction current: Coulomb, static [A], Stribeck velocity [mm/s], viscous [A s/mm], inertia.
FRICTION = {"coulomb_A": 0.5, "static_A": 0.7, "stribeck_mm_s": 2.0, "viscous_A_s_mm": 0.01,
            "inertia_A_s2_mm": 2e-4}
#: Current noise [A rms].
NOISE_A = 0.02


def _strokes(feeds_mm_min, travel_mm: float = 60.0, pause_s: float = 0.3, ramp_s: float = 0.1):
    """Velocity [mm/s] of back-and-forth strokes over ``travel_mm`` at the given feeds, smooth ramps."""
    pieces = [np.zeros(int(pause_s / SAMPLE_TIME_S))]
    for feed in feeds_mm_min:
        speed = feed / 60.0
        for direction in (1.0, -1.0):
            ramp = np.sin(0.5 * np.pi * np.arange(int(ramp_s / SAMPLE_TIME_S)) / (ramp_s / SAMPLE_TIME_S)) ** 2
            cruise = max(travel_mm / speed - ramp_s, 0.0)
            pieces += [direction * speed * ramp, direction * speed * np.ones(int(cruise / SAMPLE_TIME_S)),
                       direction * speed * ramp[::-1], np.zeros(int(pause_s / SAMPLE_TIME_S))]
    return np.concatenate(pieces)


def _truth(velocity, rng, cutting: bool):
    """Time [s], position [mm], current [A] (with offset and noise), process current [A], force [N]."""
    n = velocity.shape[0]
    time = np.arange(n) * SAMPLE_TIME_S
    position = 50.0 + np.concatenate(([0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * SAMPLE_TIME_S)))
    acceleration = np.gradient(velocity, SAMPLE_TIME_S)
    f = FRICTION
    level = f["coulomb_A"] + (f["static_A"] - f["coulomb_A"]) * np.exp(-np.abs(velocity) / f["stribeck_mm_s"])
    friction = level * np.tanh(velocity / 0.05) + f["viscous_A_s_mm"] * velocity
    force = np.zeros(n)
    if cutting:  # in the workpiece (the middle of the travel) on the negative strokes, 5 mm entry ramps
        low, high = position.min() + 15.0, position.max() - 15.0
        engaged = np.clip(np.minimum(position - low, high - position) / 5.0, 0.0, 1.0)
        force = np.where(velocity < -1.0, CUT_FORCE_N * engaged, 0.0)
    lossless = AXIS["torque_constant_Nm_per_A"] * 2.0 * math.pi / (AXIS["screw_lead_mm"] * 1e-3)
    # the cut opposes the motion: the motor drives against it, F = eta_d K_0 I
    process = force / (AXIS["efficiency_driving"] * lossless)
    current = f["inertia_A_s2_mm"] * acceleration + friction + process + OFFSET_A + rng.normal(0, NOISE_A, n)
    return time, position, np.round(current, 4), process, force


def _decimal_comma(values, digits: int) -> list[str]:
    return [f"{value:.{digits}f}".replace(".", ",") for value in values]


def _write(path: Path, lines) -> None:
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_export_logs(directory, seed: int = 0) -> dict[str, Path]:
    """Write the export-like logs and the axis file into ``directory``.

    Parameters
    ----------
    directory : str or path-like
        Existing directory.
    seed : int, default 0
        Seed of the current noise.

    Returns
    -------
    dict of str to Path
        The files by their name without extension (``aircut_1``, ..., ``axis``).
    """
    directory = Path(directory)
    rng = np.random.default_rng(seed)
    paths = {name: directory / f"{name}.csv" for name in ("aircut_1", "aircut_2", "cut", "torque_aircut",
                                                           "torque_cut")}
    k_t = AXIS["torque_constant_Nm_per_A"]

    t, x, i, _, _ = _truth(_strokes([400, 1500, 3000, 1000]), rng, cutting=False)
    _write(paths["aircut_1"], ["SINUMERIK Servo-Trace Export", "Maschine: DMU 50; Achse: X1", "Datum: 27.11.2026",
                               "", "Zeit;Lageistwert;Stromistwert", "ms;mm;A"]
           + [";".join(row) for row in zip(_decimal_comma(t * 1e3, 1), _decimal_comma(x, 5),
                                           _decimal_comma(i, 4))])

    t, x, i, _, _ = _truth(_strokes([600, 2400, 800, 2000]), rng, cutting=False)
    velocity_mm_min = np.gradient(x, t) * 60.0
    _write(paths["aircut_2"], ["time [ms],position [mm],velocity [mm/min],current [A]"]
           + [f"{a:.1f},{b:.5f},{c:.3f},{d:.4f}" for a, b, c, d in zip(t * 1e3, x, velocity_mm_min, i)])

    t, x, i, process, force = _truth(_strokes([1000, 1000, 1000]), rng, cutting=True)
    start = np.datetime64("2026-11-27T06:00:00.000")
    stamps = [str(start + np.timedelta64(int(round(s * 1e3)), "ms")).replace(".", ",") for s in t]
    _write(paths["cut"], ["Zeitstempel;Lageistwert [mm];Strom [A];truth_force [N];truth_process [A]"]
           + [";".join(row) for row in zip(stamps, _decimal_comma(x, 5), _decimal_comma(i, 4),
                                           _decimal_comma(force, 3), _decimal_comma(process, 6))])

    for name, feeds, cutting in (("torque_aircut", [400, 1500, 3000, 1000, 600, 2400], False),
                                 ("torque_cut", [1000, 1000, 1000], True)):
        t, x, i, process, force = _truth(_strokes(feeds), rng, cutting=cutting)
        motor_rpm = np.gradient(x, t) / AXIS["screw_lead_mm"] * 60.0
        _write(paths[name], ["Zeit [s];Lageistwert [mm];Drehzahl [1/min];Drehmoment [Nm];truth_force [N]"]
               + [";".join(row) for row in zip(_decimal_comma(t, 3), _decimal_comma(x, 5),
                                               _decimal_comma(motor_rpm, 2), _decimal_comma(k_t * i, 4),
                                               _decimal_comma(force, 3))])

    axis = directory / "axis.toml"
    axis.write_text("\n".join(f"{key} = {value!r}" for key, value in AXIS.items()) + "\n", encoding="utf-8")
    return {**{name: path for name, path in paths.items()}, "axis": axis}


if __name__ == "__main__":  # python tests/export_logs.py DIR
    import sys

    for written in write_export_logs(sys.argv[1] if len(sys.argv) > 1 else ".").values():
        print(written)
