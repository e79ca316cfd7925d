"""Model choice by held-out runs (greybox.identify.selection)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from axis_dev_data import axis_dev
from selection_runs import coulomb_run, score
from sklearn.base import BaseEstimator, clone

from greybox.errors import GreyboxError, ParameterError
from greybox.identify.selection import (
    EXPLODING_FACTOR,
    RACE_FACTOR,
    CandidateScore,
    check_selection_record,
    choose,
    held_out_folds,
    lead_fold,
    score_candidates,
    selection_record,
    shared_stages,
    speed_fold,
)
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel


class _Memoriser(BaseEstimator):
    """Returns the effort of every run it was fitted on exactly, and nothing (zero) for a run it has not seen."""

    def fit(self, runs):
        self.seen_ = {run.velocity.tobytes(): run.effort for run in runs}
        return self

    @property
    def n_params(self):
        return sum(effort.size for effort in self.seen_.values())

    def predict(self, runs):
        runs = runs if isinstance(runs, list) else [runs]
        return np.concatenate([self.seen_.get(run.velocity.tobytes(), np.zeros(len(run))) for run in runs])


def test_leave_one_group_out_holds_each_file_out_once():
    runs = [coulomb_run(s, 2.0) for s in range(4)]
    groups = ["a.csv", "a.csv", "b.csv", "c.csv"]
    folds = held_out_folds(runs, groups)
    assert [fold.name for fold in folds] == ["a.csv", "b.csv", "c.csv"]
    for fold, held in zip(folds, ([0, 1], [2], [3])):
        assert [id(run) for run in fold.test] == [id(runs[i]) for i in held]
        assert [id(run) for run in fold.train] == [id(runs[i]) for i in range(4) if i not in held]


def test_one_file_is_cut_into_contiguous_stretches_that_cover_it():
    run = coulomb_run(0, 6.0)
    folds = held_out_folds([run], ["only.csv"], n_blocks=3)
    assert len(folds) == 3
    held = np.concatenate([fold.test[0].time for fold in folds])
    np.testing.assert_array_equal(held, run.time)  # every sample held out exactly once, in order
    for fold in folds:
        assert len(fold.train) == 2
        assert sum(len(r) for r in fold.train) + len(fold.test[0]) == len(run)


def test_too_short_a_single_file_is_one_clear_error():
    with pytest.raises(GreyboxError, match="too short to hold out"):
        held_out_folds([coulomb_run(0, 1.0)], ["short.csv"])
    with pytest.raises(GreyboxError, match="one group per run"):
        held_out_folds([coulomb_run(0, 1.0)], ["a", "b"])


def test_the_choice_follows_held_out_error_not_training_error():
    runs = [coulomb_run(s) for s in range(3)]
    np.testing.assert_array_equal(_Memoriser().fit(runs).predict(runs), np.concatenate([r.effort for r in runs]))
    folds = held_out_folds(runs, ["r0", "r1", "r2"])
    scores = score_candidates([("memoriser", _Memoriser()), ("coulomb", CoulombModel())], folds, race=False)
    assert [s.label for s in scores] == ["memoriser", "coulomb"]
    assert scores[1].re < scores[0].re
    assert choose(scores) == 1


def test_one_standard_error_rule_prefers_the_simpler_model():
    best = score("complex", [10.0, 12.0, 14.0], 20)  # mean 12, SE 1.15
    close = score("simple", [12.0, 13.0, 13.9], 4)  # mean 12.97 within one SE
    far = score("simplest", [15.0, 16.0, 17.0], 2)
    assert choose([best, close, far]) == 1
    assert choose([best, far]) == 0  # nothing simpler lies within one SE
    failed = score("failed", [1.0, 1.0, 1.0], 1, error="fold x: diverged")
    assert math.isnan(failed.re)
    assert choose([failed, best]) == 1
    with pytest.raises(GreyboxError, match="no candidate model could be scored"):
        choose([failed])


def test_a_hostile_selection_record_is_refused_on_load(tmp_path):
    runs = [coulomb_run(s, 3.0) for s in range(2)]
    model = CoulombModel().fit(runs)
    scores = [score("coulomb", [1.0, 2.0], 4)]
    good = selection_record(scores, held_out_folds(runs, ["a", "b"]), 0)
    check_selection_record(good)
    for broken in ({**good, "chosen": "other"}, {**good, "candidates": []}, {**good, "extra": 1},
                   {**good, "candidates": [{**good["candidates"][0], "re": -1.0}]},
                   {**good, "candidates": [{**good["candidates"][0], "n_params": True}]}):
        with pytest.raises(ParameterError, match="selection_"):
            check_selection_record(broken)
        model.selection_ = broken
        path = save_model(model, tmp_path / "hostile.gbm", overwrite=True)
        with pytest.raises(GreyboxError, match="hostile.gbm: invalid CoulombModel.*selection_"):
            load_model(path)


class _Runaway(BaseEstimator):
    """A Coulomb model whose prediction runs away: thirty times the fitted one (a blown-up identification)."""

    def fit(self, runs):
        self.model_ = CoulombModel(fit_offset=True).fit(runs)
        return self

    @property
    def n_params(self):
        return self.model_.n_params + 1

    def predict(self, runs):
        return 30.0 * self.model_.predict(runs)


def test_an_exploding_fold_disqualifies_a_candidate_with_a_note():
    runs = [axis_dev("aircut_A"), axis_dev("aircut_C")]
    folds = held_out_folds(runs, ["aircut_A.csv", "aircut_C.csv"])
    scores = score_candidates([("coulomb:offset", CoulombModel(fit_offset=True)), ("runaway", _Runaway())], folds)
    floors = [fold.zero_re() for fold in folds]
    assert all(100.0 <= floor < 200.0 for floor in floors)  # a current that changes sign
    coulomb, runaway = scores
    assert coulomb.error is None and all(re < EXPLODING_FACTOR * f for re, f in zip(coulomb.fold_re, floors))
    assert runaway.error is not None and "exploded" in runaway.error and "predicting zero" in runaway.error
    assert math.isnan(runaway.re) and len(runaway.fold_re) == 1  # out, not averaged, its figure kept
    assert runaway.error.startswith(folds[0].name)  # out on the lead fold: not fitted on the other
    assert choose(scores) == 0
    record = selection_record(scores, folds, 0)
    check_selection_record(record)


def test_speed_fold_is_the_one_holding_out_faster_runs():
    slow, fast, other = coulomb_run(2), coulomb_run(1), coulomb_run(3)  # 99th percentiles 22, 54, 21 mm/s
    folds = held_out_folds([slow, fast, other], ["slow.csv", "fast.csv", "other.csv"])
    assert speed_fold(folds) == 1
    same = held_out_folds([slow, other], ["a.csv", "b.csv"])
    assert speed_fold(same) is None  # runs of one speed: no fold tests speed


def test_a_choice_that_does_not_carry_to_speed_loses_to_the_simplest():
    # fold 0 holds out the fastest run: the complex candidate wins the mean but predicts that fold worse
    simplest = score("coulomb:offset", [20.0, 14.0, 14.0, 14.0], 4)  # mean 15.5, SE 1.5
    complex_ = score("lugre:asymmetric", [22.0, 8.0, 8.0, 8.0], 9)  # mean 11.5, SE 3.5
    middle = score("stribeck:offset", [21.0, 9.0, 9.0, 9.0], 6)  # mean 12, SE 3
    assert choose([simplest, complex_]) == 1  # without the speed rule: the lowest mean, the simplest beyond one SE
    assert choose([simplest, complex_], speed=0) == 0  # 22 > 20 + 1.5
    assert choose([simplest, complex_, middle], speed=0) == 2  # 21 <= 21.5


#: Fits of ``_Scaled`` models: (factors, runs) per fit (the folds run in this process).
_FITS = []


class _Scaled(BaseEstimator):
    """A Coulomb model whose prediction of a run is scaled by ``factors.get(run.source, 1)``; with a ``stage``,
    a two-stage model whose first stage is that model (its fit frozen, nothing fitted after it)."""

    def __init__(self, factors=None, stage=None):
        self.factors = factors
        self.stage = stage

    def first_stage(self):
        return None if self.stage is None else clone(self.stage)

    def fit(self, runs):
        _FITS.append((self.factors, len(runs)))
        self.model_ = CoulombModel(fit_offset=True).fit(runs)
        return self

    def fit_staged(self, runs, *, first_stage):
        self.model_ = first_stage.model_
        return self

    @property
    def n_params(self):
        return 4

    def predict(self, runs):
        runs = runs if isinstance(runs, list) else [runs]
        return np.concatenate([self.model_.predict(run) * (self.factors or {}).get(run.source, 1.0) for run in runs])


def _three_runs():
    """Three runs of about one speed (no fold tests speed: the lead fold is the first)."""
    runs = [coulomb_run(s, noise=0.2) for s in (2, 3, 7)]
    return runs, held_out_folds(runs, [run.source for run in runs])


def test_a_candidate_far_behind_on_the_lead_fold_is_not_fitted_on_the_others():
    runs, folds = _three_runs()
    assert lead_fold(folds) == 0  # no fold tests speed: the first
    behind = _Scaled(factors={runs[0].source: 2.0})  # far behind on the lead fold only
    _FITS.clear()
    scores = score_candidates([("coulomb", CoulombModel(fit_offset=True)), ("behind", behind)], folds)
    assert len(_FITS) == 1 and scores[1].raced and "raced out" in scores[1].error
    assert len(scores[1].fold_re) == 1 and scores[1].fold_re[0] > RACE_FACTOR * scores[0].fold_re[0]
    everything = score_candidates([("coulomb", CoulombModel(fit_offset=True)), ("behind", behind)], folds,
                                  race=False)
    assert everything[1].error is None and len(everything[1].fold_re) == 3
    assert choose(scores) == choose(everything) == 0


def test_racing_keeps_a_candidate_behind_on_the_lead_fold_that_wins_the_mean():
    # behind by less than RACE_FACTOR on the lead fold, better on the two others: the best on the mean. A rule
    # that dropped every candidate behind on the lead fold would lose it.
    runs = [coulomb_run(s) for s in (2, 3, 7)]
    folds = held_out_folds(runs, [run.source for run in runs])
    high = _Scaled(factors={run.source: 1.2 for run in runs})  # a fifth too high on every run
    mixed = _Scaled(factors={runs[0].source: 1.25})  # worse than that on the lead fold, right on the others
    scores = score_candidates([("high", high), ("mixed", mixed)], folds)
    assert scores[1].error is None and len(scores[1].fold_re) == 3
    assert scores[0].fold_re[0] < scores[1].fold_re[0] < RACE_FACTOR * scores[0].fold_re[0]
    assert scores[1].re < scores[0].re - scores[1].re_se
    assert choose(scores) == 1


def test_the_lead_fold_is_the_one_that_tests_speed():
    slow, fast, other = coulomb_run(2), coulomb_run(1), coulomb_run(3)
    folds = held_out_folds([slow, fast, other], ["slow.csv", "fast.csv", "other.csv"])
    assert lead_fold(folds) == speed_fold(folds) == 1


def test_a_two_stage_candidate_freezes_the_fit_of_the_candidate_that_is_its_first_stage():
    runs, folds = _three_runs()
    stage = _Scaled()
    two = _Scaled(stage=stage)
    assert shared_stages([stage, two, _Scaled(factors={"x": 3.0})]) == [None, 0, None]
    _FITS.clear()
    shared = score_candidates([("stage", stage), ("two", two)], folds)
    assert _FITS == [(None, 2)] * 3  # the stage, once per fold on its two training runs; the second never fits
    alone = score_candidates([("two", two)], folds)  # no candidate is its stage: it fits its own
    assert shared[1].fold_re == alone[0].fold_re == shared[0].fold_re


def test_a_raced_out_simplest_candidate_sets_no_speed_ceiling_on_the_others():
    # the speed fold is the lead fold: coulomb was raced out there, beyond 1.5 times the best, so every candidate
    # left beats it on the fastest runs; the next simplest one (lugre) must not take its place as the ceiling
    raced = CandidateScore("coulomb:offset", fold_re=[30.0], fold_rmse=[0.3], n_params=4, error="raced out",
                           raced=True)
    lugre = score("lugre:offset", [10.0, 10.0, 10.0], 8)
    gms = score("gms:asymmetric", [10.5, 8.0, 8.0], 14)  # mean 8.83 +- 0.83: the best, beyond lugre's reach
    assert choose([raced, lugre, gms], speed=0) == 2
    failed = CandidateScore("coulomb:offset", error="fold x: diverged", n_params=4)  # not raced: no figure at all
    assert choose([failed, lugre, gms], speed=0) == 1  # the simplest scored one sets the ceiling, as before
