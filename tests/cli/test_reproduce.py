"""``greybox reproduce``'s progress display: a fit's warning from a worker process is a note in command-line words."""

from __future__ import annotations

import pickle

from greybox.cli.reproduce import _Elapsed
from greybox.errors import Setting, SettingWarning


def _bound_warning() -> SettingWarning:
    return SettingWarning("GMS-SVR hyperparameters: C = 155 ended at the end of its search interval; the optimum "
                          "may lie outside (widen it with ", Setting("bounds", keys=("C",)), ")")


def test_a_warning_keeps_the_settings_it_names_across_processes():
    warning = pickle.loads(pickle.dumps(_bound_warning()))  # as the worker's queue carries it
    assert [type(part) for part in warning.parts] == [str, Setting, str]
    assert str(warning) == str(_bound_warning())


def test_a_workers_warning_is_printed_as_a_note_naming_the_option(capsys):
    progress = _Elapsed()
    progress("axis X, experiment 2: gmssvr in 20.0 s, test RE 9.90 %")
    progress(pickle.loads(pickle.dumps(_bound_warning())))
    first, note = capsys.readouterr().err.splitlines()
    assert first.endswith("axis X, experiment 2: gmssvr in 20.0 s, test RE 9.90 %")
    assert note.split("] ", 1)[1].startswith("  note: GMS-SVR hyperparameters: C = 155 ended")
    assert "--set bounds='{\"C\": [LOW, HIGH]}' of greybox train" in note
    assert "bounds=)" not in note
