"""The paper's two experiments on the shipped synthetic axes: what ``greybox reproduce`` runs.

:mod:`greybox.reproduce.experiments` holds the experiments, their model
settings and the run. The validation studies beyond the paper's experiments
are not part of the installed package (``studies/`` in the repository).
"""
