"""The pages' examples run as printed: in a folder that links the repository's data, failures in one line."""

from __future__ import annotations

import pytest

from studies.as_printed import reader_folder, run_greybox
from studies.records import ROOT


def test_the_reader_folder_links_data_and_examples_and_is_removed_afterwards():
    with reader_folder() as folder:
        assert (folder / "data" / "X_A.mcap").is_file() and (folder / "examples" / "axis_x.toml").is_file()
        assert (folder / "data").resolve() == (ROOT / "data").resolve()
    assert not folder.exists() and (ROOT / "data" / "X_A.mcap").is_file()  # the links go, the data stay


def test_a_failing_command_stops_with_one_line_naming_it():
    with reader_folder() as folder, pytest.raises(SystemExit) as stopped:
        run_greybox(folder, "info", "missing.gbm")
    message = str(stopped.value)
    assert message.startswith("error: greybox info missing.gbm failed (2): ") and "missing.gbm" in message
    assert "\n" not in message and "Traceback" not in message
