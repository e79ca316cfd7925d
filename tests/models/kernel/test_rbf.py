"""The compiled RBF expansion against a plain reference and against libsvm, and its error bound."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sklearn.svm import SVR

from greybox.models.kernel import rbf
from greybox.models.kernel.rbf import DEFAULT_TOLERANCE, EXP_RELATIVE_ERROR, MAX_CUTOFF, rbf_expansion


def reference_expansion(X, sv, alpha, intercept, gamma):
    """Plain-Python evaluation, one sample and one support vector at a time."""
    out = []
    for x in X:
        total = 0.0
        for s, a in zip(sv, alpha):
            total += a * math.exp(-gamma * sum((xi - si) ** 2 for xi, si in zip(x, s)))
        out.append(total + intercept)
    return np.array(out)


def test_matches_reference_far_from_the_origin():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(37, 3)) * 5.0 + 100.0  # offset: no cancellation in the distances
    sv = rng.normal(size=(11, 3)) * 5.0 + 100.0
    alpha = rng.normal(size=11)
    expected = reference_expansion(X, sv, alpha, 0.3, 0.05)
    got = rbf_expansion(X, sv, alpha, 0.3, 0.05, tolerance=1e-14)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14 + 1e-13 * np.abs(alpha).sum())


@pytest.mark.parametrize("n_samples", [1, 2, 3, 64, 65, 127, 131])
def test_samples_taken_two_at_a_time_whatever_the_block_ends(n_samples):
    """Blocks of odd length (the last sample of a pair alone) and of one sample match the reference."""
    rng = np.random.default_rng(n_samples)
    X = np.cumsum(rng.normal(scale=0.1, size=(n_samples, 3)), axis=0)
    sv = rng.normal(size=(23, 3))
    alpha = rng.normal(size=23)
    expected = reference_expansion(X, sv, alpha, -0.2, 0.7)
    got = rbf_expansion(X, sv, alpha, -0.2, 0.7, tolerance=1e-14, threads=1)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14 + 1e-13 * np.abs(alpha).sum())


def test_compiled_exponential_within_its_stated_relative_error():
    table = np.arange(int(MAX_CUTOFF) * rbf._EXP_STEPS + 1) / rbf._EXP_STEPS  # the table's points, and between them
    t = np.concatenate([np.linspace(0.0, MAX_CUTOFF, 4001), table, table + 0.5 / rbf._EXP_STEPS,
                        table + 0.5 / rbf._EXP_STEPS - 1e-12, np.arange(65) - 1e-12])
    t = t[(t >= 0) & (t <= MAX_CUTOFF)]
    approx = np.array([rbf._exp_neg(value) for value in t])
    exact = np.array([math.exp(-value) for value in t])
    assert np.max(np.abs(approx / exact - 1.0)) <= EXP_RELATIVE_ERROR


@pytest.mark.parametrize("tolerance", [1e-3, 1e-6, 1e-10])
def test_terms_left_out_stay_within_the_tolerance(tolerance):
    """Dense time-ordered samples and wide-spread support vectors: many terms are cut, the bound holds."""
    rng = np.random.default_rng(3)
    path = np.cumsum(rng.normal(scale=0.02, size=(3000, 2)), axis=0)
    sv = rng.uniform(path.min(0) - 1, path.max(0) + 1, size=(300, 2))
    alpha = rng.normal(size=300)
    gamma = 4.0
    exact = np.exp(-gamma * ((path[:, None, :] - sv[None]) ** 2).sum(-1)) @ alpha
    got = rbf_expansion(path, sv, alpha, 0.0, gamma, tolerance=tolerance)
    error = np.abs(got - exact)
    assert error.max() <= tolerance + EXP_RELATIVE_ERROR * np.abs(alpha).sum() + 1e-13
    if tolerance >= 1e-6:
        assert error.max() > 1e-3 * tolerance  # terms were left out: the bound is not vacuous


def test_threads_share_the_work_without_changing_a_bit():
    rng = np.random.default_rng(4)
    X = np.cumsum(rng.normal(scale=0.05, size=(40_000, 3)), axis=0)
    sv = rng.normal(size=(200, 3)) * X.std(0)
    alpha = rng.normal(size=200)
    one = rbf_expansion(X, sv, alpha, 0.1, 0.5, threads=1)
    two = rbf_expansion(X, sv, alpha, 0.1, 0.5, threads=2)
    three = rbf_expansion(X, sv, alpha, 0.1, 0.5, threads=3)
    np.testing.assert_array_equal(one, two)
    np.testing.assert_array_equal(one, three)


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
    assert svr.support_vectors_.shape[0] > 500
    for tolerance in (DEFAULT_TOLERANCE, 1e-10):  # within the stated bound, and as close as asked
        got = rbf_expansion(X_test, svr.support_vectors_, svr.dual_coef_.ravel(), svr.intercept_[0], 2.0,
                            tolerance=tolerance)
        bound = tolerance + EXP_RELATIVE_ERROR * np.sum(np.abs(svr.dual_coef_)) + 1e-12 * np.max(np.abs(expected))
        assert np.max(np.abs(got - expected)) <= bound


def test_empty_inputs_and_bad_shapes():
    assert rbf_expansion(np.zeros((0, 2)), np.ones((3, 2)), np.ones(3), 1.0, 1.0).shape == (0,)
    np.testing.assert_array_equal(rbf_expansion(np.zeros((4, 2)), np.zeros((0, 2)), [], 2.5, 1.0), 2.5)
    with pytest.raises(ValueError, match="features"):
        rbf_expansion(np.zeros((4, 3)), np.ones((3, 2)), np.ones(3))
    with pytest.raises(ValueError, match="dual coefficients"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(2))
    with pytest.raises(ValueError, match="gamma"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(3), gamma=0.0)
    with pytest.raises(ValueError, match="tolerance must be positive"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(3), tolerance=0.0)
    with pytest.raises(ValueError, match="threads"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.ones(3), threads=0)
    with pytest.raises(ValueError, match="too small"):
        rbf_expansion(np.zeros((4, 2)), np.ones((3, 2)), np.full(3, 1e20), tolerance=1e-10)


def test_coefficients_within_the_tolerance_give_the_intercept():
    got = rbf_expansion(np.zeros((5, 2)), np.zeros((2, 2)), [3e-11, -3e-11], 1.5, 1.0, tolerance=1e-10)
    np.testing.assert_array_equal(got, 1.5)
