"""Validation studies: what the README's and the docs' figures come from (not part of the installed package).

This folder sits beside ``greybox/`` in the repository and is left out of the
wheel. The scripts in ``scripts/`` run the studies (they put the repository
on ``sys.path``); their tests are in ``tests/studies/`` (pytest's
``pythonpath`` setting makes ``import studies`` work).

- :mod:`studies.cutting` and :mod:`studies.cut_recovery`: recovery of a known
  cutting-force current (``scripts/cutting_validation.py``);
- :mod:`studies.cutting_load`: the process-load prediction under cutting
  (``scripts/cutting_load_validation.py``);
- :mod:`studies.discovery`, :mod:`studies.discovery_family` and
  :mod:`studies.hysteresis_axis`: hidden effects, null data and gap closure of
  the discovery workflow (``scripts/discovery_study.py``);
- :mod:`studies.priors`, :mod:`studies.robustness` and
  :mod:`studies.members`: the twin-family studies (``scripts/family_study.py``);
- :mod:`studies.emps`: the EMPS benchmark's protocol on the real ball-screw
  drive (``scripts/emps_benchmark.py``);
- :mod:`studies.arts` and :mod:`studies.arts_data`: the friction models on the
  real ARTS-Lab dry-friction device with backlash (``scripts/arts_benchmark.py``);
- :mod:`studies.auto`: the held-out model choice both benchmarks report;
- :mod:`studies.records` and :mod:`studies.result_pages`: the measured records under ``docs/results/``
  (``scripts/record.py``) and the pages' tables rendered from them (``scripts/render_results.py``).

The paper's two experiments that ``greybox reproduce`` runs are in the
package: :mod:`greybox.reproduce`. Nothing is imported here, so that importing
one study does not load the others.
"""
