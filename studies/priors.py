"""Choosing the kernel-model priors on the training runs of the truth family.

The SVR stage of GMS+SVR has two settings that its own cross-validation
cannot choose: what it learns (the GMS residual or, as the paper's eq. 8, the
current) and how wide its kernels may become (the floor of the RBF parameter
gamma). Time-blocked cross-validation inside one training log prefers wide
kernels, which carry the correction far from where it was learnt. The sole
SVR has one: whether its Gaussian kernel is isotropic in the standardised
(position, velocity) plane or weighs velocity by a searched weight (narrower
across the friction's sign change at zero speed than along the travel).
This study chooses them on the family's *training* runs only: each candidate is fitted
on the first three quarters of dataset A of a development family (a family
seed of its own, never the one a study reports) and scored on the rest of A
(new motion in the same window) and on dataset B of the same axis, the other
training run of the paper's experiment 2 (constant feeds over the whole
travel, beyond the 50 mm window of A). The test runs C and D play no part.

A candidate's score on a run is its RE over the noise floor's RE there; the
best candidate has the lowest median over the axes of the mean of its two
scores; candidates within 1 % of it are equivalent, and the default is kept
when it is one of them. The GMS stage is fitted once per axis and shared.
"""

from __future__ import annotations

import json
import os
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from greybox.atomic import write_text_atomic
from greybox.data.prepare import prepare, trim
from greybox.evaluate.records import TRUTH_CHANNEL
from greybox.metrics import relative_error
from greybox.models.friction.gms import GMSModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.models.svr import SVRCurrentModel
from greybox.reproduce.experiments import MODEL_SETTINGS
from greybox.twin.family import draw_member, member_dataset

__all__ = ["CANDIDATES", "DEFAULT", "SVR_CANDIDATES", "SVR_DEFAULT", "STUDIES", "EQUIVALENT", "TRAIN_SHARE",
           "score_member", "run_prior_study"]

#: Candidate priors: name -> (target, gamma interval, or None for the default search intervals).
CANDIDATES = {
    "residual, gamma >= 3": ("residual", (3.0, 100.0)),
    "residual, gamma >= 1": ("residual", (1.0, 100.0)),
    "residual, gamma >= 0.1": ("residual", (0.1, 100.0)),
    "residual, gamma >= 0.01": ("residual", None),
    "current (eq. 8), gamma >= 0.01": ("current", None),
}


#: The candidate of the default of :class:`~greybox.models.gmssvr.GMSSVRModel` (the residual, searched over
#: :func:`~greybox.models.kernel.expansion.default_bounds`, gamma in [0.01, 1000]). Until this study first ran (seed 1,
#: members 0-11) the default was "residual, gamma >= 1"; the study chose this one (docs/svr.md).
DEFAULT = "residual, gamma >= 0.01"

#: Candidate kernels of the sole SVR (:class:`~greybox.models.svr.SVRCurrentModel`): name -> velocity_weight
#: (None: searched with the other hyperparameters).
SVR_CANDIDATES = {
    "isotropic (velocity weight 1)": 1.0,
    "velocity weight searched": None,
}

#: The candidate of the default of :class:`~greybox.models.svr.SVRCurrentModel` (velocity_weight=None). Until
#: this study first ran (seed 1, members 0-11) the kernel was isotropic; the study chose the searched weight
#: (docs/svr.md).
SVR_DEFAULT = "velocity weight searched"

#: The studies: model kind -> (candidates, the candidate of the current default).
STUDIES = {"gmssvr": (CANDIDATES, DEFAULT), "svr": (SVR_CANDIDATES, SVR_DEFAULT)}

#: Relative difference of the median score under which two candidates count as equivalent; the default is
#: then kept (no change of a default without evidence for it).
EQUIVALENT = 0.01

#: Share of dataset A (from its start) both stages are fitted on; the rest of A and B score the candidates.
TRAIN_SHARE = 0.75


def _ratio(log, predicted) -> float:
    return relative_error(log.effort, predicted) / relative_error(log.effort, log.extras[TRUTH_CHANNEL])


def _gmssvr_candidates(train):
    """``(name, fitted GMS+SVR)`` for each of :data:`CANDIDATES`, sharing one GMS stage fitted on ``train``."""
    gms = GMSModel(**MODEL_SETTINGS["gms"]).fit([train])
    for name, (target, gamma) in CANDIDATES.items():
        bounds = None if gamma is None else {"gamma": gamma}
        yield name, GMSSVRModel(target=target, bounds=bounds, **MODEL_SETTINGS["gmssvr"]).fit_svr([train], gms=gms)


def _svr_candidates(train):
    """``(name, fitted sole SVR)`` for each of :data:`SVR_CANDIDATES`."""
    for name, weight in SVR_CANDIDATES.items():
        yield name, SVRCurrentModel(velocity_weight=weight, **MODEL_SETTINGS["svr"]).fit([train])


