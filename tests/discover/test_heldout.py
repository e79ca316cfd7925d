"""The held-out test of the discovery workflow (:mod:`greybox.discover.heldout`).

A missing effect lowers the error on stretches of the log it was not fitted
on; noise and deterministic misfit that a scan over many periods happens to
match do not. The calibration cases below put structure into the residual that
no library effect has (pre-sliding transients after reversals, a ripple in one
direction only), not only noise.
"""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.discover.heldout import HeldOutTest, _solve, block_labels
from greybox.errors import GreyboxError
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import effect
from greybox.models.friction import CoulombModel, GMSModel
from studies.discovery import StudyCase, case_logs
from studies.hysteresis_axis import FamilyCase, family_logs

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

DURATION_S = 20.0


def _tester(run, added=None, **settings) -> HeldOutTest:
    """Held-out test on the Coulomb model fitted to ``run`` (its effort plus ``added``)."""
    if added is not None:
        run = run.replace(effort=run.effort + added)
    model = AugmentedModel(base=CoulombModel()).fit([run])
    part = model.linear_part([run])
    return HeldOutTest(model.with_base_friction([run]), part.columns, run.effort - part.fixed, model.context,
                       **settings)


def _since_reversal_mm(run) -> np.ndarray:
    """Travel since the direction of motion last changed [mm], and the present direction."""
    direction = np.sign(run.velocity)
    moving = direction != 0
    last = np.maximum.accumulate(np.where(moving, np.arange(len(run)), 0))
    held = direction[last]
    change = np.flatnonzero(np.diff(held) != 0) + 1
    start = np.zeros(len(run), dtype=np.int64)
    start[change] = change
    start = np.maximum.accumulate(start)
    return np.abs(run.position - run.position[start]), held


def test_blocks_are_contiguous_and_balanced():
    class Run:
        def __init__(self, n):
            self.n = n

        def __len__(self):
            return self.n

    labels = block_labels([Run(100), Run(150)], 5)
    assert labels.size == 250 and np.all(np.diff(labels) >= 0)
    assert np.array_equal(np.bincount(labels), [50] * 5)
    with pytest.raises(GreyboxError, match="at least 2"):
        block_labels([Run(100)], 1)
    with pytest.raises(GreyboxError, match="too few"):
        block_labels([Run(30)], 5)


def test_the_fit_is_least_squares_and_stays_bounded_on_collinear_columns():
    rng = np.random.default_rng(0)
    design = rng.standard_normal((2000, 4)) * [1.0, 10.0, 0.1, 3.0]
    target = design @ [1.0, -2.0, 3.0, 0.5] + 0.01 * rng.standard_normal(2000)
    np.testing.assert_allclose(_solve(design, target), np.linalg.lstsq(design, target, rcond=None)[0], rtol=1e-3)
    collinear = np.column_stack((design[:, 0], design[:, 0] + 1e-9 * rng.standard_normal(2000)))
    coefficients = _solve(collinear, design[:, 0])
    assert np.all(np.abs(coefficients) < 1.0) and coefficients.sum() == pytest.approx(1.0, rel=1e-3)


def test_a_missing_ripple_passes_with_its_period_on_every_block():
    train, _, _ = case_logs(StudyCase("position_periodic_force", 1.0, 1, "coulomb", DURATION_S))
    result = _tester(train, rng=np.random.default_rng(1)).evaluate(effect("position_periodic_force"), 2.5)
    assert result.passes, result.reasons
    assert result.gain > 0.2 and result.positive_blocks == 5
    assert all(abs(shape / 2.5 - 1.0) < 0.02 for shape in result.shapes)
    assert min(result.direction_transfer.values()) > 0.1
    assert result.margin >= result.null_q95 and result.margin >= 0.02


@pytest.mark.parametrize("name", ["position_periodic_force", "position_periodic_friction", "thermal_drift",
                                  "position_trend"])
