"""Physical friction models: Coulomb, Stribeck, LuGre and GMS.

Each model is a current model (inertia + friction, see
:class:`greybox.models.estimator.CurrentModel`) with scikit-learn estimator
conventions; the dynamic ones (LuGre, GMS) run compiled kernels from
:mod:`greybox.models.friction.kernels`.
"""

from .coulomb import CoulombModel
from .gms import GMSModel, GMSState
from .lugre import LuGreModel
from .stribeck import StribeckModel, stribeck_curve

__all__ = ["CoulombModel", "GMSModel", "GMSState", "LuGreModel", "StribeckModel", "stribeck_curve"]
