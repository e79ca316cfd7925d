"""``greybox synth`` and :func:`greybox.twin.synthesize`: files, refusal to overwrite, errors."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.cli import main
from greybox.data.io import read_log
from greybox.errors import GreyboxError
from greybox.twin import ESSENTIAL_TRUTH_CHANNELS, make_dataset, synthesize
from greybox.twin.family import draw_member, member_dataset


def test_synth_writes_one_file_per_dataset(tmp_path, capsys):
    out = tmp_path / "twin"
    status = main(["synth", "--axis", "X", "Y", "--out", str(out), "--seed", "3", "--datasets", "A", "P",
                   "--duration", "10", "--effect", "position_periodic_force", "--strength", "0.15",
                   "--effect-param", "period_mm=5", "--cutting"])
    assert status == 0
    assert sorted(p.name for p in out.iterdir()) == ["X_A.mcap", "X_P.mcap", "Y_A.mcap", "Y_P.mcap"]
    lines = [line for line in capsys.readouterr().out.strip().splitlines() if not line.startswith("note:")]
    assert len(lines) == 4 and lines[0].startswith("X_A:") and "noise floor" in lines[0]
    log = read_log(out / "Y_A.mcap")
    expected = make_dataset("Y", "A", seed=3, duration_s=10.0, effect="position_periodic_force",
                            effect_strength=0.15, effect_params={"period_mm": 5.0}, cutting=True)
    assert log.axis == "Y" and log.dataset == "A" and log.attrs["seed"] == 3
    assert log.attrs["effect"] == {"name": "position_periodic_force", "strength_A": 0.15, "period_mm": 5.0,
                                   "phase_rad": 0.0}
    np.testing.assert_array_equal(log.current, expected.current)
    np.testing.assert_array_equal(log.position, expected.position)
    np.testing.assert_allclose(log.time, expected.time, atol=1e-9)
    for name in expected.extras:
        np.testing.assert_allclose(log.extras[name], expected.extras[name], atol=0.5e-6 + 1e-12)


def test_synth_refuses_to_overwrite_without_force(tmp_path, capsys):
    args = ["synth", "--axis", "X", "--out", str(tmp_path), "--seed", "1", "--datasets", "D", "A", "--duration", "4"]
    target = tmp_path / "X_A.mcap"
    target.write_bytes(b"user data")
    assert main(args) == 2
    error = capsys.readouterr().err
    assert "X_A.mcap" in error and "--force" in error and "exists" in error
    assert target.read_bytes() == b"user data"
    assert not (tmp_path / "X_D.mcap").exists()  # nothing written at all
    assert main(args + ["--force"]) == 0
    assert read_log(target).dataset == "A"


@pytest.mark.parametrize("args, message", [
    (["--axis", "Z"], "unknown axis 'Z'"),
    (["--axis", "X", "--datasets", "A", "Q"], "unknown dataset 'Q'"),
    (["--axis", "X", "--effect", "cogging"], "unknown hidden effect 'cogging'"),
    (["--axis", "X", "--strength", "0.1"], "need --effect"),
    (["--axis", "X", "--effect", "thermal_drift", "--effect-param", "tau=2"], "no parameter 'tau'"),
    (["--axis", "X", "--effect", "thermal_drift", "--effect-param", "time_constant_s=fast"], "not a number"),
    (["--axis", "X", "--seed", "-2"], "argument --seed: must be an integer from 0 to 4294967295, got -2"),
    (["--axis", "X", "--duration", "0"], "argument --duration: must be a positive number of seconds, got 0"),
    ([], "give the axes to simulate (--axis X, Y, C or several) or --family N"),
    (["--family", "2", "--axis", "X"], "--family draws each axis, its noise and sensors; --axis does not apply"),
    (["--family", "2", "--noise-std", "0.2"], "--noise-std does not apply"),
    (["--family", "0"], "argument --family: must be a positive integer, got 0"),
    (["--family", "1", "--datasets", "A", "--duration", "1"], "dataset A needs at least"),
])
def test_synth_errors_are_one_line_messages(tmp_path, capsys, args, message):
    argv = ["synth", "--out", str(tmp_path / "o"), "--seed", "0", *args]
    try:
        status = main(argv)
    except SystemExit as stop:  # values out of range are refused by the option parser
        status = stop.code
    assert status == 2
    error = capsys.readouterr().err
    assert message in error and "Traceback" not in error
    assert not any((tmp_path / "o").glob("*.mcap"))


def test_synthesize_keeps_only_the_requested_truth_channels(tmp_path):
    paths = synthesize("X", 5, tmp_path, ["D"], truth_channels=ESSENTIAL_TRUTH_CHANNELS, cutting=True)
    log = read_log(paths[0])
    assert set(log.extras) == {"truth_current_A", "truth_process_A", "truth_process_force_N"}
    with pytest.raises(GreyboxError, match="unknown truth channel"):
        synthesize("X", 5, tmp_path / "b", ["D"], truth_channels=["truth_speed_A"])
    assert not (tmp_path / "b").exists()


def test_synth_family_writes_each_member_with_its_own_law_and_a_catalogue(tmp_path, capsys):
    out = tmp_path / "family"
    assert main(["synth", "--family", "4", "--seed", "9", "--out", str(out), "--datasets", "C", "--duration", "4",
                 "--cutting", "--truth", "essential"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert [line.split(":")[0] for line in lines[:4]] == [f"member_{i:03d}" for i in range(4)]
    assert "family.json" in lines[-1]
    for index in range(4):
        member = draw_member(index, 9)
        log = read_log(out / member.name / f"{member.axis}_C.mcap")
        assert log.attrs["family_member"]["law"] == member.law
        expected = member_dataset(member, "C", duration_s=4.0, cutting=True)
        np.testing.assert_array_equal(log.current, expected.current)
        assert set(log.extras) == {"truth_current_A", "truth_process_A", "truth_process_force_N"}


def test_synth_parts_writes_a_series_with_its_events_and_truth(tmp_path, capsys):
    import json

    program = tmp_path / "part.mpf"
    program.write_text("G0 X-226\nG1 X-272 F600\nG1 X-226 F2000\n")
    args = ["synth", "--parts", "2", "--plan", str(program), "--out", str(tmp_path / "o"), "--seed", "1",
            "--breakage", "2:3.5", "--loading", "0.5", "--part-layout", "series", "--warmup-drop", "0.3"]
    assert main(args) == 0
    assert "part series of 2 parts on X" in capsys.readouterr().out
    truth = json.loads((tmp_path / "o" / "X_parts.json").read_text())
    assert truth["warm_up"]["drop"] == 0.3 and truth["events"][0]["kind"] == "breakage"
    series = read_log(tmp_path / "o" / "X_series.mcap")
    second = series.extras["part"] == 2
    assert np.abs(series.extras["truth_process_A"][second]).max() > 0.0
    assert not any((tmp_path / "o").glob("X_part0*.mcap"))  # series layout only
    assert main(args) == 2 and "exists" in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (["--parts", "2", "--breakage", "2"], "--breakage '2': expected PART:SECONDS"),
    (["--parts", "2", "--pause", "0:10"], "--pause '0:10'"),
    (["--parts", "2", "--axis", "X", "Y"], "--parts runs one axis"),
    (["--parts", "2", "--family", "2"], "--family does not apply"),
    (["--axis", "X", "--wear", "2"], "--wear needs --parts N"),
    (["--parts", "2", "--warmup-drop", "1"], "argument --warmup-drop"),
])
def test_synth_parts_errors_are_one_line_messages(tmp_path, capsys, args, message):
    try:
        status = main(["synth", "--out", str(tmp_path / "o"), "--seed", "0", *args])
    except SystemExit as stop:
        status = stop.code
    assert status == 2
    error = capsys.readouterr().err
    assert message in error and "Traceback" not in error
    assert not (tmp_path / "o").exists()
