"""Each model's linear parameters as regressor columns (the linear part of the model protocol)."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.twin import make_dataset

MODELS = [CoulombModel(), CoulombModel(asymmetric=True), CoulombModel(fit_offset=True),
          StribeckModel(), StribeckModel(fit_offset=True), LuGreModel(fit_offset=True, n_starts=1, max_iter=60),
          GMSModel(n_elements=2, n_starts=1, max_iter=60, staged=False)]


@pytest.fixture(scope="module")
def run():
    return prepare([make_dataset("X", "A", seed=2, duration_s=8.0)])[0]


@pytest.mark.parametrize("template", MODELS, ids=lambda m: repr(m))
def test_columns_times_coefficients_plus_fixed_is_the_prediction(template, run):
    model = template.fit(run)
    part = model.linear_part(run)
    assert part.columns.shape == (len(run), model.linear_coefficients().size)
    np.testing.assert_allclose(part.columns @ model.linear_coefficients() + part.fixed, model.predict(run),
                               rtol=0, atol=1e-12)
    assert np.all(model.linear_coefficients() >= part.lower) and np.all(model.linear_coefficients() <= part.upper)


@pytest.mark.parametrize("template", MODELS, ids=lambda m: repr(m))
def test_written_coefficients_change_the_prediction_as_the_columns_say(template, run):
    model = template.fit(run)
    part = model.linear_part(run)
    new = model.linear_coefficients() * 1.1 + 0.01
    model.set_linear_coefficients(new)
    np.testing.assert_array_equal(model.linear_coefficients(), new)
    np.testing.assert_allclose(model.predict(run), part.columns @ new + part.fixed, rtol=0, atol=1e-12)


def test_symmetric_coulomb_keeps_its_levels_tied(run):
    model = CoulombModel().fit(run)
    model.set_linear_coefficients([3e-4, 0.8, 0.01])
    assert model.coulomb_pos_ == model.coulomb_neg_ == 0.8
    assert model.viscous_pos_ == model.viscous_neg_ == 0.01
