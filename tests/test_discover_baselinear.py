"""The base models' linear parameters as regressor columns."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.discover.baselinear import base_coefficients, base_linear_part, set_base_coefficients
from greybox.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
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
    part = base_linear_part(model, run)
    assert part.columns.shape == (len(run), base_coefficients(model).size)
    np.testing.assert_allclose(part.columns @ base_coefficients(model) + part.fixed, model.predict(run),
                               rtol=0, atol=1e-12)
    assert np.all(base_coefficients(model) >= part.lower) and np.all(base_coefficients(model) <= part.upper)


@pytest.mark.parametrize("template", MODELS, ids=lambda m: repr(m))
def test_written_coefficients_change_the_prediction_as_the_columns_say(template, run):
    model = template.fit(run)
    part = base_linear_part(model, run)
    new = base_coefficients(model) * 1.1 + 0.01
    set_base_coefficients(model, new)
    np.testing.assert_array_equal(base_coefficients(model), new)
    np.testing.assert_allclose(model.predict(run), part.columns @ new + part.fixed, rtol=0, atol=1e-12)


def test_symmetric_coulomb_keeps_its_levels_tied(run):
    model = CoulombModel().fit(run)
    set_base_coefficients(model, [3e-4, 0.8, 0.01])
    assert model.coulomb_pos_ == model.coulomb_neg_ == 0.8
    assert model.viscous_pos_ == model.viscous_neg_ == 0.01
