"""Shares of held-out runs outside the operating region of training runs: twin, axis_dev, ARTS harmonic.

The operating region (:mod:`greybox.data.operating`) depends on the training runs alone, so the shares need
no fitted model (the ``"effort"`` flag, which needs one, is left out here). Cases:

- twin: trained on ``data/X_A.mcap``, each other air cut of the X axis held out (same kind of run);
- axis_dev: trained on ``aircut_A.csv``, ``aircut_C.csv`` (the other point-to-point programme) held out;
- ARTS: trained on the harmonic tests :data:`studies.arts.TRAIN_FILES`, each other harmonic test held out,
  and made-up runs of small oscillations (0.2 mm at 2 Hz, 0.5 mm at 5 Hz, 1 mm at 1 Hz about the middle of
  the training positions, 20 s at 1024 Hz): a stand-in for the regime of the irregular excitations, which
  are kept back and not in ``../shared/data/real``.

:func:`grid_rule` is the rule the grid of the region is chosen by, on the development air cuts alone.

``python -m studies.operating_region`` prints the shares.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from greybox.data.log import AxisLog
from greybox.data.operating import CELLS_PER_DECADE, MIN_CELL_SHARE, NEIGHBOURS, OperatingRegion, operating_record
from greybox.train.logs import read_training_logs

__all__ = ["GRID_CANDIDATES", "grid_rule", "outside_shares", "region_of", "small_oscillation"]

#: The settings :func:`grid_rule` chooses from: (cells a decade, least share of a cell, neighbours).
GRID_CANDIDATES = [(cells, share, neighbours) for cells in (4, 8, 16) for share in (0.0, 0.001, 0.005)
                   for neighbours in (0, 1)]

_ROOT = Path(__file__).resolve().parents[1]
_SHARED = _ROOT.parent / "shared" / "data"


def region_of(runs, cells_per_decade: int = CELLS_PER_DECADE, min_share: float = MIN_CELL_SHARE,
              neighbours: int = NEIGHBOURS) -> OperatingRegion:
    """The operating region of ``runs`` as a training record holds it.

    Parameters
    ----------
    runs : list of AxisLog
        Prepared training runs.
    cells_per_decade : int, default :data:`~greybox.data.operating.CELLS_PER_DECADE`
        Resolution of the grid [-].
    min_share : float, default :data:`~greybox.data.operating.MIN_CELL_SHARE`
        Least share of the training samples in a seen cell [-].
    neighbours : int, default :data:`~greybox.data.operating.NEIGHBOURS`
        Cells next to a seen one that count as seen [-].
    """
    ranges = {channel: [float(min(np.min(getattr(r, channel)) for r in runs)),
                        float(max(np.max(getattr(r, channel)) for r in runs))]
              for channel in ("position", "velocity", "acceleration")}
    return OperatingRegion(ranges, operating_record(runs, cells_per_decade=cells_per_decade, min_share=min_share),
                           neighbours=neighbours)


def _shares(region: OperatingRegion, run: AxisLog) -> dict:
    flags, _ = region.flags(run, region.start(), sample_time=run.sample_time)
    return {"outside": float(np.mean(np.logical_or.reduce(list(flags.values())))),
            **{name: float(np.mean(values)) for name, values in flags.items()}}


def small_oscillation(centre: float, amplitude: float = 0.2, frequency: float = 2.0, seconds: float = 20.0,
                      step: float = 1 / 1024, effort_unit: str = "N") -> AxisLog:
    """A run of small sinusoidal oscillations [mm] about ``centre`` [mm], zero acceleration (as ARTS is read).

    Parameters
    ----------
    centre, amplitude : float
        Middle and amplitude of the motion [mm].
    frequency : float
        [Hz].
    seconds, step : float
        Length and step of the run [s].
    effort_unit : str
        Unit of the (zero) effort column.
    """
    time = np.arange(int(seconds / step)) * step
    omega = 2 * np.pi * frequency
    return AxisLog(time=time, position=centre + amplitude * np.sin(omega * time), effort=np.zeros(time.size),
                   velocity=amplitude * omega * np.cos(omega * time), acceleration=np.zeros(time.size),
                   effort_unit=effort_unit)


def _motion(train, held, setting) -> float:
    region = region_of(train, *setting)
    flags, _ = region.flags(held, region.start(), sample_time=held.sample_time)
    return float(np.mean(flags["motion"]))


def grid_rule() -> tuple[dict, tuple]:
    """The rule of :data:`greybox.data.operating.CELLS_PER_DECADE` on the development air cuts.

    Returns
    -------
    table : dict
        Per setting of :data:`GRID_CANDIDATES`, the shares flagged by motion [-] of the held-out air cuts
        of the same kind (``"same"``: X_C, Y_C, aircut_C) and of another kind (``"other"``: X_B, Y_B,
        aircut_B), each trained on the A air cut of its axis.
    chosen : tuple
        The setting with the largest mean ``"other"`` share among those whose ``"same"`` shares are all at
        most 1 %; ties to the fewer cells a decade.
    """
    twin = {f"{axis}_{kind}": read_training_logs([str(_ROOT / "data" / f"{axis}_{kind}.mcap")])[0][0]
            for axis in "XY" for kind in "ABC"}
    axis = _SHARED / "independent" / "axis_dev"
    dev = {kind: read_training_logs([str(axis / f"aircut_{kind}.csv")])[0][0] for kind in "ABC"}
    pairs = {"same": [(twin["X_A"], twin["X_C"]), (twin["Y_A"], twin["Y_C"]), (dev["A"], dev["C"])],
             "other": [(twin["X_A"], twin["X_B"]), (twin["Y_A"], twin["Y_B"]), (dev["A"], dev["B"])]}
    table = {setting: {side: [_motion([a], b, setting) for a, b in runs] for side, runs in pairs.items()}
             for setting in GRID_CANDIDATES}
    eligible = [s for s in GRID_CANDIDATES if max(table[s]["same"]) <= 0.01]
    chosen = max(eligible, key=lambda s: (np.mean(table[s]["other"]), -s[0]))
    return table, chosen


def outside_shares(cells_per_decade: int = CELLS_PER_DECADE) -> dict:
    """The shares per case: ``{case: {held-out run: {"outside": share, quantity: share, ...}}}`` [-].

    Parameters
    ----------
    cells_per_decade : int, default :data:`~greybox.data.operating.CELLS_PER_DECADE`
        Resolution of the grid [-].
    """
    from studies.arts import TEST_FILES, TRAIN_FILES, benchmark_log

    out = {}
    twin = {name: read_training_logs([str(_ROOT / "data" / f"X_{name}.mcap")])[0] for name in "ABCD"}
    region = region_of(twin["A"], cells_per_decade)
    out["twin X (trained on X_A)"] = {f"X_{name}": _shares(region, runs[0]) for name, runs in twin.items()
                                      if name != "A"}
    axis = _SHARED / "independent" / "axis_dev"
    dev = {name: read_training_logs([str(axis / f"aircut_{name}.csv")])[0] for name in "ABC"}
    region = region_of(dev["A"], cells_per_decade)
    out["axis_dev (trained on aircut_A)"] = {f"aircut_{name}": _shares(region, runs[0])
                                             for name, runs in dev.items() if name != "A"}
    arts = _SHARED / "real" / "ARTS_friction_damper"
    train = [benchmark_log(arts / name) for name in TRAIN_FILES]
    region = region_of(train, cells_per_decade)
    middle = float(np.mean([np.median(run.position) for run in train]))
    out["ARTS (trained on the 0.25 Hz harmonic tests)"] = {
        **{name: _shares(region, benchmark_log(arts / name)) for name in TEST_FILES},
        **{f"small oscillations {a} mm at {f} Hz": _shares(region, small_oscillation(middle, a, f))
           for a, f in ((0.2, 2.0), (0.5, 5.0), (1.0, 1.0))}}
    return out


if __name__ == "__main__":
    rule, best = grid_rule()
    for setting, sides in rule.items():
        print(f"cells/decade {setting[0]:2d} share {setting[1]:.3f} neighbours {setting[2]}: " + "  ".join(
            f"{side} " + " ".join(f"{100 * v:5.2f}" for v in values) for side, values in sides.items()))
    print(f"chosen: {best}")
    for case, runs in outside_shares().items():
        print(case)
        for name, shares in runs.items():
            print(f"  {name:36s} " + "  ".join(f"{key} {100 * value:5.1f} %" for key, value in shares.items()))
    print(f"load: {os.getloadavg()[0]:.1f}")
