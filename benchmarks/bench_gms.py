"""Speed of the compiled GMS kernel against plain Python and plain C, and GMS identification time.

Usage::

    python benchmarks/bench_gms.py [--json] [--steps 2000000] [--repeats 5] [--elements 4]

- ``ns_per_step``: numba kernel :func:`greybox.models.friction.kernels.gms_friction_kernel`,
  best of ``--repeats`` runs over ``--steps`` steps (compilation excluded),
  interleaved with the C runs;
- ``python_ns_per_step``: the plain-Python reference of the tests
  (``tests/friction_reference.py``) on ``--python-steps`` steps, best of 3;
- ``c_ns_per_step``: ``benchmarks/gms_loop.c`` (the same recursion) compiled
  with ``cc -O2`` at run time, best of ``--repeats`` (timed inside the C program,
  file input and output excluded); ``null`` without a compiler.
  ``c_max_abs_diff`` is its largest difference to the numba friction [A];
- ``fit_seconds``: :class:`greybox.models.friction.GMSModel` with default settings on a
  synthetic 500 Hz log of ``--fit-seconds-of-data`` seconds simulated by a GMS
  truth plus noise.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the plain-Python references

from friction_reference import gms_reference
from friction_signals import STEP, motion_log, velocity_profile

from greybox.models.friction import GMSModel
from greybox.models.friction.gms import GMSState, simulate_gms
from greybox.models.friction.kernels import direction_curves, gms_friction_kernel

ROOT = Path(__file__).resolve().parents[1]


def parameters(n_elements: int) -> dict:
    """GMS parameters of a ball-screw-like axis: break-away 0.02 mm, Coulomb level about 1 A."""
    alpha = np.geomspace(1.0, 20.0, n_elements)
    return {"alpha": alpha / alpha.sum(), "k": np.full(n_elements, 50.0), "sigma": 0.002, "s_0": 0.02,
            "s_inf": 0.015, "v_s": 5.0, "C": 3.0, "mu": 0.005}


def bench_velocity(n_steps: int) -> np.ndarray:
    """Strokes of +-50 mm/s with a 7 Hz ripple: sliding, reversals and pre-sliding loops [mm/s]."""
    t = np.arange(n_steps) * STEP
    return 50.0 * np.sin(2 * np.pi * 0.5 * t) + 5.0 * np.sin(2 * np.pi * 7.0 * t)


def numba_runner(velocity, p):
    """Callable timing one run of the numba kernel [ns/step]; the kernel is compiled (or loaded) first."""
    rest = GMSState.at_rest(p["alpha"].size)
    curves = direction_curves((p["s_0"],) * 2, (p["s_inf"],) * 2, (p["v_s"],) * 2)  # the same in both directions
    viscous = np.full(2, p["mu"])
    args = (STEP, p["alpha"], p["k"], p["sigma"], curves, p["C"], viscous, rest.z, rest.mode)
    gms_friction_kernel(velocity[:10], *args)
    output = {}

    def run():
        start = time.perf_counter()
        output["friction"], _, _ = gms_friction_kernel(velocity, *args)
        return (time.perf_counter() - start) / velocity.size * 1e9

    return run, output


def c_runner(velocity, p, workdir: Path):
    """Callable timing one run of benchmarks/gms_loop.c built with ``cc -O2`` [ns/step]; ``None`` without cc."""
    compiler = shutil.which("cc")
    if compiler is None:
        return None, None
    exe = workdir / "gms_loop"
    subprocess.run([compiler, "-O2", "-o", str(exe), str(ROOT / "benchmarks" / "gms_loop.c"), "-lm"], check=True)
    velocity.astype(np.float64).tofile(workdir / "v.bin")
    args = [repr(float(x)) for x in (STEP, p["C"], p["sigma"], p["s_0"], p["s_inf"], p["v_s"], p["mu"])]
    args += [str(p["alpha"].size)] + [repr(float(x)) for x in np.concatenate((p["alpha"], p["k"]))]
    command = [str(exe), str(workdir / "v.bin"), str(workdir / "f.bin"), "1", *args]

    def run():
        return float(subprocess.run(command, check=True, capture_output=True, text=True).stdout.strip())

    return run, lambda: np.fromfile(workdir / "f.bin")


def time_python(velocity, p):
    """Best of 3 runs of the plain-Python reference [ns/step] and its friction."""
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        friction = gms_reference(velocity, STEP, p["alpha"], p["k"], p["sigma"], p["s_0"], p["s_inf"], p["v_s"],
                                 p["C"], p["mu"])[0]
        best = min(best, time.perf_counter() - start)
    return best / velocity.size * 1e9, np.asarray(friction)


def time_fit(duration):
    """Seconds to fit a default GMSModel on a synthetic log of ``duration`` seconds at 500 Hz."""
    truth = dict(parameters(4), k=np.array([40.0, 60.0, 30.0, 45.0]))
    velocity = velocity_profile(duration, seed=1)
    log = motion_log(velocity)
    friction, _ = simulate_gms(velocity, STEP, **truth)
    noise = 0.02 * np.random.default_rng(0).standard_normal(velocity.size)
    log = log.replace(effort=0.001 * log.acceleration + friction + noise)
    model = GMSModel()
    start = time.perf_counter()
    model.fit(log)
    seconds = time.perf_counter() - start
    rmse = float(np.sqrt(np.mean((model.predict(log) - log.effort) ** 2)))
    return seconds, len(log), model.n_evaluations_, rmse


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    parser.add_argument("--steps", type=int, default=2_000_000)
    parser.add_argument("--python-steps", type=int, default=20_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--elements", type=int, default=4)
    parser.add_argument("--fit-seconds-of-data", type=float, default=180.0)
    args = parser.parse_args(argv)

    p = parameters(args.elements)
    velocity = bench_velocity(args.steps)
    run_numba, numba_out = numba_runner(velocity, p)
    with tempfile.TemporaryDirectory() as tmp:
        run_c, c_friction = c_runner(velocity, p, Path(tmp))
        ns, c_ns = np.inf, np.inf
        for _ in range(args.repeats):  # interleaved, so that both see the same machine load
            ns = min(ns, run_numba())
            if run_c is not None:
                c_ns = min(c_ns, run_c())
        c_diff = None if run_c is None else float(np.max(np.abs(c_friction() - numba_out["friction"])))
    c_ns = None if run_c is None else c_ns
    py_ns, py_friction = time_python(velocity[: args.python_steps], p)
    py_diff = float(np.max(np.abs(py_friction - numba_out["friction"][: args.python_steps])))
    fit_s, fit_n, fit_evals, fit_rmse = time_fit(args.fit_seconds_of_data)
    result = {
        "ns_per_step": round(ns, 3),
        "python_ns_per_step": round(py_ns, 1),
        "c_ns_per_step": None if c_ns is None else round(c_ns, 3),
        "n_elements": args.elements,
        "n_steps": args.steps,
        "python_steps": args.python_steps,
        "speedup_vs_python": round(py_ns / ns, 1),
        "ratio_to_c": None if c_ns is None else round(ns / c_ns, 3),
        "python_max_abs_diff": py_diff,
        "c_max_abs_diff": c_diff,
        "fit_seconds": round(fit_s, 2),
        "fit_samples": fit_n,
        "fit_evaluations": fit_evals,
        "fit_rmse_A": round(fit_rmse, 5),
    }
    if args.json:
        print(json.dumps(result))
    else:
        print(f"GMS N={args.elements}, {args.steps} steps: numba {ns:.2f} ns/step, plain Python {py_ns:.0f} ns/step "
              f"({py_ns / ns:.0f}x), C -O2 "
              + ("n/a" if c_ns is None else f"{c_ns:.2f} ns/step (numba/C {ns / c_ns:.2f})"))
        print(f"GMS identification on {fit_n} samples: {fit_s:.1f} s, {fit_evals} simulations, "
              f"RMSE {fit_rmse:.4f} A (noise 0.02 A)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
