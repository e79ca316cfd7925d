"""The model's view for a stream (:meth:`CurrentModel.stream_view`): checked once, then chunk by chunk as the
whole run, for every kind a model file may hold."""

from __future__ import annotations

import numpy as np
import pytest
from live_helpers import QUICK

from greybox.data.prepare import prepare
from greybox.errors import LogError
from greybox.models.files import load_model


@pytest.mark.parametrize("kind", sorted(QUICK))
def test_the_view_chunk_by_chunk_gives_the_whole_run(kind, model_file, cut_raw):
    model = load_model(model_file(kind))
    run = prepare([cut_raw])[0].select(slice(0, 1200))
    step = run.sample_time
    view = model.stream_view(run.select(slice(0, 10)), sample_time=step)
    state, region, parts, flags = view.initial_state(), view.region_state(), [], []
    for start in range(0, len(run), 10):
        current, state, flagged, region = view.predict_flag_chunk(run.select(slice(start, start + 10)), state, region,
                                                                  sample_time=step)
        parts.append(current)
        flags.append(flagged)
    whole = model.predict(run)
    np.testing.assert_allclose(np.concatenate(parts), whole, rtol=0, atol=1e-9 * (1 + np.abs(whole).max()))
    expected = model.outside_training(run)
    assert set(flags[0]) == set(expected)
    for name, values in expected.items():
        np.testing.assert_array_equal(np.concatenate([part[name] for part in flags]), values, err_msg=name)


def test_the_view_refuses_a_stream_the_model_does_not_take(model_file, cut_raw):
    model = load_model(model_file("gmssvr"))
    run = prepare([cut_raw])[0].select(slice(0, 10))
    with pytest.raises(LogError, match="effort in N"):
        model.stream_view(run.replace(effort_unit="N"), sample_time=run.sample_time)
    with pytest.raises(LogError, match="positive number of seconds"):
        model.stream_view(run, sample_time=0.0)
    with pytest.raises(LogError, match="not prepared"):
        model.stream_view(run.replace(acceleration=None), sample_time=run.sample_time)
