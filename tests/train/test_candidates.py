"""The candidate models of ``--model auto`` and the choice among them (greybox.train.candidates)."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import motion_log
from selection_runs import coulomb_run, score
from sklearn.base import BaseEstimator

from greybox.errors import GreyboxError
from greybox.identify.selection import CandidateScore, shared_stages
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.train.candidates import build_candidate, choose_model, gap_shown


def test_candidate_specifications_build_the_models_they_name():
    model = build_candidate("gms:asymmetric,elements=3")
    assert isinstance(model, GMSModel) and model.asymmetric and model.n_elements == 3
    model = build_candidate("gmssvr:asymmetric", inertia=0.0)
    assert isinstance(model, GMSSVRModel) and model.gms.asymmetric and model.gms.inertia == 0.0
    model = build_candidate("stribeck:offset,backlash,inertia=0.5")
    assert isinstance(model, BacklashModel) and model.base.fit_offset and model.base.inertia == 0.5
    for bad, message in (("nosuch", "unknown model kind"), ("gms:wobble", "unknown option"),
                         ("gms:elements=x", "needs a number"), ("coulomb:elements=3", "takes no n_elements")):
        with pytest.raises(GreyboxError, match=message):
            build_candidate(bad)


def test_choose_model_refits_the_choice_and_records_the_table(tmp_path):
    runs = [coulomb_run(s) for s in range(3)]
    model = choose_model(runs, ["a.csv", "b.csv", "c.csv"], candidates=["coulomb", "stribeck"])
    record = model.selection_
    assert record["folds"] == ["a.csv", "b.csv", "c.csv"]
    assert [c["label"] for c in record["candidates"]] == ["coulomb", "stribeck"]
    assert all(len(c["fold_re"]) == 3 and c["error"] is None for c in record["candidates"])
    assert isinstance(model, CoulombModel if record["chosen"] == "coulomb" else StribeckModel)
    assert model.n_samples_fit_ == sum(len(r) for r in runs)  # refitted on every run
    path = save_model(model, tmp_path / "auto.gbm")
    assert load_model(path).selection_ == record


def _gap_run(seed: int, width: float, duration: float = 6.0):
    """Coulomb friction behind a gap on a sine: after each reversal no force until the motion crossed ``width`` [mm]."""
    t = np.arange(int(duration / 0.002)) * 0.002
    w = 2 * np.pi * (0.5 + 0.25 * seed)
    velocity = (10.0 + 5.0 * seed) * w * np.cos(w * t)
    log = motion_log(velocity, source=f"gap{seed}.csv")
    effort = np.zeros(len(log))
    direction, start = 0.0, log.position[0]
    for i, (x, v) in enumerate(zip(log.position, velocity)):
        if v != 0.0 and np.sign(v) != direction:
            direction, start = np.sign(v), x
        effort[i] = direction * 1.0 if abs(x - start) >= width else 0.0
    noise = 0.01 * np.random.default_rng(seed).standard_normal(len(log))
    return log.replace(effort=effort + noise)


@pytest.mark.slow
@pytest.mark.parametrize("width, tried", [(3.0, True), (0.0, False)])
def test_dynamic_models_behind_a_gap_are_tried_when_the_runs_show_one(width, tried):
    runs = [_gap_run(s, width, duration=6.0) for s in range(3)]
    model = choose_model(runs, ["a", "b", "c"], candidates=["stribeck:asymmetric", "stribeck:asymmetric,backlash"],
                         gap_candidates=["coulomb:backlash"])
    labels = [c["label"] for c in model.selection_["candidates"]]
    assert ("coulomb:backlash" in labels) is tried
    assert any("a gap:" in note for note in model.selection_["notes"]) is tried


def test_the_folds_fit_each_candidate_with_a_smaller_search_of_the_same_model():
    for spec in ("gms:offset", "gmssvr:asymmetric", "lugre:offset", "stribeck:asymmetric,backlash"):
        full = build_candidate(spec)
        fold = full.held_out_search()
        assert type(fold) is type(full) and fold is not full
        settings, reduced = full.get_params(deep=True), fold.get_params(deep=True)
        changed = {name for name in settings if not isinstance(settings[name], BaseEstimator)
                   and settings[name] != reduced[name]}
        # only the size of the search differs: no option of the candidate
        assert changed and all(name.split("__")[-1] in ("n_starts", "n_calls", "refine") for name in changed)
        assert all(reduced[name] < settings[name] for name in changed)


def test_the_real_two_stage_candidates_share_the_gms_candidate_of_their_own_options():
    labels = ["gms:offset", "gms:asymmetric", "gmssvr:offset", "gmssvr:asymmetric", "lugre:offset"]
    models = [build_candidate(label).held_out_search() for label in labels]
    assert shared_stages(models) == [None, None, 0, 1, None]
    other = [build_candidate("gms:offset,elements=3").held_out_search(), models[2]]
    assert shared_stages(other) == [None, None]  # another GMS: the stage is fitted with its own settings


def test_a_gap_shows_on_the_lead_fold_when_the_model_without_it_was_raced_out():
    without = CandidateScore("stribeck:asymmetric", fold_re=[80.0], fold_rmse=[1.0], n_params=9, error="raced out",
                             raced=True)
    behind = score("stribeck:asymmetric,backlash", [20.0, 50.0, 30.0], 10)  # lead fold 1 here: 50 < 80
    assert gap_shown(without, behind, lead=1) == (80.0, 50.0, " on the lead fold")
    assert gap_shown(without, score("b", [20.0, 90.0, 30.0], 10), lead=1) is None  # worse on the lead fold
    assert gap_shown(score("a", [9.0, 9.0, 9.0], 9), score("b", [8.0, 8.0, 8.0], 10), lead=0)[:2] == (9.0, 8.0)
    assert gap_shown(score("a", [9.0] * 3, 9, error="fold x: diverged"), behind, lead=1) is None
