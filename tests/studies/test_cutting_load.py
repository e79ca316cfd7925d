"""The force under load: the twin's process force, the family's axis files and the cutting-under-load study."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.cli import main
from greybox.data.axis_config import read_axis_config
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.reproduce.experiments import QUICK_SETTINGS
from greybox.twin import make_dataset
from greybox.twin.cutting import CuttingSpec
from greybox.twin.drive import AXIS_EFFICIENCIES
from greybox.twin.family import AXIS_FILE, draw_member, member_dataset
from studies.cutting_load import PASSES, TARGET_PCT, cutting_load_markdown, run_member, summarise

#: A validation study's tests (runs of the study, its script, the real data sets): left out of the default
#: run (`pytest -m slow` runs them, as .ci/run does).
pytestmark = pytest.mark.slow

CUT_BOTH_WAYS = CuttingSpec(strength_A=1.0, return_pass=-0.6)


def test_the_x_axis_books_the_screw_losses_in_its_process_current():
    """Opposing stroke: F = eta_d K_0 I; the stroke the force pushes along: F = K_0 I / eta_b."""
    log = make_dataset("X", "D", seed=3, cutting=CUT_BOTH_WAYS)
    current, force, v = (log.extras["truth_process_A"], log.extras["truth_process_force_N"], log.velocity)
    lossless = 1.35 * 2 * math.pi / 0.010  # the twin's motor over the X axis' 10 mm lead [N/A]
    driving, backdriven = (current * v > 0), (current * v < 0)
    assert driving.sum() > 1000 and backdriven.sum() > 1000
    np.testing.assert_allclose(force[driving] / current[driving], AXIS_EFFICIENCIES[0] * lossless, rtol=1e-12)
    np.testing.assert_allclose(force[backdriven] / current[backdriven], lossless / AXIS_EFFICIENCIES[1], rtol=1e-12)
    assert log.attrs["cutting"]["axis_config"]["efficiency_backdriven"] == AXIS_EFFICIENCIES[1]


def test_without_a_return_pass_the_return_stroke_is_an_air_cut_and_the_option_is_checked():
    log = make_dataset("X", "D", seed=3, cutting=CuttingSpec(strength_A=1.0))
    process = log.extras["truth_process_A"]
    assert np.all(process[log.velocity > 0] == 0.0) and np.any(process[log.velocity < 0] != 0.0)
    with pytest.raises(GreyboxError, match="return pass must be in"):
        CuttingSpec(return_pass=-1.5)


@pytest.fixture(scope="module")
def loaded_member():
    """Member 3 of family seed 3 (backlash screw, load gain 0.079) on D, with and without the cut."""
    member = draw_member(3, 3)
    cut, air = prepare([member_dataset(member, "D", cutting=CUT_BOTH_WAYS), member_dataset(member, "D")])
    return member, cut, air


def test_a_perfect_air_cut_model_with_the_member_axis_file_recovers_the_force_of_both_passes(loaded_member):
    """The family books the losses in its friction; the axis file's efficiencies undo them (within g x (1 - d))."""
    member, cut, air = loaded_member
    config = member.plant.axis_config(member.axis)
    gain = member.plant.load_gain
    assert (config.efficiency_driving, config.efficiency_backdriven) == pytest.approx((1 / (1 + gain), 1 - gain))
    process = cut.effort - air.effort  # what a perfect model of the air cut leaves: the same noise cancels
    truth = cut.extras["truth_process_force_N"]
    estimated = config.process_load(process, cut.velocity)
    blind = config.load_constants[0] * process
    for sign in (1.0, -1.0):
        chosen = (truth != 0) & (truth * cut.velocity * sign > 0)
        error = abs(np.mean(estimated[chosen]) / np.mean(truth[chosen]) - 1)
        assert error < gain * 0.5, sign  # the load friction below the law's peak: less than half of g here
        if sign < 0:  # back-driven: one factor is about 2 g too small
            blind_error = abs(np.mean(blind[chosen]) / np.mean(truth[chosen]) - 1)
            assert blind_error > 1.5 * gain > 3 * error


