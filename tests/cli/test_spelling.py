"""Messages of the command speak the command line: settings spelt as options from one table, warnings as notes."""

from __future__ import annotations

import argparse
import warnings

import pytest

import greybox.cli as cli
from greybox.cli._spelling import OPTIONS, command_notes, error_message, spell, spelt
from greybox.data.io import write_log
from greybox.errors import GreyboxError, LogError, ParameterError, Setting, SettingWarning
from greybox.models.files import load_model
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def air_cut(tmp_path_factory):
    """A 4 s air cut of the synthetic X axis (MCAP)."""
    path = tmp_path_factory.mktemp("notes") / "X_A.mcap"
    write_log(make_dataset("X", "A", seed=2, duration_s=4.0), path)
    return path


def _main(capsys, *argv):
    status = cli.main([str(arg) for arg in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_refused_combination_names_the_options(air_cut, tmp_path, capsys):
    out = tmp_path / "c.gbm"
    status, _, err = _main(capsys, "train", "--model", "coulomb", "--offset", "--asymmetric", "--train", air_cut,
                           "--out", out)
    assert status == 2 and not out.exists()
    (line,) = err.splitlines()
    assert line.startswith("greybox train: error: ")
    assert "--offset" in line and "--asymmetric" in line
    assert "fit_offset" not in line and "=True" not in line and "asymmetric=" not in line


def test_seed_out_of_range_through_set_names_the_seed_option(air_cut, tmp_path, capsys):
    status, _, err = _main(capsys, "train", "--model", "gms", "--set", "random_state=-1", "--train", air_cut,
                           "--out", tmp_path / "g.gbm")
    assert status == 2
    (line,) = err.splitlines()
    assert "--model-seed" in line and "random_state" not in line


def test_search_at_its_bound_is_one_note_naming_set_bounds(air_cut, tmp_path, capsys):
    """An SVR search for C in an interval far too low ends at its upper end: a note, not a UserWarning."""
    out = tmp_path / "svr.gbm"
    status, printed, err = _main(capsys, "train", "--model", "svr", "--train", air_cut, "--out", out, "--quiet",
                                 "--set", "n_calls=6", "--set", "n_subset=600", "--set", "epsilon=0.01",
                                 "--set", "gamma=1", "--set", "velocity_weight=1",
                                 "--set", 'bounds={"C": [1e-5, 1e-4]}')
    assert status == 0, err
    assert load_model(out).at_bounds_ == ["C"]  # the search did end at its bound
    notes = [line for line in err.splitlines() if line]
    assert len(notes) == 1, err
    assert notes[0].startswith("note: ") and "C = 0.0001" in notes[0]
    assert "--set bounds='{\"C\": [LOW, HIGH]}'" in notes[0]
    assert "UserWarning" not in err and ".py:" not in err and "bounds=)" not in err
    assert "note:" not in printed


def test_warnings_become_one_note_each_in_command_words(capsys):
    args = argparse.Namespace(command="train", set=[])
    before = warnings.showwarning
    with command_notes(args) as notes:
        for _ in range(3):
            warnings.warn(SettingWarning("gms: use ", Setting("asymmetric", True), "\n  or widen the search with ",
                                         Setting("bounds")), stacklevel=1)
        warnings.warn("overflow encountered in exp", RuntimeWarning, stacklevel=1)
    err = capsys.readouterr().err
    assert err.splitlines() == [
        "note: gms: use --asymmetric or widen the search with --set bounds='{\"NAME\": [LOW, HIGH]}'",
        "note: overflow encountered in exp"]
    assert notes == err.splitlines() and warnings.showwarning is before


def test_error_message_of_a_command_without_set():
    args = argparse.Namespace(command="discover")  # discover offers no --set
    error = ParameterError(Setting("n_starts", assign=False), " must be a positive integer, got 0")
    assert str(error) == "n_starts must be a positive integer, got 0"  # Python's spelling
    assert error_message(error, args) == ("n_starts (--set n_starts=VALUE of greybox train) must be a positive "
                                          "integer, got 0")
    plain = GreyboxError("data/x.csv: column 'position_mm' has NaN\n at t = 1 s")
    assert error_message(plain, args) == "data/x.csv: column 'position_mm' has NaN at t = 1 s"


@pytest.mark.parametrize("setting, python, option", [
    (Setting("asymmetric", True), "asymmetric=True", "--asymmetric"),
    (Setting("fit_offset", False), "fit_offset=False", "no --offset"),
    (Setting("fit_offset", assign=False), "fit_offset", "--offset"),
    (Setting("n_elements", 4), "n_elements=4", "--elements 4"),
    (Setting("n_elements"), "n_elements=", "--elements N"),
    (Setting("random_state", assign=False), "random_state", "--model-seed"),
    (Setting("C", 2.0), "C=2.0", "--set C=2.0"),
    (Setting("max_iter", assign=False), "max_iter", "--set max_iter"),
    (Setting("bounds", keys=("C", "gamma")), "bounds=", "--set bounds='{\"C\": [LOW, HIGH], \"gamma\": [LOW, HIGH]}'"),
    (Setting("columns", {"time_s": ...}), "columns={'time_s': ...}", "--columns time_s=COLUMN"),
    (Setting("columns", {"position_mm": "X1"}), "columns={'position_mm': 'X1'}", "--columns position_mm=X1"),
    (Setting("columns"), "columns=", "--columns NAME=COLUMN"),
    (Setting("sample_time", assign=False), "sample_time", "--sample-time"),
    (Setting("topic"), "topic=", "--topic TOPIC"),
    (Setting("axis", "X"), "axis='X'", "--axis X"),
])
def test_a_setting_is_spelt_in_python_by_the_library_and_as_its_option_by_the_command(setting, python, option):
    assert str(setting) == python
    assert spell(setting) == option


def test_text_around_the_settings_is_kept_as_it_is():
    """No word of the text is rewritten, even one that looks like a keyword: only the Setting parts are."""
    parts = ["RMSE=3 A, gms.n_elements_ = 4; asymmetric Coulomb levels; fit_offset=True; ", Setting("fit_offset", True)]
    assert spelt(parts) == "RMSE=3 A, gms.n_elements_ = 4; asymmetric Coulomb levels; fit_offset=True; --offset"


def test_every_model_option_of_the_commands_is_in_the_one_table():
    from greybox.cli._model_options import MODEL_OPTIONS

    assert {name: OPTIONS[name].flag for _, _, name in MODEL_OPTIONS} == {
        "fit_offset": "--offset", "asymmetric": "--asymmetric", "n_elements": "--elements",
        "random_state": "--model-seed", "inertia": "--inertia"}


def test_a_refused_combination_names_both_settings_in_python_and_both_options_on_the_command_line():
    from greybox.models.friction import CoulombModel

    with pytest.raises(ParameterError) as caught:
        CoulombModel(asymmetric=True, fit_offset=True).fit([])
    assert "choose asymmetric or fit_offset, not both" in str(caught.value)
    message = error_message(caught.value, argparse.Namespace(command="train", set=[]))
    assert "choose --asymmetric or --offset, not both" in message


def test_a_log_error_spells_the_reading_options():
    error = LogError("a.csv", "no time column (map one with ", Setting("columns", {"time_s": ...}), ")")
    assert str(error) == "a.csv: no time column (map one with columns={'time_s': ...})"
    assert error_message(error, argparse.Namespace(command="info")) == (
        "a.csv: no time column (map one with --columns time_s=COLUMN)")


@pytest.mark.parametrize("content, option", [
    ("time_s,position_mm,velocity_mm_s\n0,0,0\n0.002,0,0\n0.004,0,0\n", "--columns NAME=COLUMN"),
    ("time_s,position_mm,current_A\n0,0,0\n0.002,0,0\n0.004,0,0\n", "--sample-time applies"),
])
def test_log_errors_name_the_reading_options(tmp_path, capsys, content, option):
    path = tmp_path / "log.csv"
    path.write_text(content)
    extra = ["--sample-time", "0.002"] if "sample-time" in option else []
    status, _, err = _main(capsys, "info", str(path), *extra)
    assert status == 2 and option in err
    assert "columns=" not in err and "sample_time" not in err


def test_a_velocity_weight_at_its_bound_names_it_in_the_set_bounds_example(capsys):
    args = argparse.Namespace(command="train", set=[])
    with command_notes(args):
        warnings.warn(SettingWarning("SVR hyperparameters: velocity_weight = 9.9e+03 ended at the end of its search "
                                     "interval; the optimum may lie outside (widen it with ",
                                     Setting("bounds", keys=("velocity_weight",)), ")"), stacklevel=1)
    err = capsys.readouterr().err
    assert "--set bounds='{\"velocity_weight\": [LOW, HIGH]}'" in err, err
    assert "SVR hyperparameters: velocity_weight = 9.9e+03 ended" in err  # a reported value stays as it is
