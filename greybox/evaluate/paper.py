"""The published figures of Rüppel et al. (2024) that reports put beside greybox's.

Tables 3 (train on A, test on C) and 4 (train on A + B, test on C + D) of the
paper (J. Machine Engineering 24(1), 2024), measured on the X and Y axes of a Mazak
VARIAXIS i-600. Keys are ``(experiment, axis, model)`` with
the model names of :data:`greybox.models.registry` (``stribeck``, ``svr``, ``gms``,
``gmssvr``); experiment 1 is Table 3, experiment 2 is Table 4.
"""

from __future__ import annotations

__all__ = ["PAPER_RE", "PAPER_TRAIN_RE", "PAPER_TEST_RMSE", "PAPER_SOURCE"]

#: Test RE [%] (RMSE over the mean current).
PAPER_RE: dict[tuple[int, str, str], float] = {
    (1, "X", "stribeck"): 11.4, (1, "X", "svr"): 12.6, (1, "X", "gms"): 11.9,
    (1, "Y", "stribeck"): 14.9, (1, "Y", "svr"): 14.4, (1, "Y", "gms"): 13.4,
    (2, "X", "stribeck"): 10.1, (2, "X", "svr"): 42.2, (2, "X", "gms"): 11.0, (2, "X", "gmssvr"): 7.1,
    (2, "Y", "stribeck"): 25.3, (2, "Y", "svr"): 51.3, (2, "Y", "gms"): 25.0, (2, "Y", "gmssvr"): 12.0,
}

#: Training RE [%].
PAPER_TRAIN_RE: dict[tuple[int, str, str], float] = {
    (1, "X", "stribeck"): 9.2, (1, "X", "svr"): 9.2, (1, "X", "gms"): 9.9,
    (1, "Y", "stribeck"): 13.2, (1, "Y", "svr"): 12.2, (1, "Y", "gms"): 12.1,
    (2, "X", "stribeck"): 10.3, (2, "X", "svr"): 9.2, (2, "X", "gms"): 8.9, (2, "X", "gmssvr"): 6.6,
    (2, "Y", "stribeck"): 23.2, (2, "Y", "svr"): 5.5, (2, "Y", "gms"): 23.0, (2, "Y", "gmssvr"): 12.0,
}

#: Test RMSE [A].
PAPER_TEST_RMSE: dict[tuple[int, str, str], float] = {
    (1, "X", "stribeck"): 0.13, (1, "X", "svr"): 0.14, (1, "X", "gms"): 0.13,
    (1, "Y", "stribeck"): 0.15, (1, "Y", "svr"): 0.15, (1, "Y", "gms"): 0.14,
    (2, "X", "stribeck"): 0.12, (2, "X", "svr"): 0.50, (2, "X", "gms"): 0.13, (2, "X", "gmssvr"): 0.08,
    (2, "Y", "stribeck"): 0.32, (2, "Y", "svr"): 0.64, (2, "Y", "gms"): 0.31, (2, "Y", "gmssvr"): 0.15,
}

#: Where the published figures come from, printed under every experiment table.
PAPER_SOURCE = (
    "Paper: Rüppel et al., J. Machine Engineering 24(1) 2024, Tables 3 and 4, measured on a Mazak VARIAXIS "
    "i-600; models the paper did not run are blank (–). "
    "Our figures come from the synthetic axis, not from the paper's machine."
)
