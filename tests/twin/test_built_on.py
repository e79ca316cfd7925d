"""A plant built on another hands on its axis file and process load unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.twin.ageing import AgedPlant
from greybox.twin.built_on import BuiltOnPlant
from greybox.twin.part_series import WarmPlant, WarmUp
from greybox.twin.plant import default_plant_parameters


@pytest.mark.parametrize("wrap", [lambda p: AgedPlant(p, play_mm=0.01, defect_gain=0.5),
                                  lambda p: WarmPlant(p, WarmUp(drop=0.3, time_constant_s=5.0), warmth=0.0)])
def test_axis_file_and_process_load_are_the_wrapped_plants(wrap):
    plant = default_plant_parameters("X")
    other = default_plant_parameters("C")
    built = wrap(plant)
    assert built.underlying is plant
    assert built.axis_config("X").to_toml() == plant.axis_config("X").to_toml()
    assert built.axis_config("X").to_toml() != other.axis_config("X").to_toml()
    current = np.array([-2.0, -0.5, 0.5, 2.0])
    velocity = np.array([10.0, -10.0, 10.0, -10.0])
    np.testing.assert_array_equal(built.process_load(current, velocity), plant.process_load(current, velocity))


def test_a_mix_in_without_a_wrapped_plant_says_so():
    with pytest.raises(NotImplementedError):
        BuiltOnPlant().axis_config("X")
