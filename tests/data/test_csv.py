"""CSV axis logs: round trip, unit suffixes, column mapping, the UMich CNC-mill files."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.io import read_log, write_log
from greybox.errors import LogError


def test_round_trip_is_exact_and_keeps_metadata(tmp_path, make_log):
    rng = np.random.default_rng(5)
    log = make_log(
        velocity=rng.normal(size=2000),
        extras={"truth_friction_A": rng.normal(size=2000)},
        attrs={"seed": 5, "note": "twin, dataset T"},
    )
    path = tmp_path / "axis.csv"
    write_log(log, path)
    back = read_log(path)
    for name in ("time", "position", "effort", "velocity"):
        assert np.array_equal(getattr(back, name), getattr(log, name)), name
    assert back.acceleration is None
    assert np.array_equal(back.extras["truth_friction_A"], log.extras["truth_friction_A"])
    assert (back.axis, back.dataset, back.effort_unit, back.attrs) == ("X", "T", "A", log.attrs)


def test_unit_suffixes_are_converted(tmp_path):
    path = tmp_path / "units.csv"
    path.write_text(
        "time_ms,position_um,velocity_mm_min,acceleration_m_s2,current_mA,spindle_rpm\n"
        "0,1500,600,0.5,250,3000\n"
        "2,1600,-1200,-1.0,-750,3000\n"
        "4,1700,0,0,0,3000\n"
    )
    log = read_log(path)
    np.testing.assert_allclose(log.time, [0.0, 0.002, 0.004])
    np.testing.assert_allclose(log.position, [1.5, 1.6, 1.7])
    np.testing.assert_allclose(log.velocity, [10.0, -20.0, 0.0])  # 600 mm/min = 10 mm/s
    np.testing.assert_allclose(log.acceleration, [500.0, -1000.0, 0.0])
    np.testing.assert_allclose(log.current, [0.25, -0.75, 0.0])
    assert list(log.extras) == ["spindle_rpm"]


def test_metre_and_metre_per_minute(tmp_path):
    path = tmp_path / "si.csv"
    path.write_text("time_s,position_m,velocity_m_min,force_kN\n0,0.25,0.06,1.5\n0.001,0.26,-0.12,-2\n")
    log = read_log(path)
    np.testing.assert_allclose(log.position, [250.0, 260.0])
    np.testing.assert_allclose(log.velocity, [1.0, -2.0])  # 0.06 m/min = 60 mm / 60 s
    np.testing.assert_allclose(log.effort, [1500.0, -2000.0])
    assert log.effort_unit == "N"


def test_semicolon_and_decimal_comma(tmp_path):
    path = tmp_path / "de.csv"
    path.write_text("# Export SINUMERIK Trace\ntime_s;position_mm;current_A\n0;1,5;-0,25\n0,002;1,75;0,5\n")
    log = read_log(path)
    np.testing.assert_allclose(log.position, [1.5, 1.75])
    np.testing.assert_allclose(log.current, [-0.25, 0.5])


def test_extras_named_with_other_words_are_not_base_channels(tmp_path):
    path = tmp_path / "extras.csv"
    path.write_text("time_s,position_mm,position_setpoint_mm,current_A,current_command_A,mode\n0,1,1.1,2,2.1,run\n0.1,2,2.1,3,3.1,run\n")
    log = read_log(path)
    assert sorted(log.extras) == ["current_command_A", "position_setpoint_mm"]  # text column 'mode' ignored
    np.testing.assert_allclose(log.position, [1.0, 2.0])


def test_column_mapping_and_sample_time(tmp_path):
    path = tmp_path / "cnc.csv"
    path.write_text("POS,IQ,VEL\n10,1,0\n11,2,60\n12,3,120\n")
    log = read_log(path, columns={"position_um": "POS", "current_A": "IQ", "velocity_mm_min": "VEL"}, sample_time=0.5)
    np.testing.assert_allclose(log.time, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(log.position, [0.010, 0.011, 0.012])
    np.testing.assert_allclose(log.velocity, [0.0, 1.0, 2.0])
    assert log.extras == {}


def test_current_and_force_together_need_a_choice(tmp_path):
    path = tmp_path / "both.csv"
    path.write_text("time_s,position_mm,current_A,force_N\n0,1,2,3\n0.1,1,2,3\n")
    with pytest.raises(LogError, match="both a current column"):
        read_log(path)
    log = read_log(path, columns={"force_N": "force_N"})
    assert log.effort_unit == "N" and list(log.extras) == ["current_A"]


def test_time_column_and_sample_time_conflict(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("time_s,position_mm,current_A\n0,1,2\n0.1,1,2\n")
    with pytest.raises(LogError, match="sample_time applies only to files without"):
        read_log(path, sample_time=0.1)


def test_umich_cnc_mill_file_with_column_mapping(real_data):
    path = real_data("UMich_CNC_mill_tool_wear") / "experiment_01.csv"
    log = read_log(
        path,
        columns={"position_mm": "X1_ActualPosition", "velocity_mm_s": "X1_ActualVelocity",
                 "current_A": "X1_CurrentFeedback"},
        sample_time=0.1,
    )
    assert len(log) == 1055  # README: 1055 rows, 105.5 s at 10 Hz
    assert log.sample_time == pytest.approx(0.1)
    assert log.current.min() == pytest.approx(-17.0) and log.current.max() == pytest.approx(19.0)  # README range
    assert "Machining_Process" not in log.extras and "tool_condition" not in log.extras
    assert "Unnamed: 0" not in log.extras
    assert "Y1_CurrentFeedback" in log.extras and len(log.extras) == 44  # 47 numeric columns minus 3 mapped


def test_single_word_suffix_is_taken_as_a_unit_unless_the_quantity_is_mapped(tmp_path):
    path = tmp_path / "setpoint.csv"
    path.write_text("time_s,position_setpoint,POS,current_A\n0,1,1,2\n0.1,2,2,3\n")
    with pytest.raises(LogError, match="unknown unit 'setpoint' in column 'position_setpoint'"):
        read_log(path)
    log = read_log(path, columns={"position_mm": "POS"})
    assert list(log.extras) == ["position_setpoint"]


def test_byte_order_mark_and_comment_lines(tmp_path):
    path = tmp_path / "excel.csv"
    text = "\ufeff# exported 2024-05-02\ntime_s;position_mm;current_A\n0;1,5;2\n0,002;1,5;2\n"
    path.write_bytes(text.encode("utf-8"))
    log = read_log(path)
    np.testing.assert_allclose(log.time, [0.0, 0.002])
    np.testing.assert_allclose(log.position, [1.5, 1.5])
