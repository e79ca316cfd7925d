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


def test_a_stream_checks_the_effort_record_once_at_its_start_and_flags_each_chunk_as_the_model_does():
    slow, fast = _run(1, 20.0), _run(2, 200.0)
    model = CoulombModel().fit(slow)
    view = model.stream_view(fast.select(slice(0, 10)), sample_time=fast.sample_time)
    region, state, flags = view.region_state(), view.initial_state(), []
    for start in range(0, len(fast), 10):
        _, state, flagged, region = view.predict_flag_chunk(fast.select(slice(start, start + 10)), state, region,
                                                            sample_time=fast.sample_time)
        flags.append(flagged["effort"])
    expected = model.effort_flags(model.predict(fast))["effort"]
    assert expected.any() and not expected.all()
    np.testing.assert_array_equal(np.concatenate(flags), expected)
    model.effort_range_ = [2.0, 1.0]  # a corrupt record: refused when the stream starts, before any chunk
    with pytest.raises(ParameterError, match="effort_range_"):
        model.stream_view(fast.select(slice(0, 10)), sample_time=fast.sample_time)


def test_a_fit_far_beyond_the_measured_efforts_is_refused_and_a_sound_one_passes():
    run = _run(3, 40.0)
    model = CoulombModel().fit(run)  # fit calls the check: a sound fit passes
    check_plausible(model, [run])
    model.viscous_pos_ = model.viscous_neg_ = 100.0  # 4000 A at 40 mm/s on runs of about 1 A
    with pytest.raises(GreyboxError, match=f"beyond {PLAUSIBLE_EFFORT_FACTOR:g} times the largest effort") as caught:
        check_plausible(model, [run])
    assert "\n" not in str(caught.value) and "viscous" in str(caught.value)


def test_with_its_training_record_every_kind_of_model_has_the_same_region_and_a_file_keeps_it(tmp_path):
    from greybox.models.files import load_model, save_model
    from greybox.models.friction import LuGreModel
    from greybox.train.record import record_training

    train, test = _run(1, 20.0), _run(2, 40.0)
    models = {}
    for kind in (CoulombModel, LuGreModel):  # memoryless (once flagged standstill) and dynamic (never did)
        model = kind().fit(train)
        record_training(model, [train], [model.predict(train)], names=["run1"])
        models[kind.__name__] = model
    flags = {name: model.outside_training(test) for name, model in models.items()}
    assert "standstill" in flags["CoulombModel"] and "standstill" not in flags["LuGreModel"]  # not the region
    inputs = [{q: f for q, f in each.items() if q not in ("effort", "standstill")} for each in flags.values()]
    assert set(inputs[0]) == {"position", "velocity", "acceleration", "motion"}
    for quantity in inputs[0]:
        np.testing.assert_array_equal(inputs[0][quantity], inputs[1][quantity])
    assert inputs[0]["velocity"].any()  # the test run is twice as fast
    lugre = models["LuGreModel"]
    state, region, parts = lugre.initial_state(), lugre.region_state(), []
    for samples in (slice(0, 7), slice(7, 900), slice(900, None)):
        _, state, chunk, region = lugre.predict_flag_chunk(test.select(samples), state, region,
                                                           sample_time=test.sample_time)
        parts.append(chunk)
    for quantity, values in flags["LuGreModel"].items():
        np.testing.assert_array_equal(np.concatenate([part[quantity] for part in parts]), values)
    loaded = load_model(save_model(lugre, tmp_path / "lugre.gbm"))
    for quantity, values in loaded.outside_training(test).items():
        np.testing.assert_array_equal(values, flags["LuGreModel"][quantity])
