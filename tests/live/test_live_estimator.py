"""The estimator of a stream: its warm-up before the stream loads the kernels and leaves the stream as it was."""

from __future__ import annotations

import gc

import numpy as np
import pytest
from live_helpers import QUICK

from greybox.live.estimator import LiveEstimator
from greybox.live.run import settled_memory
from greybox.models.files import load_model


def _estimates(estimator, log, size=10) -> np.ndarray:
    parts = []
    for k in range(0, len(log), size):
        parts += [result.model for result in estimator.step(log.select(slice(k, k + size))).results]
    parts += [result.model for result in estimator.finish().results]
    return np.concatenate(parts)


@pytest.mark.parametrize("kind", sorted(QUICK))
def test_the_warm_up_runs_and_leaves_the_stream_as_it_was(kind, model_file, cut_raw):
    model = load_model(model_file(kind))
    warmed = LiveEstimator(model)
    assert warmed.warm_up()
    assert (warmed.runs, warmed.waiting, warmed.timeline.nominal) == (0, 0, None)
    np.testing.assert_array_equal(_estimates(warmed, cut_raw), _estimates(LiveEstimator(model), cut_raw))


def test_the_start_up_objects_are_frozen_while_the_stream_runs():
    with settled_memory():
        assert gc.get_freeze_count() > 0
    assert gc.get_freeze_count() == 0


def test_a_warm_up_the_options_refuse_leaves_the_error_to_the_stream(model_file):
    estimator = LiveEstimator(load_model(model_file("gms")), cutoff_hz=1e6)  # above the Nyquist frequency
    assert estimator.warm_up() is False
    assert estimator.runs == 0
