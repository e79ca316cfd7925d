"""Closed-loop position control with model-based friction feed-forward (Tjahjowidodo et al., IFAC 2005).

Friction models are judged by what they do in a controller: a PID position
loop, tuned once, around a plant (the synthetic axis's truth plant or an
identified GMS/LuGre model), with feed-forward of the inertia plus the
friction model under test, on a low-stroke and a high-stroke filtered random
reference. See docs/compensate.md.

- :mod:`~greybox.control.references`: references (filtered random, from a log);
- :mod:`~greybox.control.pid`: the discrete PID (filtered derivative, anti-windup);
- :mod:`~greybox.control.tuning`: one set of gains by pole placement;
- :mod:`~greybox.control.feedforward`: inertia and model feed-forwards;
- :mod:`~greybox.control.plants`: closed-loop plants with their compiled loop kernels;
- :mod:`~greybox.control.loop`: the simulation and the comparison;
- :mod:`~greybox.control.report`: tables and plots.
"""

from .feedforward import InertiaFeedForward, ModelFeedForward
from .loop import LoopResult, compare_feedforwards, simulate_loop
from .pid import PIDGains
from .plants import ModelPlant, TwinPlant
from .references import Reference, filtered_random_reference, reference_from_log, stroke_reference
from .report import comparison_rows, format_tables, plot_tracking_errors, write_report
from .tuning import default_bandwidth_hz, pole_placement_gains

__all__ = [
    "InertiaFeedForward",
    "ModelFeedForward",
    "LoopResult",
    "compare_feedforwards",
    "simulate_loop",
    "PIDGains",
    "ModelPlant",
    "TwinPlant",
    "Reference",
    "filtered_random_reference",
    "reference_from_log",
    "stroke_reference",
    "comparison_rows",
    "format_tables",
    "plot_tracking_errors",
    "write_report",
    "default_bandwidth_hz",
    "pole_placement_gains",
]