def test_synth_family_writes_each_member_axis_file(tmp_path):
    out = tmp_path / "family"
    status = main(["synth", "--family", "2", "--seed", "3", "--datasets", "C", "--duration", "4", "--cutting",
                   "--cutting-return-pass", "-0.5", "--out", str(out)])
    assert status == 0
    for index in (0, 1):
        member = draw_member(index, 3)
        written = read_axis_config(out / member.name / AXIS_FILE)
        assert written.to_dict() == member.plant.axis_config(member.axis).to_dict()


def test_a_member_of_the_study_reports_both_passes_and_the_axis_file_beats_one_factor_when_back_driven():
    row = run_member(1, 2026, settings=QUICK_SETTINGS, duration_s=20.0)
    assert set(row["models"]) == {"stribeck", "gms", "gmssvr"}
    for calibration in row["models"]["gmssvr"]["interval"].values():
        assert 0.5 < calibration["coverage"] <= 1.0 and calibration["width_N"] > 0
    for name, cell in row["models"].items():
        aware, blind = cell["axis_file"], cell["one_factor"]
        # Driving: the same factor, but for the samples whose noise flips the process current's sign.
        assert aware["driving"]["mean_error_pct"] == pytest.approx(blind["driving"]["mean_error_pct"], abs=0.1), name
        assert aware["driving"]["true_mean_N"] < 0 and aware["back-driven"]["true_mean_N"] < 0
        # One factor makes a back-driven force eta_d eta_b times the direction-aware one (about 1 - 2 g).
        product = row["efficiencies"][0] * row["efficiencies"][1]
        assert blind["back-driven"]["estimated_mean_N"] == pytest.approx(
            product * aware["back-driven"]["estimated_mean_N"], rel=2e-3), name
    gmssvr = row["models"]["gmssvr"]
    assert abs(gmssvr["axis_file"]["back-driven"]["mean_error_pct"]) < abs(
        gmssvr["one_factor"]["back-driven"]["mean_error_pct"])


def _row(index, errors, coverage=0.95):
    cell = {"driving": {"mean_error_pct": errors[0]}, "back-driven": {"mean_error_pct": errors[1]},
            "rms_error_pct": 10.0}
    interval = {"coverage": coverage, "coverage_in_cut": coverage - 0.1, "width_N": 100.0, "width_pct_of_cut": 20.0}
    return {"index": index, "law": "dahl", "axis": "X", "efficiencies": [0.95, 0.95],
            "models": {"gmssvr": {"axis_file": cell, "one_factor": cell,
                                  "interval": {"C": interval, "D air run": {**interval, "coverage": 0.5}}}}}


def test_summary_judges_the_median_absolute_error_of_each_pass():
    rows = [_row(i, (d, b), c) for i, ((d, b), c) in enumerate(zip([(1, -9), (-2, 8), (3, -7), (-6, 1), (0.5, 2)],
                                                                     [0.9, 0.94, 0.95, 0.96, 0.99]))]
    summary = summarise(rows)
    cell = summary["models"]["gmssvr"]["axis_file"]
    assert cell["driving"]["median"] == 2.0 and cell["back-driven"]["median"] == 7.0
    assert summary["met"] == {"driving": True, "back-driven": False}
    assert summary["within_target"] == {"driving": 4, "back-driven": 2}
    assert set(PASSES) == {"driving", "back-driven"} and TARGET_PCT == 5.0
    text = cutting_load_markdown({"family_seed": 1, "first": 0, "members": 5, "workers": 1, "cut_text": "a cut"},
                                 summary, 60.0)
    assert "driving 2.0 % (target <= 5 %: met; 4 of 5 members within it)" in text
    assert "back-driven 7.0 % (target <= 5 %: not met; 2 of 5 members within it)" in text
    assert summary["coverage_met"] == {"C": True, "D air run": False}
    assert ("calibrated on C 95.0 % (target 93-97 %: met), calibrated on D air run 50.0 % (target 93-97 %: "
            "not met)") in text
    assert "| GMS+SVR | C | 95.0 (91.6-97.8) | 85.0 (81.6-87.8) | 100 | 20 |" in text
