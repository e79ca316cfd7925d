"""The recovered process current on the synthetic axis: its error is the model's air-cut error."""

from __future__ import annotations

import numpy as np

from greybox.data.prepare import prepare
from greybox.models.friction import GMSModel
from greybox.predict.process import predict_process
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
