"""Hand-over of the kernel models' correction to their physical part outside the training region."""

from __future__ import annotations

import math

import numpy as np
import pytest
from model_files import write_members
from svr_runs import FIXED, sweep_run

from greybox.errors import ParameterError
from greybox.models import files, registry
from greybox.models.handover import HANDOVER_LENGTHS, hand_over, handover_weight, handover_width
from greybox.models.svr import SVRCurrentModel


def reference_weight(x, low, high, width):
    """Plain-Python hand-over weight of one sample: smoothstep of the distance from the box."""
    squared = 0.0
    for value, lo, hi in zip(x, low, high):
        gap = lo - value if value < lo else value - hi if value > hi else 0.0
        squared += gap * gap
    t = min(math.sqrt(squared) / width, 1.0)
    return 1.0 - 3.0 * t * t + 2.0 * t * t * t


def test_the_weight_is_one_in_the_box_zero_beyond_the_width_and_matches_the_reference():
    rng = np.random.default_rng(0)
    low, high, width = np.array([-1.0, 0.0, 2.0]), np.array([1.0, 0.5, 2.0]), 0.7
    X = rng.uniform(-3.0, 4.0, size=(2000, 3))
    weight = handover_weight(X, low, high, width)
    expected = [reference_weight(x, low, high, width) for x in X]
    np.testing.assert_allclose(weight, expected, rtol=0, atol=1e-14)
    inside = np.all((X >= low) & (X <= high), axis=1)
    box_sample = np.array([[0.3, 0.25, 2.0]])
    assert handover_weight(box_sample, low, high, width)[0] == 1.0
    distance = np.linalg.norm(np.maximum(np.maximum(low - X, X - high), 0.0), axis=1)
    assert np.all(weight[inside] == 1.0) and np.all(weight[distance >= width] == 0.0)
    between = (distance > 0) & (distance < width)
    assert between.any() and np.all((weight[between] > 0) & (weight[between] < 1))


def test_the_weight_falls_monotonically_with_a_continuous_slope():
    """Along a line leaving the box the weight and its slope are continuous (C1), the slope zero at both ends."""
    low, high, width = np.zeros(2), np.ones(2), 0.5
    s = np.linspace(0.0, 2.0, 20001)
    X = np.column_stack((s, np.full_like(s, 0.5)))  # leaves the box at s = 1, the weight ends at s = 1.5
    weight = handover_weight(X, low, high, width)
    slope = np.diff(weight) / np.diff(s)
    assert np.all(slope <= 0)
    assert np.max(np.abs(np.diff(weight))) < 1e-3  # no jump
    assert np.max(np.abs(np.diff(slope))) < 1e-2  # no kink: the slope changes by small steps only
    assert abs(slope[np.searchsorted(s, 1.0)]) < 1e-2 and abs(slope[np.searchsorted(s, 1.5) - 1]) < 1e-2
    assert np.min(slope) == pytest.approx(-1.5 / width, rel=1e-3)  # smoothstep's steepest slope, mid-way


def test_bad_widths_and_boxes_are_refused():
    X = np.zeros((3, 2))
    for width in (0.0, -1.0, float("nan"), float("inf"), None):
        with pytest.raises(ParameterError, match="handover_width_"):
            handover_weight(X, np.zeros(2), np.ones(2), width)
    for low, high in ((np.ones(2), np.zeros(2)), (np.zeros(3), np.ones(3)), (np.zeros(2), np.array([1.0, np.nan]))):
        with pytest.raises(ParameterError, match="training box"):
            handover_weight(X, low, high, 1.0)


def test_the_width_is_a_kernel_length_scale_and_no_weight_keeps_the_fitted_prediction():
    assert handover_width(4.0) == pytest.approx(HANDOVER_LENGTHS / 2.0)
    fitted, physical = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0])
    np.testing.assert_array_equal(hand_over(physical, fitted, None), fitted)
    np.testing.assert_allclose(hand_over(physical, fitted, np.array([1.0, 0.5, 0.0])), [1.0, 1.0, 1.0])


@pytest.fixture(scope="module")
def svr_pair():
    """The sole SVR fitted with and without the hand-over (same kernel: the setting does not touch the fit)."""
    train = sweep_run(1)
    return SVRCurrentModel(**FIXED).fit(train), SVRCurrentModel(**FIXED, handover=False).fit(train)


