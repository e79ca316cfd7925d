"""scripts/twin_axes.py: the twin's axis properties docs/synthetic-axis.md renders (record twin-axes)."""

import runpy
from pathlib import Path

import numpy as np
import pytest

from greybox.twin.axes import AXES
from greybox.twin.plant import default_plant_parameters

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "twin_axes.py"


@pytest.fixture(scope="module")
def properties():
    return runpy.run_path(str(SCRIPT))["axis_properties"]


@pytest.mark.parametrize("axis", ["X", "Y"])
def test_the_stiffness_is_the_sum_of_each_elements_breakaway_over_its_deflection(properties, axis):
    plant = default_plant_parameters(axis)
    expected = sum(f / d for f, d in zip(plant.breakaway_A, plant.breakaway_deflection_mm))
    assert properties(axis)["stiffness_A_mm"] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("axis", ["X", "Y"])
def test_the_sliding_friction_is_taken_at_mid_travel_and_dips_between_the_feeds(properties, axis):
    figures, plant = properties(axis), default_plant_parameters(axis)
    middle = 0.5 * sum(AXES[axis].travel_mm)
    low, high = figures["sliding_A"]
    at_ends = plant.steady_friction(np.array([100.0, 2000.0]) / 60.0, middle)
    assert low < min(at_ends) and high == pytest.approx(max(at_ends), rel=1e-9)
    assert 100.0 < figures["sliding_min_feed_mm_min"] < 2000.0
    assert plant.steady_friction(figures["sliding_min_feed_mm_min"] / 60.0, middle) == pytest.approx(low, rel=1e-12)


@pytest.mark.parametrize("axis", ["X", "Y"])
def test_the_window_lies_inside_the_travel_and_the_ends_are_taken_against_mid_travel(properties, axis):
    figures, plant = properties(axis), default_plant_parameters(axis)
    assert figures["g_travel"][0] <= figures["g_window"][0] <= figures["g_window"][1] <= figures["g_travel"][1]
    middle = 0.5 * sum(AXES[axis].travel_mm)
    end = AXES[axis].travel_mm[1]
    assert figures["ends_over_middle"][1] == pytest.approx(plant.position_factor(end) / plant.position_factor(middle))
