"""TDMS logs through npTDMS: group and channel mapping, time from waveform properties or a time channel."""

from __future__ import annotations

import numpy as np
import pytest
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

import greybox.cli as cli
from greybox.data.io import read_log
from greybox.errors import LogError
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def log():
    return make_dataset("X", "A", seed=61, duration_s=4)


def _write(path, groups, waveform: float | None = None, start: float = 0.0):
    """``groups``: {group: {channel: values}}; with ``waveform`` every channel carries LabVIEW's waveform timing."""
    props = {"wf_increment": waveform, "wf_start_offset": start} if waveform else {}
    objects = [RootObject(properties={"title": "greybox test"})]
    for group, channels in groups.items():
        objects.append(GroupObject(group))
        objects += [ChannelObject(group, name, np.asarray(values), properties=props)
                    for name, values in channels.items()]
    with TdmsWriter(path) as writer:
        writer.write_segment(objects)


def test_waveform_timing_and_a_channel_mapping(tmp_path, log):
    path = tmp_path / "crio.tdms"
    _write(path, {"X1": {"X1_Pos": log.position / 1000.0, "X1_Iq": log.effort}}, waveform=0.002, start=1.5)
    read = read_log(path, columns={"position_m": "X1_Pos", "current_A": "X1_Iq"})
    np.testing.assert_allclose(read.time, 1.5 + log.time, atol=1e-9)
    np.testing.assert_allclose(read.position, log.position, rtol=1e-12)
    np.testing.assert_array_equal(read.effort, log.effort)


def test_a_time_channel_and_conventional_names_and_a_choice_of_group(tmp_path, log, capsys):
    path = tmp_path / "machine.tdms"
    channels = {"time_s": log.time, "position_mm": log.position, "current_A": log.effort}
    _write(path, {"X": channels, "Y": {**channels, "position_mm": -log.position}})
    with pytest.raises(LogError, match="2 TDMS groups \\(X, Y\\); choose one with --topic GROUP"):
        read_log(path)
    read = read_log(path, topic="Y")
    np.testing.assert_array_equal(read.position, -log.position)
    np.testing.assert_array_equal(read.time, log.time)
    assert cli.main(["info", str(path), "--topic", "Z"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "no TDMS group 'Z'; the file holds X, Y" in err
    assert cli.main(["info", str(path), "--topic", "X"]) == 0


def test_corrupt_and_timeless_files_are_one_line_errors(tmp_path, log, capsys):
    bad = tmp_path / "bad.tdms"
    bad.write_bytes(b"TDSm" + bytes(60))
    assert cli.main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "bad.tdms" in err and "Traceback" not in err
    timeless = tmp_path / "timeless.tdms"
    _write(timeless, {"X": {"position_mm": log.position, "current_A": log.effort}})
    assert len(read_log(timeless, sample_time=0.002)) == len(log)
    with pytest.raises(LogError):
        read_log(timeless)