def test_inside_the_training_box_the_sole_svr_predicts_as_without_the_hand_over(svr_pair):
    model, plain = svr_pair
    np.testing.assert_array_equal(model.dual_coef_, plain.dual_coef_)
    assert plain.handover_width_ is None and model.handover_width_ == handover_width(model.gamma_)
    test = sweep_run(3)
    inside = ~model.outside_training(test)["inputs"]
    assert inside.mean() > 0.5
    np.testing.assert_array_equal(model.predict(test)[inside], plain.predict(test)[inside])


def test_beyond_the_training_speeds_the_sole_svr_hands_over_to_the_coulomb_viscous_proxy(svr_pair):
    """Sliding friction beyond 3x the training speed: monotone, growing at most linearly (the proxy's law)."""
    model, plain = svr_pair
    train = sweep_run(1)
    top = float(np.max(np.abs(train.velocity)))
    assert model.proxy_coulomb_ > 0 and model.proxy_viscous_ > 0
    for sign in (1.0, -1.0):
        v = sign * np.linspace(3.0, 10.0, 400) * top
        p = np.full_like(v, float(np.median(train.position)))
        fast = train.select(slice(0, v.size)).replace(position=p, velocity=v, acceleration=np.zeros_like(v))
        friction = model.friction(fast)
        np.testing.assert_allclose(friction, model.proxy_coulomb_ * sign + model.proxy_viscous_ * v, atol=1e-12)
        assert np.all(sign * np.diff(friction) >= 0)
        # without the hand-over the kernel falls back to its intercept: flat in speed, whatever the sign
        np.testing.assert_allclose(plain.friction(fast), plain.intercept_, atol=1e-9)


def test_a_run_leaving_the_box_predicts_alike_in_chunks_and_at_once(svr_pair):
    model, _ = svr_pair
    test = sweep_run(4, n=3000)
    test = test.replace(position=test.position * 1.6, velocity=test.velocity * 1.6)
    weight = model._handover(np.column_stack((test.position, test.velocity)))
    assert np.any(weight == 0) and np.any((weight > 0) & (weight < 1)) and np.any(weight == 1)
    whole = model.predict(test)
    state, parts = None, []
    for start in range(0, len(test), 700):
        part, state = model.predict_chunk(test.select(slice(start, start + 700)), state,
                                          sample_time=test.sample_time)
        parts.append(part)
    np.testing.assert_allclose(np.concatenate(parts), whole, rtol=0, atol=1e-12)


def test_the_hand_over_round_trips_and_a_file_from_before_it_predicts_as_fitted(svr_pair, tmp_path, monkeypatch):
    import copy
    import json
    import zipfile

    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    model, plain = svr_pair
    test = sweep_run(4, n=2000)
    test = test.replace(velocity=test.velocity * 2.0)  # partly beyond the training speeds
    loaded = files.load_model(files.save_model(model, tmp_path / "new.gbm"))
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))
    assert {"handover_width", "proxy_coulomb", "proxy_viscous"} <= {row.name for row in loaded.parameter_table()}
    # a file written before the hand-over has neither the setting nor its attribute
    old = copy.deepcopy(plain)
    del old.handover_width_
    saved = files.save_model(old, tmp_path / "saved.gbm")
    with zipfile.ZipFile(saved) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    document = json.loads(members["model.json"])
    del document["model"]["params"]["handover"]
    members["model.json"] = json.dumps(document).encode()
    path = tmp_path / "old.gbm"
    write_members(path, members)
    loaded_old = files.load_model(path)
    assert loaded_old.handover  # the setting's default ...
    np.testing.assert_array_equal(loaded_old.predict(test), plain.predict(test))  # ... yet predicts as fitted
    assert not np.allclose(loaded_old.predict(test), model.predict(test))


def test_a_file_with_a_bad_hand_over_width_is_refused(svr_pair, tmp_path, monkeypatch):
    import copy

    from greybox.errors import ModelFileError

    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    hostile = copy.deepcopy(svr_pair[0])
    hostile.handover_width_ = -1.0
    path = files.save_model(hostile, tmp_path / "hostile.gbm")
    with pytest.raises(ModelFileError, match="handover_width_"):
        files.load_model(path)
