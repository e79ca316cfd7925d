"""The samples of an OPC UA server's variables: values matched by their source time stamp, in stamp order."""

from __future__ import annotations

import datetime
import math

import pytest

from greybox.live.opcua_samples import SampleAssembler

COLUMNS = ("time_s", "position_mm", "current_A")


def add_sample(assembler, stamp, values, columns=COLUMNS):
    for column, value in zip(columns, values):
        assembler.add(column, stamp, value)


def test_values_of_one_stamp_are_one_sample_and_samples_come_in_stamp_order():
    assembler = SampleAssembler(COLUMNS)
    assembler.add("time_s", 2, 0.004)  # the variables' notifications interleaved, a later stamp first
    add_sample(assembler, 1, (0.002, 1.0, 0.5))
    assert assembler.take() == [(1, {"time_s": [0.002], "position_mm": [1.0], "current_A": [0.5]})]
    assembler.add("current_A", 2, 0.6)
    assert assembler.take() == [] and assembler.pending == 1  # position of stamp 2 still to come
    assembler.add("position_mm", 2, 1.1)
    add_sample(assembler, 3, (0.006, 1.2, 0.7))
    assert assembler.take() == [(2, {"time_s": [0.004, 0.006], "position_mm": [1.1, 1.2], "current_A": [0.6, 0.7]})]
    assert assembler.pending == 0


def test_a_value_that_is_not_a_plain_number_goes_alone_to_the_decoder():
    assembler = SampleAssembler(COLUMNS)
    add_sample(assembler, 1, (0.002, 1.0, 0.5))
    add_sample(assembler, 2, (0.004, 1.1, "overload"))
    add_sample(assembler, 3, (0.006, math.nan, 0.5))
    add_sample(assembler, 4, (0.008, 1.3, 0.5))
    add_sample(assembler, 5, (0.010, 1.4, 0.5))
    taken = assembler.take()
    assert [stamp for stamp, _ in taken] == [1, 2, 3, 4]
    assert taken[1][1]["current_A"] == "overload" and math.isnan(taken[2][1]["position_mm"])
    assert taken[3][1]["time_s"] == [0.008, 0.010]  # the samples after them joined again


def test_a_sample_a_variable_never_completes_is_given_without_it():
    assembler = SampleAssembler(COLUMNS)
    add_sample(assembler, 1, (0.002, 1.0), COLUMNS[:2])  # its current never comes
    assert assembler.take() == []
    add_sample(assembler, 2, (0.004, 1.1, 0.6))  # the current's next stamp: stamp 1 is dead
    assert assembler.take() == [(1, {"time_s": 0.002, "position_mm": 1.0}),
                                (2, {"time_s": [0.004], "position_mm": [1.1], "current_A": [0.6]})]


def test_the_samples_held_are_bounded():
    assembler = SampleAssembler(COLUMNS, max_pending=3)
    for stamp in range(5):  # the current never delivers: nothing can be said dead
        add_sample(assembler, stamp, (0.002 * stamp, 1.0), COLUMNS[:2])
    taken = assembler.take()
    assert [stamp for stamp, _ in taken] == [0, 1] and assembler.pending == 3


def test_a_sample_given_again_is_left_out():
    """After a reconnection the subscription starts with the current values: the last sample again."""
    assembler = SampleAssembler(COLUMNS)
    add_sample(assembler, 1, (0.002, 1.0, 0.5))
    add_sample(assembler, 2, (0.004, 1.1, 0.6))
    assert len(assembler.take()) == 1
    add_sample(assembler, 2, (0.004, 1.1, 0.6))  # the current values again
    add_sample(assembler, 1, (0.002, 1.0, 0.5))
    assert assembler.take() == [] and assembler.pending == 0
    add_sample(assembler, 3, (0.006, 1.2, 0.7))
    assert assembler.take() == [(3, {"time_s": [0.006], "position_mm": [1.2], "current_A": [0.7]})]


def test_stamps_of_one_sample_within_the_tolerance_are_matched():
    """A server stamping each variable as it writes it: stamps a little apart are one sample, the nearest one
    lacking the variable; a value of the next cycle (beyond the tolerance) starts the next sample."""
    assembler = SampleAssembler(COLUMNS, tolerance_s=0.5e-3)
    assembler.add("time_s", 1.0000, 0.002)
    assembler.add("position_mm", 1.0003, 1.0)
    assembler.add("time_s", 1.0021, 0.004)  # the next sample's time, before the first sample's current
    assembler.add("current_A", 0.9998, 0.5)
    assembler.add("position_mm", 1.0019, 1.1)
    assembler.add("current_A", 1.0024, 0.6)
    assert assembler.take() == [(1.0, {"time_s": [0.002, 0.004], "position_mm": [1.0, 1.1], "current_A": [0.5, 0.6]})]
    exact = SampleAssembler(COLUMNS)
    add_sample(exact, 1.0, (0.002, 1.0))
    exact.add("current_A", 1.0003, 0.5)
    assert exact.pending == 2  # without a tolerance, two samples


def test_without_a_time_variable_the_time_is_the_mean_of_the_stamps():
    start = datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc)
    naive = datetime.datetime(2026, 1, 1)  # asyncua's stamps are naive UTC
    assembler = SampleAssembler(("position_mm", "current_A"), tolerance_s=0.5e-3)
    assembler.add("position_mm", start, 1.0)
    assembler.add("current_A", naive + datetime.timedelta(microseconds=300), 0.5)
    [(stamp, values)] = assembler.take()
    assert stamp == start
    assert values["time_s"] == [pytest.approx(start.timestamp() + 150e-6, abs=1e-6)]
    assert values["position_mm"] == [1.0] and values["current_A"] == [0.5]


def test_a_negative_tolerance_is_refused():
    with pytest.raises(ValueError, match="tolerance_s"):
        SampleAssembler(COLUMNS, tolerance_s=-1.0)
