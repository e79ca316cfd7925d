"""The twin runs an NC program file and writes its log (what ``greybox synth --plan`` calls)."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.io import read_log
from greybox.errors import GreyboxError
from greybox.nc.blocks import Dwell, Move, Program
from greybox.nc.gcode import write_program
from greybox.twin.datasets import ESSENTIAL_TRUTH_CHANNELS
from greybox.twin.nc_run import synthesize_program


def test_a_program_file_becomes_one_log_of_its_axis_and_is_not_overwritten(tmp_path):
    program = tmp_path / "strokes.mpf"
    program.write_text(write_program(Program("Y", (Move(-300.0, None), Move(-280.0, 600.0), Dwell(0.5),
                                                   Move(-300.0, 1200.0)))))
    ran = synthesize_program(program, 5, tmp_path / "out", truth_channels=ESSENTIAL_TRUTH_CHANNELS)
    assert ran.path == tmp_path / "out" / "Y_strokes.mcap" and len(ran.program.blocks) == 4
    log = read_log(ran.path)
    assert log.axis == "Y" and len(log) == len(ran.log)
    assert log.position.min() == pytest.approx(-300.0, abs=0.01)
    assert log.position.max() == pytest.approx(-280.0, abs=0.01)
    assert np.abs(log.velocity).max() == pytest.approx(1200.0 / 60.0, rel=0.02)  # the faster stroke's feed [mm/s]
    before = ran.path.read_bytes()
    with pytest.raises(GreyboxError, match="Y_strokes.mcap: file exists"):
        synthesize_program(program, 6, tmp_path / "out")
    assert ran.path.read_bytes() == before
    again = synthesize_program(program, 5, tmp_path / "out", force=True, truth_channels=ESSENTIAL_TRUTH_CHANNELS)
    assert again.path.read_bytes() == before  # same seed, same file
