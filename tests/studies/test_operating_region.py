"""The study of the operating region (studies.operating_region): its stand-in runs and regions."""

import numpy as np

from studies.operating_region import region_of, small_oscillation


def test_small_oscillations_outside_a_sweep_and_a_sweep_inside():
    sweep = small_oscillation(0.0, amplitude=40.0, frequency=0.25, seconds=40.0)
    region = region_of([sweep])
    again, _ = region.flags(sweep, region.start(), sample_time=sweep.sample_time)
    assert not (again["position"] | again["velocity"]).any()
    assert again["motion"].mean() < 0.001  # only cells of fewer than MIN_CELL_SAMPLES samples (its first steps)
    tiny = small_oscillation(0.0, amplitude=0.2, frequency=5.0)
    assert np.ptp(tiny.position) <= 0.4 + 1e-9
    flags, _ = region.flags(tiny, region.start(), sample_time=tiny.sample_time)
    assert flags["motion"][tiny.time > 1.0].mean() > 0.9
