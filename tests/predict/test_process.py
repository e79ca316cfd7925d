"""The recovered process current on the synthetic axis: its error is the model's air-cut error."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.models.friction import GMSModel
from greybox.predict.process import predict_process, process_blocks
from greybox.twin import make_dataset

#: Resolution of the logged current [A]: the cut and air-cut logs differ by the process current up to it.
CURRENT_RESOLUTION_A = 1e-3


def test_process_error_equals_the_air_cut_residual():
    """Same motion and noise with and without the cut, so (measured - model) - truth = air-cut residual."""
    model = GMSModel(n_starts=1, max_iter=80).fit(prepare([make_dataset("X", "A", seed=21, duration_s=10)])[0])
    cut = prepare([make_dataset("X", "C", seed=22, duration_s=10, cutting=True)])[0]
    air = prepare([make_dataset("X", "C", seed=22, duration_s=10)])[0]
    truth = cut.extras["truth_process_A"]
    assert np.count_nonzero(truth) > 100  # the log really cuts
    result = predict_process(model, cut, chunk_s=2.5)
    residual_air = air.current - model.predict(air)
    error = result.process - truth
    assert np.max(np.abs(error - residual_air)) <= CURRENT_RESOLUTION_A + 1e-12
    # the process current stands out of the air-cut error: it is recovered with positive correlation
    assert np.corrcoef(result.process, truth)[0, 1] > 0.5


def test_thinned_picture_keeps_single_sample_peaks():
    """Long logs are drawn as per-bin minimum and maximum, so a one-sample spike survives thinning."""
    import matplotlib
    import matplotlib.pyplot

    matplotlib.use("Agg")
    from greybox.predict.plot import envelope_indices, plot_process
    from greybox.predict.process import ProcessResult

    n = 10_001
    time = np.arange(n) * 0.002
    measured = np.zeros(n)
    measured[4321] = 5.0
    result = ProcessResult(time=time, position=np.zeros(n), velocity=np.zeros(n), measured=measured,
                           model=np.zeros(n), load=763.4 * measured,
                           load_constants=(763.4, 763.4))
    assert envelope_indices(n, 20_000).size == n
    figure = plot_process(result, max_points=500)
    process_axes = figure.axes[2]
    drawn = process_axes.lines[0].get_ydata()
    assert drawn.size <= 502 and drawn.max() == 5.0
    assert process_axes.get_ylabel() == "process current [A]"
    assert [axes.get_ylabel() for axes in process_axes.child_axes] == ["process force [N]"]
    matplotlib.pyplot.close(figure)


def test_process_panel_draws_the_moving_mean():
    import matplotlib
    import matplotlib.pyplot

    matplotlib.use("Agg")
    from greybox.predict.plot import plot_process
    from greybox.predict.process import ProcessResult

    n = 2000
    time = np.arange(n) * 0.002
    measured = np.where(time > 2.0, -0.4, 0.0) + 0.3 * np.sin(2 * np.pi * 100.0 * time)
    result = ProcessResult(time=time, position=np.zeros(n), velocity=np.zeros(n), measured=measured,
                           model=np.zeros(n), load=None)
    figure = plot_process(result, mean_s=0.1)
    mean_line = figure.axes[2].lines[1]
    assert "0.1 s" in mean_line.get_label()
    inside = mean_line.get_ydata()[(mean_line.get_xdata() > 2.2) & (mean_line.get_xdata() < 3.8)]
    np.testing.assert_allclose(inside, -0.4, atol=1e-9)
    matplotlib.pyplot.close(figure)
    assert len(plot_process(result, mean_s=0.0).axes[2].lines) == 2  # process line and zero line only
    matplotlib.pyplot.close("all")


def _blocks_of(log, samples):
    return [log.select(slice(start, min(start + samples, len(log)))) for start in range(0, len(log), samples)]


def test_blocks_predicted_on_the_model_thread_give_the_whole_run_and_read_ahead():
    """Block k is predicted on its own thread while block k + 1 is read: the results are still those of the
    whole run, and the blocks' iterator is advanced before block k's result comes out."""
    model = GMSModel(n_starts=1, max_iter=40).fit(prepare([make_dataset("X", "A", seed=21, duration_s=6)])[0])
    cut = prepare([make_dataset("X", "C", seed=22, duration_s=6, cutting=True)])[0]
    events = []
    callers = set()
    predict_flag_chunk = model.predict_flag_chunk

    def recorded(*args, **kwargs):
        callers.add(threading.get_ident())
        return predict_flag_chunk(*args, **kwargs)

    model.predict_flag_chunk = recorded

    def reading():
        for k, block in enumerate(_blocks_of(cut, 1000)):
            events.append(("read", k))
            yield block

    results = []
    for k, result in enumerate(process_blocks(model, reading(), sample_time=cut.sample_time, chunk_s=0.7,
                                                   read_ahead=True)):
        events.append(("result", k))
        results.append(result)
    np.testing.assert_array_equal(np.concatenate([r.model for r in results]), model.predict(cut))
    n = len(results)
    assert n == -(-len(cut) // 1000) > 2
    for k in range(n - 1):
        assert events.index(("read", k + 1)) < events.index(("result", k))
    assert threading.get_ident() not in callers


def test_a_failing_block_and_an_early_stop_leave_no_model_work_behind():
    model = GMSModel(n_starts=1, max_iter=40).fit(prepare([make_dataset("X", "A", seed=21, duration_s=4)])[0])
    cut = prepare([make_dataset("X", "C", seed=22, duration_s=4, cutting=True)])[0]
    running = []
    predict_flag_chunk = model.predict_flag_chunk

    def recorded(*args, **kwargs):
        running.append(1)
        out = predict_flag_chunk(*args, **kwargs)
        running.pop()
        return out

    model.predict_flag_chunk = recorded

    def failing():
        yield from _blocks_of(cut, 1000)[:2]
        raise RuntimeError("the third block is corrupt")

    with pytest.raises(RuntimeError, match="third block"):
        list(process_blocks(model, failing(), sample_time=cut.sample_time, read_ahead=True))
    assert not running  # the second block's prediction ended before the error came out
    results = process_blocks(model, iter(_blocks_of(cut, 1000)), sample_time=cut.sample_time, read_ahead=True)
    next(results)
    results.close()
    assert not running
