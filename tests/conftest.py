"""Shared fixtures: small synthetic axis logs with known content."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog


def sine_log(n: int = 2000, sample_time: float = 0.002, *, seed: int = 0, **fields) -> AxisLog:
    """A log of a sinusoidal stroke: position 50 sin(2 pi 0.5 t) mm, noisy current in A."""
    rng = np.random.default_rng(seed)
    time = np.arange(n) * sample_time
    position = 50.0 * np.sin(2 * np.pi * 0.5 * time)
    values = dict(
        time=time,
        position=position,
        effort=0.01 * np.gradient(position, sample_time) + rng.normal(0.0, 0.1, n),
        axis="X",
        dataset="T",
    )
    values.update(fields)
    return AxisLog(**values)


@pytest.fixture
def make_log():
    """Factory of small sinusoidal axis logs, see :func:`sine_log`."""
    return sine_log
