"""Synthetic machine-tool feed axis: truth plant, trajectories, hidden effects, cutting load.

The truth plant (:mod:`greybox.twin.plant`) is a 24-element Maxwell-slip
friction with lagged Stribeck weakening, viscous friction, a position profile
along the screw and inertia, integrated at 0.25 ms; it is not one of the
package's own friction models. :func:`make_dataset` produces the datasets A-D
of Rüppel et al. (2024, Table 1) and the pre-sliding excitation P as
:class:`~greybox.data.log.AxisLog` objects with their truth components;
:func:`synthesize` writes them as MCAP files.
"""

from .axes import AXES, AxisGeometry, axis_geometry
from .cutting import CuttingSpec, cutting_current
from .datasets import ESSENTIAL_TRUTH_CHANNELS, SAMPLE_TIME_S, TRUTH_CHANNELS, make_dataset, synthesize
from .effects import EFFECTS, EffectInputs, effect_current, effect_parameters
from .noise import CurrentNoise
from .plant import PlantParameters, default_plant_parameters, simulate_plant
from .sensors import Sensors
from .trajectories import DATASETS, DEFAULT_DATASETS, dataset_trajectory

__all__ = [
    "AXES",
    "AxisGeometry",
    "axis_geometry",
    "CuttingSpec",
    "cutting_current",
    "CurrentNoise",
    "DATASETS",
    "DEFAULT_DATASETS",
    "dataset_trajectory",
    "EFFECTS",
    "EffectInputs",
    "effect_current",
    "effect_parameters",
    "ESSENTIAL_TRUTH_CHANNELS",
    "make_dataset",
    "PlantParameters",
    "default_plant_parameters",
    "SAMPLE_TIME_S",
    "Sensors",
    "simulate_plant",
    "synthesize",
    "TRUTH_CHANNELS",
]