def test_noise_alone_does_not_pass(name):
    passed = []
    for seed in range(4):
        train, _, _ = case_logs(StudyCase(None, 0.0, seed, "coulomb", DURATION_S))
        tester = _tester(train, rng=np.random.default_rng(seed))
        shape = tester.best_shape(effect(name)) if effect(name).shape is not None else None
        result = tester.evaluate(effect(name), shape)
        passed.append(result.passes)
        assert result.gain < 0.02
    assert sum(passed) == 0


@pytest.mark.parametrize("seed", range(3))
def test_pre_sliding_misfit_after_reversals_is_not_a_ripple(seed):
    # a transient after every reversal that the Coulomb base lacks: deterministic, the size of the noise,
    # tied to where the axis reverses, not periodic in position
    train, _, _ = case_logs(StudyCase(None, 0.0, seed, "coulomb", DURATION_S))
    travel, direction = _since_reversal_mm(train)
    misfit = -0.15 * direction * np.exp(-travel / 0.3)
    tester = _tester(train, misfit, rng=np.random.default_rng(seed))
    for name in ("position_periodic_force", "position_periodic_friction"):
        result = tester.evaluate(effect(name), tester.best_shape(effect(name)))
        assert not result.passes, (name, result.to_dict())


def test_a_ripple_in_one_direction_only_does_not_carry_over():
    train, _, _ = case_logs(StudyCase(None, 0.0, 2, "coulomb", DURATION_S))
    artefact = 0.1 * np.sin(2.0 * np.pi * train.position / 5.0) * (train.velocity > 0.0)
    result = _tester(train, artefact, rng=np.random.default_rng(2)).evaluate(effect("position_periodic_force"), 5.0)
    assert not result.passes
    assert any("does not predict the other" in reason for reason in result.reasons)


def test_a_velocity_only_misfit_is_spanned_by_the_velocity_curve():
    train, _, _ = case_logs(StudyCase(None, 0.0, 3, "coulomb", DURATION_S))
    excess = 0.1 * np.exp(-(np.abs(train.velocity) / 4.0) ** 2) * np.sign(train.velocity)  # Gaussian Stribeck
    tester = _tester(train, excess, rng=np.random.default_rng(3))
    assert tester.evaluate(effect("velocity_curve")).passes
    assert not _tester(train, rng=np.random.default_rng(3)).evaluate(effect("velocity_curve")).passes


def _family_tester(runs, seed) -> HeldOutTest:
    """Held-out test on the GMS model fitted to ``runs``."""
    model = AugmentedModel(base=GMSModel()).fit(runs)
    part = model.linear_part(runs)
    target = np.concatenate([run.effort for run in runs])
    return HeldOutTest(runs, part.columns, target - part.fixed, model.context, rng=np.random.default_rng(seed)), model


def test_presliding_hysteresis_of_another_shape_is_spanned_by_the_presliding_refinement():
    # the family's Bouc-Wen pre-sliding is not the GMS elements' shape: the play-operator bank spans the
    # difference where a block's motion is like the others' (a block with speeds the others lack can fail)
    passes, gains, curve_gains = 0, [], []
    for seed in (7, 8, 9, 10):
        train = prepare(family_logs(FamilyCase(None, 0.0, seed, 20.0))[0])
        tester, model = _family_tester(train, seed)
        result = tester.evaluate(effect("presliding_hysteresis"))
        passes += result.passes
        gains.append(result.gain)
        curve_gains.append(tester.evaluate(effect("velocity_curve")).gain)
    assert passes >= 2 and np.median(gains) > 0.05 and np.median(gains) > 3.0 * max(np.median(curve_gains), 0.0)
    # the same motion with the current the GMS law itself gives, plus white noise: nothing to refine
    rng = np.random.default_rng(8)
    own = [run.replace(effort=model.predict(run) + rng.normal(0.0, 0.02, len(run))) for run in train]
    assert not _family_tester(own, 10)[0].evaluate(effect("presliding_hysteresis")).passes
