"""Block means of oversampled runs: the block length keeps the pre-sliding transition sampled, the means are means."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import motion_log

from greybox.identify.coarse import SAMPLES_PER_DEFLECTION, block_means, coarse_block
from greybox.identify.initial import presliding_deflection, static_initial_guess

#: Break-away deflection of the elasto-plastic spring of the synthetic device [mm].
DEFLECTION = 5.0


def spring_device(step: float, amplitude=50.0, period=4.0, cycles=3) -> object:
    """A sine motion and the force of one elasto-plastic spring (deflection :data:`DEFLECTION`, 10 N/mm)."""
    t = np.arange(int(cycles * period / step)) * step
    w = 2.0 * np.pi / period
    log = motion_log(amplitude * w * np.cos(w * t), step=step, effort_unit="N")
    z = np.empty(len(log))
    zi = 0.0
    for i, dx in enumerate(np.diff(log.position, prepend=log.position[0])):
        zi = float(np.clip(zi + dx, -DEFLECTION, DEFLECTION))
        z[i] = zi
    return log.replace(effort=10.0 * z)


def test_block_means_are_the_means_of_consecutive_samples():
    log = spring_device(1.0 / 256.0)
    coarse = block_means(log, 7)
    n = len(log) // 7
    assert len(coarse) == n
    for name in ("time", "position", "velocity", "acceleration", "effort"):
        np.testing.assert_allclose(getattr(coarse, name)[3], np.mean(getattr(log, name)[21:28]), rtol=1e-12)
    assert coarse.sample_time == pytest.approx(7 * log.sample_time)
    assert block_means(log, 1) is log


def test_an_oversampled_run_gets_blocks_that_keep_the_deflection_sampled():
    fine, coarse_rate = spring_device(1.0 / 1024.0), spring_device(1.0 / 64.0)
    m = coarse_block([fine])
    assert m > 1
    assert coarse_block([coarse_rate]) == 1  # a sample already spans a tenth of the deflection: nothing changes
    averaged = block_means(fine, m)
    delta = presliding_deflection([fine], static_initial_guess([fine], fit_offset=True))
    travel = np.percentile(np.abs(fine.velocity), 99) * averaged.sample_time
    assert travel <= delta / SAMPLES_PER_DEFLECTION
    assert np.percentile(np.abs(fine.velocity), 99) * (m + 1) * fine.sample_time > delta / SAMPLES_PER_DEFLECTION
    # the hysteresis survives: the block means' force against position is the fine run's within a tenth of the range
    fine_force = np.interp(averaged.time, fine.time, fine.effort)
    assert np.max(np.abs(averaged.effort - fine_force)) < 0.1 * np.ptp(fine.effort)


def test_a_short_run_keeps_500_blocks():
    short = spring_device(1.0 / 1024.0, cycles=0.6)  # one reversal, 2457 samples
    assert coarse_block([short]) == len(short) // 500 < coarse_block([spring_device(1.0 / 1024.0)])
