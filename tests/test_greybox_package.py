"""The top-level package: its public names, AxisLog loaded on first use."""

from __future__ import annotations

import subprocess
import sys

import pytest

import greybox
from greybox.data.log import AxisLog


def test_the_public_names_are_there_and_axislog_is_the_data_layers():
    from greybox import AxisLog as named

    assert named is AxisLog and greybox.AxisLog is AxisLog
    assert set(greybox.__all__) <= set(dir(greybox))


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'NoSuchThing'"):
        greybox.NoSuchThing  # noqa: B018


def test_importing_greybox_loads_no_numpy():
    code = "import sys, greybox; print('numpy' in sys.modules, 'greybox.data.log' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]
