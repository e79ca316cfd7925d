"""NC programs for air cuts: the blocks of a one-axis program, ISO G-code in and out, and the air-cut planner.

:mod:`greybox.nc.blocks` holds the blocks (moves and dwells) and imports nothing
else of greybox; :mod:`greybox.nc.gcode` writes them as ISO G-code and reads
G-code back; :mod:`greybox.nc.plan` plans the air cuts of the paper's datasets
A and B as a program. The synthetic twin runs a program
(:mod:`greybox.twin.nc_run`), so a plan can be tried before the machine runs it.
"""

from .blocks import AXIS_LETTERS, Dwell, Move, Program
from .gcode import parse_program, read_program, write_program
from .plan import AirCutPlan, plan_air_cuts

__all__ = ["AXIS_LETTERS", "Dwell", "Move", "Program", "parse_program", "read_program", "write_program",
           "AirCutPlan", "plan_air_cuts"]
