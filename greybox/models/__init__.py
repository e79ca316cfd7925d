"""The model kinds: every current model greybox fits, predicts with and stores, in one place.

A current model predicts the drive effort of a feed axis, inertia plus friction
(plus a data-driven correction), from its prepared motion. The parts:

- :mod:`~greybox.models.estimator`: the shared implementation (fitting template, run checks, prediction);
- :mod:`~greybox.models.friction`: the physical kinds (Coulomb, Stribeck, LuGre, GMS, any of them behind a
  backlash) and their compiled time-stepping kernels;
- :mod:`~greybox.models.svr`, :mod:`~greybox.models.gmssvr`: the kernel kinds (the SVR alone, GMS plus an SVR
  correction), on the kernel engine of :mod:`~greybox.models.kernel` and the hand-over of
  :mod:`~greybox.models.handover`;
- :mod:`~greybox.models.augmented`: a base model plus named effects of :mod:`~greybox.models.effects`;
- :mod:`~greybox.models.registry`: the kinds by the name model files and ``greybox train --model`` use.

A new model kind is its module here plus one line in the registry. Importing this package loads nothing:
each part is imported where it is used.
"""
