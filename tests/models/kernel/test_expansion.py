"""The compiled kernels of a kernel model's frame (`KernelFrame`) against plain Python."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from greybox.models.kernel import expansion as expansion_module
from greybox.models.kernel.expansion import KernelFrame
from greybox.models.kernel.rbf import BLOCK_SAMPLES, DEFAULT_TOLERANCE, EXP_RELATIVE_ERROR, add_expansion, threads_for


def _model(rng, *, weights=True, handover=True, ranges=True, n_support=40, n_features=3):
    """A fitted kernel model's arrays, drawn at random (what KernelFrame reads of a model)."""
    X = rng.normal(size=(200, n_features)) * [2.0, 5.0, 0.3][:n_features] + [1.0, -3.0, 0.0][:n_features]
    model = SimpleNamespace(input_mean_=X.mean(axis=0), input_scale_=X.std(axis=0),
                            input_weights_=rng.uniform(0.5, 2.0, n_features) if weights else None,
                            handover_width_=0.8 if handover else None,
                            input_range_=np.array([X.min(axis=0), X.max(axis=0)]) if ranges else None,
                            support_vectors_=rng.normal(size=(n_support, n_features)),
                            dual_coef_=rng.normal(size=n_support), intercept_=0.3, gamma_=0.7)
    return model, X


def stated_bound(model) -> float:
    """The kernel's stated bound on its error against the full sum (:mod:`greybox.models.kernel.rbf`), plus
    the rounding of a sum of a few dozen terms."""
    weight = float(np.sum(np.abs(model.dual_coef_)))
    return DEFAULT_TOLERANCE + EXP_RELATIVE_ERROR * weight + 1e-13 * weight


def reference_terms(model, X):
    """Plain-Python expansion, hand-over weight and input-range flags of each row of raw inputs ``X``."""
    n_features = X.shape[1]
    weights = model.input_weights_ if model.input_weights_ is not None else [1.0] * n_features
    expansion, weight, outside = [], [], []
    if model.handover_width_ is not None:
        box = [[(bound[f] - model.input_mean_[f]) / model.input_scale_[f] * math.sqrt(weights[f])
                for f in range(n_features)] for bound in model.input_range_]
    for row in X:
        scaled = [(row[f] - model.input_mean_[f]) / model.input_scale_[f] * math.sqrt(weights[f])
                  for f in range(n_features)]
        total = model.intercept_
        for sv, alpha in zip(model.support_vectors_, model.dual_coef_):
            total += alpha * math.exp(-model.gamma_ * sum((a - b) ** 2 for a, b in zip(scaled, sv)))
        expansion.append(total)
        if model.handover_width_ is not None:
            distance = math.sqrt(sum(max(lo - x, x - hi, 0.0) ** 2 for x, lo, hi in zip(scaled, *box)))
            t = min(distance / model.handover_width_, 1.0)
            weight.append(1.0 - 3.0 * t * t + 2.0 * t ** 3)
        if model.input_range_ is not None:
            outside.append(any(x < lo or x > hi for x, lo, hi in zip(row, *model.input_range_)))
    return np.array(expansion), np.array(weight), np.array(outside, dtype=bool)


@pytest.mark.parametrize("weights, handover, ranges", [(True, True, True), (False, True, True),
                                                       (True, False, True), (True, False, False)])
def test_terms_match_plain_python_and_the_offline_path(weights, handover, ranges):
    rng = np.random.default_rng(7)
    model, X = _model(rng, weights=weights, handover=handover, ranges=ranges)
    X = np.concatenate([X[:70], X[:30] * 3.0])  # samples inside and far outside the training box
    frame = KernelFrame(model)
    expansion, weight, outside = frame.terms(X)
    want_expansion, want_weight, want_outside = reference_terms(model, X)
    np.testing.assert_allclose(expansion, want_expansion, rtol=0, atol=stated_bound(model))
    np.testing.assert_allclose(expansion, frame.expansion(X), rtol=0, atol=1e-12)
    if handover:
        np.testing.assert_allclose(weight, want_weight, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(weight, frame.weight(X))
        assert np.any(weight == 1.0) and np.any(weight < 1.0)
    else:
        assert weight is None
    if ranges:
        np.testing.assert_array_equal(outside, want_outside)
        assert outside.any() and not outside.all()
    else:
        assert outside is None


def test_coordinates_match_plain_python():
    rng = np.random.default_rng(3)
    model, X = _model(rng)
    got = KernelFrame(model).coordinates(X[:20])
    want = [[(x - m) / s * math.sqrt(w) for x, m, s, w in zip(row, model.input_mean_, model.input_scale_,
                                                              model.input_weights_)] for row in X[:20]]
    np.testing.assert_allclose(got, want, rtol=1e-15, atol=0)


def test_terms_of_no_samples_are_empty():
    model, _ = _model(np.random.default_rng(1))
    expansion, weight, outside = KernelFrame(model).terms(np.empty((0, 3)))
    assert expansion.shape == weight.shape == outside.shape == (0,)


def test_a_log_chunk_shares_its_kernel_sums_over_threads_and_gets_the_same_terms(monkeypatch):
    rng = np.random.default_rng(11)
    model, X = _model(rng)
    walk = np.cumsum(rng.normal(scale=0.05, size=(160 * BLOCK_SAMPLES, X.shape[1])), axis=0)  # a log's slow drift
    long = X.mean(axis=0) + walk * X.std(axis=0)
    assert threads_for(len(long), 2) == 2 and threads_for(len(X), 2) == 1
    monkeypatch.setattr(expansion_module.numba, "get_num_threads", lambda: 1)
    alone = KernelFrame(model).terms(long)
    shared = []
    monkeypatch.setattr(expansion_module, "add_expansion", lambda *a: shared.append(a[-1]) or add_expansion(*a))
    monkeypatch.setattr(expansion_module.numba, "get_num_threads", lambda: 2)
    together = KernelFrame(model).terms(long)
    assert shared == [2]  # the threaded path ran
    for one, two in zip(alone, together):
        np.testing.assert_array_equal(one, two)
    step = slice(None, None, 97)
    want_expansion, _, _ = reference_terms(model, long[step])
    np.testing.assert_allclose(together[0][step], want_expansion, rtol=0, atol=stated_bound(model))
