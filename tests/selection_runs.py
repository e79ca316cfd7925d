"""Runs and candidate scores for the tests of model choice by held-out runs (tests/identify/test_selection.py,
tests/train/test_candidates.py)."""

from __future__ import annotations

import numpy as np
from friction_signals import motion_log, velocity_profile

from greybox.identify.selection import CandidateScore


def coulomb_run(seed: int, duration: float = 6.0, noise: float = 0.02):
    """A run whose effort is Coulomb + viscous friction plus a little white noise.

    Parameters
    ----------
    seed : int
        Seed of the velocity profile and of the noise.
    duration : float
        Length of the run [s].
    noise : float
        Standard deviation of the white noise on the effort [A].

    Returns
    -------
    AxisLog
        The run: effort 0.8 sign(v) + 0.01 v [A] plus the noise, source ``run<seed>.csv``.
    """
    velocity = velocity_profile(duration, seed=seed, v_max=60.0)
    log = motion_log(velocity, source=f"run{seed}.csv")
    rng = np.random.default_rng(seed)
    effort = 0.8 * np.sign(velocity) + 0.01 * velocity + noise * rng.standard_normal(len(velocity))
    return log.replace(effort=effort)


def score(label: str, folds, n_params: int, error: str | None = None) -> CandidateScore:
    """A candidate's score with the given held-out REs.

    Parameters
    ----------
    label : str
        The candidate's label.
    folds : sequence of float
        Its RE on each held-out fold [%].
    n_params : int
        Its number of parameters.
    error : str or None
        Why it failed, or None.

    Returns
    -------
    CandidateScore
        The score, with an RMSE of 0.1 on every fold.
    """
    return CandidateScore(label, fold_re=list(folds), fold_rmse=[0.1] * len(folds), n_params=n_params, error=error)
