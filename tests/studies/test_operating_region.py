"""The study of the operating region (studies.operating_region): its stand-in runs and regions."""

import numpy as np

from studies.operating_region import _grid_only, _reversal_flags, region_of, small_oscillation


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


def test_the_rules_reversal_flags_at_the_span_window_are_the_regions():
    """What :func:`reversal_rule` scores for the window 0.5 s and deadband 1 (the grid alone or the reversals)
    is what the region flags by motion; four reversals a second where training showed one catch most of a run
    the grid alone mostly lets in, and a 2 s window counts the two a second a 0.5 s window cannot."""
    train = [small_oscillation(0.0, amplitude=40.0, frequency=0.25, seconds=40.0),
             small_oscillation(0.0, amplitude=2.0, frequency=0.5, seconds=20.0)]
    region = region_of(train)
    fast = small_oscillation(0.0, amplitude=1.0, frequency=2.0, seconds=10.0)
    flags, _ = region.flags(fast, region.start(), sample_time=fast.sample_time)
    reversals = _reversal_flags(train, fast, 0.5, 1.0)
    np.testing.assert_array_equal(_grid_only(region, fast) | reversals, flags["motion"])
    assert _grid_only(region, fast).mean() < 0.5 < 0.9 < reversals.mean()
    middle = small_oscillation(0.0, amplitude=0.5, frequency=1.0, seconds=10.0)
    assert _reversal_flags(train, middle, 0.5, 1.0).mean() < 0.01
    assert _reversal_flags(train, middle, 2.0, 1.0).mean() > 0.9
