"""Validation studies that need the synthetic twin: what the README's figures come from.

- :mod:`greybox.studies.experiments`: the paper's two experiments on the
  shipped synthetic axes (``greybox reproduce``);
- :mod:`greybox.studies.cutting` and :mod:`greybox.studies.cut_recovery`:
  recovery of a known cutting-force current (``scripts/cutting_validation.py``);
- :mod:`greybox.studies.discovery`: hidden effects, null data and gap closure
  of the discovery workflow (``scripts/discovery_study.py``);
- :mod:`greybox.studies.emps`: the EMPS benchmark's protocol on the real
  ball-screw drive (``scripts/emps_benchmark.py``);
- :mod:`greybox.studies.arts`: the friction models on the real ARTS-Lab
  dry-friction device with backlash (``scripts/arts_benchmark.py``).

Besides :mod:`greybox.twin` itself, only this package, :mod:`greybox.control`
and :mod:`greybox.cli` import the twin (``tests/test_import_graph.py``); the
rest of the library works on any axis log. Nothing is imported here, so that
importing one study does not load the others.
"""
