"""Properties of the twin's X and Y axes that docs/synthetic-axis.md states, computed from their parameters.

For each linear axis of :data:`greybox.twin.axes.AXES` with :func:`greybox.twin.plant.default_plant_parameters`:
the total initial stiffness of the Maxwell-slip elements [A/mm]; the steady sliding friction at mid travel
between 100 and 2000 mm/min [A] and the feed of its minimum [mm/min]; the position factor ``g`` inside the
measurement window and over the travel; the Coulomb part of the friction at the two ends of the travel over
its level at mid travel. Prints one JSON object (the record ``twin-axes``)::

    python scripts/twin_axes.py
"""

from __future__ import annotations

import json

import numpy as np

from greybox.twin.axes import AXES
from greybox.twin.plant import default_plant_parameters

#: The feeds [mm/min] over which the steady friction is given, and the grid of positions per mm.
FEEDS_MM_MIN, PER_MM = (100.0, 2000.0), 20


def axis_properties(name: str) -> dict:
    """The stated properties of one linear axis.

    Parameters
    ----------
    name : str
        ``"X"`` or ``"Y"``.

    Returns
    -------
    dict
        ``stiffness_A_mm``, ``sliding_A`` (low, high), ``sliding_min_feed_mm_min``, ``g_window`` and
        ``g_travel`` (low, high), ``ends_over_middle`` (the travel's two ends: the position factor there over
        the one at mid travel).
    """
    geometry = AXES[name]
    plant = default_plant_parameters(name)
    middle = 0.5 * (geometry.travel_mm[0] + geometry.travel_mm[1])
    feeds = np.geomspace(*FEEDS_MM_MIN, 400)
    sliding = plant.steady_friction(feeds / 60.0, middle)

    def factors(low: float, high: float) -> np.ndarray:
        return plant.position_factor(np.linspace(low, high, int((high - low) * PER_MM) + 1))

    window, travel = factors(*geometry.window_mm), factors(*geometry.travel_mm)
    ends = plant.position_factor(np.array(geometry.travel_mm)) / plant.position_factor(middle)
    return {"stiffness_A_mm": float(np.sum(plant.stiffness_A_mm)),
            "sliding_A": [float(sliding.min()), float(sliding.max())],
            "sliding_min_feed_mm_min": float(feeds[np.argmin(sliding)]),
            "g_window": [float(window.min()), float(window.max())],
            "g_travel": [float(travel.min()), float(travel.max())],
            "ends_over_middle": [float(value) for value in ends]}


def main() -> int:
    figures = {"feeds_mm_min": list(FEEDS_MM_MIN),
               "axes": {name: axis_properties(name) for name, geometry in AXES.items() if geometry.motion == "linear"}}
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
