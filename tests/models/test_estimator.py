"""The shared parts of the current models (greybox.models.estimator): training region, plausibility of a fit."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import motion_log, velocity_profile

from greybox.errors import GreyboxError, ParameterError
from greybox.models.estimator import PLAUSIBLE_EFFORT_FACTOR, check_plausible, outside_any
from greybox.models.friction import CoulombModel


def _run(seed: int, v_max: float, level: float = 0.8):
    velocity = velocity_profile(4.0, seed=seed, v_max=v_max)
    log = motion_log(velocity, source=f"run{seed}.csv")
    return log.replace(effort=level * np.sign(velocity) + 0.01 * velocity)


def test_a_prediction_beyond_the_trained_efforts_is_outside_the_training_region():
    slow = _run(1, 20.0)
    model = CoulombModel().fit(slow)
    assert model.effort_range_ == [float(slow.effort.min()), float(slow.effort.max())]
    fast = _run(2, 200.0)  # viscous 0.01 A s/mm at 200 mm/s: beyond every effort of the slow run
    flags = model.outside_training(fast)
    predicted = model.predict(fast)
    beyond = (predicted > slow.effort.max()) | (predicted < slow.effort.min())
    assert beyond.any()
    np.testing.assert_array_equal(flags["effort"], beyond)
    assert np.all(outside_any(flags)[beyond])
    # the chunked prediction of a stream flags the same samples
    current, _, chunk_flags, _ = model.predict_flag_chunk(fast, model.initial_state(), model.region_state(),
                                                          sample_time=fast.sample_time)
    np.testing.assert_array_equal(chunk_flags["effort"], beyond)
    np.testing.assert_array_equal(current, predicted)


def test_a_model_file_without_the_effort_record_has_no_effort_flag_and_a_corrupt_one_is_refused():
    model = CoulombModel().fit(_run(1, 20.0))
    del model.effort_range_  # a file written before greybox kept it
    assert "effort" not in model.outside_training(_run(2, 40.0)) and model.effort_flags(np.zeros(3)) == {}
    model.effort_range_ = [1.0, float("nan")]
    with pytest.raises(ParameterError, match="effort_range_"):
        model.effort_flags(np.zeros(3))


def test_a_fit_far_beyond_the_measured_efforts_is_refused_and_a_sound_one_passes():
    run = _run(3, 40.0)
    model = CoulombModel().fit(run)  # fit calls the check: a sound fit passes
    check_plausible(model, [run])
    model.viscous_pos_ = model.viscous_neg_ = 100.0  # 4000 A at 40 mm/s on runs of about 1 A
    with pytest.raises(GreyboxError, match=f"beyond {PLAUSIBLE_EFFORT_FACTOR:g} times the largest effort") as caught:
        check_plausible(model, [run])
    assert "\n" not in str(caught.value) and "viscous" in str(caught.value)