_FITTERS = {"gmssvr": _gmssvr_candidates, "svr": _svr_candidates}


def score_member(index: int, family_seed: int, *, model: str = "gmssvr", train_share: float = TRAIN_SHARE) -> dict:
    """Scores of every candidate of one study on one family member's training runs.

    The model (for GMS+SVR both stages) is fitted on the first ``train_share``
    of dataset A; each candidate is scored by its RE over the noise floor's RE
    on the rest of A (new motion inside the window: interpolation) and on B
    (the whole travel: extrapolation in position), and by the mean of the two.

    Parameters
    ----------
    index : int
        Member index.
    family_seed : int
        Family seed (a development family's, not one a study reports).
    model : {"gmssvr", "svr"}, default "gmssvr"
        The study (:data:`STUDIES`): the GMS+SVR priors or the sole SVR's kernel.
    train_share : float, default :data:`TRAIN_SHARE`
        Share of dataset A's duration, from its start, that the model is fitted on.
    """
    started = time.perf_counter()
    member = draw_member(index, family_seed)
    whole, check = (prepare(member_dataset(member, d))[0] for d in ("A", "B"))
    split = float(whole.time[0] + train_share * (whole.time[-1] - whole.time[0]))
    train, tail = trim(whole, stop_s=split), trim(whole, start_s=split)
    scores = {}
    for name, fitted in _FITTERS[model](train):
        ratios = {"A_tail": _ratio(tail, fitted.predict(tail)), "B": _ratio(check, fitted.predict(check))}
        scores[name] = {**ratios, "mean": 0.5 * (ratios["A_tail"] + ratios["B"])}
    return {"index": member.index, "law": member.law, "axis": member.axis, "scores": scores,
            "seconds": time.perf_counter() - started}


def _choice(summary: dict, default: str = DEFAULT) -> dict:
    """The best candidate, those within :data:`EQUIVALENT` of it, and the one kept (``default`` if equivalent)."""
    score = {name: cell["mean"]["median"] for name, cell in summary.items()}
    best = min(score, key=score.get)
    equivalent = [name for name in score if score[name] <= score[best] * (1.0 + EQUIVALENT)]
    return {"best": best, "equivalent": equivalent, "chosen": default if default in equivalent else best}


def _run(arguments):
    index, family_seed, model = arguments
    return score_member(index, family_seed, model=model)


def run_prior_study(json_path: str | os.PathLike, *, members: int = 12, family_seed: int = 1, workers: int = 1,
                    model: str = "gmssvr", progress=None) -> dict:
    """Score every candidate of a study on ``members`` axes of the development family; write and return the summary.

    Parameters
    ----------
    json_path : path-like
        Where the returned document is written (JSON), once all members are scored.
    members : int, default 12
        Number of axes, member indices 0 to ``members - 1``.
    family_seed : int, default 1
        Seed of the development family.
    workers : int, default 1
        Processes scoring members side by side.
    model : {"gmssvr", "svr"}, default "gmssvr"
        The study (:data:`STUDIES`): the GMS+SVR priors or the sole SVR's kernel.
    progress : callable, optional
        Receives one line per scored member.

    Returns
    -------
    dict
        ``{"settings", "members", "summary": {candidate: {"A_tail" | "B" | "mean": {"median", "p90"}}},
        "best", "equivalent", "chosen"}``: the candidate with the lowest median of the mean score, those
        within :data:`EQUIVALENT` of it, and the one chosen (the default when it is among them).
    """
    if model not in STUDIES:
        raise ValueError(f"model must be one of {', '.join(STUDIES)}, got {model!r}")
    candidates, default = STUDIES[model]
    say = progress or (lambda line: None)
    started, rows = time.perf_counter(), []
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for row in pool.map(_run, [(index, family_seed, model) for index in range(members)]):
            rows.append(row)
            say(f"member {row['index']:3d} ({row['law']}): "
                + "; ".join(f"{k} A {v['A_tail']:.2f} B {v['B']:.2f}" for k, v in row["scores"].items()))
    summary = {name: {key: {"median": float(np.median([r["scores"][name][key] for r in rows])),
                            "p90": float(np.quantile([r["scores"][name][key] for r in rows], 0.9))}
                      for key in ("A_tail", "B", "mean")} for name in candidates}
    result = {"settings": {"model": model, "family_seed": family_seed, "members": members,
                           "train": f"first {100 * TRAIN_SHARE:g} % of A",
                           "scored_on": "rest of A, and B", "model_settings": MODEL_SETTINGS[model]},
              "summary": summary, **_choice(summary, default), "members": rows,
              "seconds": time.perf_counter() - started}
    write_text_atomic(json_path, json.dumps(result, indent=1) + "\n")
    return result
