"""Truth friction laws of the synthetic axis family, one module per law.

Each law is a frozen dataclass of its parameters with a ``draw(rng)`` over
documented physical ranges (``RANGES``) and a compiled kernel; the base class
(:mod:`.base`) imports nothing else of greybox. The family plant
(:mod:`greybox.twin.family`) composes a law with the effects every feed axis has.
"""

from .backlash_screw import BacklashScrewLaw
from .base import LawResponse, TruthLaw
from .bristle import BristleLaw
from .dahl import DahlLaw
from .maxwell_slip import MaxwellSlipLaw

#: The family's laws by name, in the order the family cycles through them.
TRUTH_LAWS = {law.name: law for law in (MaxwellSlipLaw, BristleLaw, DahlLaw, BacklashScrewLaw)}

__all__ = ["TruthLaw", "LawResponse", "MaxwellSlipLaw", "BristleLaw", "DahlLaw", "BacklashScrewLaw", "TRUTH_LAWS"]
