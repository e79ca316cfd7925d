"""The batched RBF expansion against a plain reference and against libsvm."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.svm import SVR

from greybox.models.rbf import rbf_expansion


def reference_expansion(X, sv, alpha, intercept, gamma):
    """Plain-Python evaluation, one sample and one support vector at a time."""
    out = []
    for x in X:
        total = 0.0
        for s, a in zip(sv, alpha):
            total += a * np.exp(-gamma * sum((xi - si) ** 2 for xi, si in zip(x, s)))
        out.append(total + intercept)
    return np.array(out)


def test_matches_reference_for_every_chunk_size():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(37, 3)) * 5.0 + 100.0  # offset: the centring must remove it
    sv = rng.normal(size=(11, 3)) * 5.0 + 100.0
    alpha = rng.normal(size=11)
    expected = reference_expansion(X, sv, alpha, 0.3, 0.05)
    for chunk in (1, 7, 11, 50, 1 << 16):
        got = rbf_expansion(X, sv, alpha, 0.3, 0.05, chunk_elements=chunk)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_kernel_is_one_at_a_support_vector():
    sv = np.array([[1e3, -2e3], [5.0, 7.0]])
    got = rbf_expansion(sv, sv, [1.0, 0.0], 0.0, 1e6)
    np.testing.assert_allclose(got, [1.0, 0.0], atol=1e-15)


def test_matches_sklearn_svr_predict():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(1500, 2))
    y = np.sin(2.0 * X[:, 0]) + 0.5 * X[:, 1] + 0.05 * rng.normal(size=1500)
    svr = SVR(C=10.0, epsilon=0.01, gamma=2.0).fit(X, y)
    X_test = rng.normal(size=(5000, 2)) * 1.5
    expected = svr.predict(X_test)
    got = rbf_expansion(X_test, svr.support_vectors_, svr.dual_coef_.ravel(), svr.intercept_[0], 2.0)
    assert svr.support_vectors_.shape[0] > 500
    assert np.max(np.abs(got - expected)) <= 1e-10 * np.max(np.abs(expected))


def test_empty_inputs_and_bad_shapes():
    assert rbf_expansion(np.zeros((0, 2)), np.ones((3, 2)), np.ones(3), 1.0, 1.0).shape == (0,)
    np.testing.assert_array_equal(rbf_expansion(np.zeros((4, 2)), np.zeros((0, 2)), [], 2.5, 1.0), 2.5)
    with pytest.raises(ValueError, match="features"):
        rbf_expansion(np.zeros((4, 3)), np.ones((3, 2)), np.ones(3))
    with pytest.raises(ValueError, match="dual coefficients"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(2))
    with pytest.raises(ValueError, match="gamma"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(3), gamma=0.0)
