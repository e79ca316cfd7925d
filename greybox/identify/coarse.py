"""Block means of oversampled runs, for searches that only rank settings (the width of a backlash).

A search that fits a model once per trial setting and keeps the best needs the runs only as finely as the
friction responds to them. The finest length the friction follows is the pre-sliding deflection ``delta``
(:func:`~greybox.identify.initial.presliding_deflection`): after a reversal the force takes a travel of
about ``2 delta`` to cross from one sliding level to the other. Where the motor travels much less than
``delta`` in one sample even at its top speed, means over blocks of ``m`` samples keep at least
:data:`SAMPLES_PER_DEFLECTION` samples within ``delta`` and lose no shape the model could fit; the search then
simulates ``m`` times fewer samples. Where a sample already spans ``delta`` (a ball screw at 500 Hz:
``delta`` some 0.001-0.01 mm against 0.06 mm of travel per sample at 30 mm/s) ``m`` is 1 and nothing changes.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..data.log import AxisLog
from .initial import presliding_deflection, static_initial_guess

__all__ = ["SAMPLES_PER_DEFLECTION", "coarse_block", "block_means"]

#: Samples a block mean must keep within the pre-sliding deflection at the 99th percentile of ``|v|`` [-].
SAMPLES_PER_DEFLECTION = 10

#: Samples a run keeps at least after block means (fewer: the run is taken whole) [-].
_MIN_BLOCKS = 500


def coarse_block(runs: Sequence[AxisLog]) -> int:
    """Samples per block mean that keep :data:`SAMPLES_PER_DEFLECTION` samples within the pre-sliding deflection.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs (velocity given), on one sample time.

    Returns
    -------
    int
        ``m = floor(delta / (SAMPLES_PER_DEFLECTION * v99 * T))``, at least 1: ``delta`` the pre-sliding
        deflection of the runs [mm] (1 when they have no reversal from sliding), ``v99`` the 99th percentile
        of ``|v|`` [mm/s], ``T`` the largest sample time of the runs [s]; at most what leaves the shortest run
        500 blocks.
    """
    runs = list(runs)
    delta = presliding_deflection(runs, static_initial_guess(runs, fit_offset=True))
    speed = float(np.percentile(np.abs(np.concatenate([run.velocity for run in runs])), 99))
    step = max(run.sample_time for run in runs)
    if delta is None or not (speed > 0.0 and np.isfinite(step) and step > 0.0):
        return 1
    m = int(np.floor(delta / (SAMPLES_PER_DEFLECTION * speed * step)))
    return max(1, min(m, min(len(run) for run in runs) // _MIN_BLOCKS))


def block_means(run: AxisLog, m: int) -> AxisLog:
    """The run as means over consecutive blocks of ``m`` samples (a last, shorter block dropped).

    Parameters
    ----------
    run : AxisLog
        A prepared run (velocity and acceleration given).
    m : int
        Samples per block (1: the run itself).

    Returns
    -------
    AxisLog
        Time, position, velocity, acceleration and effort averaged per block; no extras.
    """
    if m <= 1:
        return run
    n = len(run) // m * m

    def mean(values):
        return np.asarray(values[:n], dtype=float).reshape(-1, m).mean(axis=1)

    return run.replace(time=mean(run.time), position=mean(run.position), effort=mean(run.effort),
                       velocity=mean(run.velocity), acceleration=mean(run.acceleration), extras={})
