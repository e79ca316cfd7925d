"""The recovered process current on the synthetic axis: its error is the model's air-cut error."""

from __future__ import annotations

import numpy as np

from greybox.data.prepare import prepare
from greybox.evaluate.process import predict_process
from greybox.friction import GMSModel
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
