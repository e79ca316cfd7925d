"""Feed-forward adapters of the fitted models."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.control import InertiaFeedForward, ModelFeedForward, stroke_reference
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def runs():
    return prepare([make_dataset("X", "A", seed=21, duration_s=8.0), make_dataset("X", "P", seed=21, duration_s=8.0)])


@pytest.fixture(scope="module")
def models(runs):
    gms = GMSModel(n_starts=1, max_iter=60).fit(runs)
    # the GMS+SVR freezes the GMS fitted here: the same stage its own fit on these runs would identify
    # (tests/models/test_contract.py, staged fit), identified once
    gmssvr = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=60), optimize=False, C=1.0, epsilon=0.02, gamma=0.5,
                         n_subset=300).fit_staged(runs, first_stage=gms)
    return {
        "coulomb": CoulombModel().fit(runs),
        "stribeck": StribeckModel().fit(runs),
        "lugre": LuGreModel(n_starts=1, max_iter=60).fit(runs),
        "gms": gms,
        "gmssvr": gmssvr,
    }


@pytest.mark.parametrize("kind", ["coulomb", "stribeck", "lugre", "gms", "gmssvr"])
def test_model_feedforward_is_the_model_prediction_along_the_reference(models, kind):
    model = models[kind]
    reference = stroke_reference("high", 3.0, seed=2, start_mm=-250.0)
    feedforward = ModelFeedForward(model)
    assert feedforward.name == kind and feedforward.inertia_A_s2_mm == model.J_
    np.testing.assert_allclose(feedforward.current(reference), model.predict(reference.to_log()), rtol=1e-12,
                               atol=1e-12)
    # another inertia changes the inertial part only
    other = ModelFeedForward(model, inertia_A_s2_mm=1e-3, name="mine")
    np.testing.assert_allclose(other.current(reference) - feedforward.current(reference),
                               (1e-3 - model.J_) * reference.acceleration, atol=1e-12)
    assert other.name == "mine"


def test_dynamic_feedforward_is_causal(models):
    """Sample k depends on the reference up to k only: the state is carried step by step."""
    reference = stroke_reference("low", 4.0, seed=3)
    full = ModelFeedForward(models["gms"]).current(reference)
    changed = reference.__class__(reference.name, reference.time, reference.position,
                                  np.where(reference.time > 2.0, -reference.velocity, reference.velocity),
                                  reference.acceleration)
    cut = np.searchsorted(reference.time, 2.0, side="right")
    partial = ModelFeedForward(models["gms"]).current(changed)
    np.testing.assert_array_equal(partial[:cut], full[:cut])
    assert not np.allclose(partial[cut:], full[cut:])


def test_inertia_feedforward():
    reference = stroke_reference("high", 2.0, seed=1)
    feedforward = InertiaFeedForward(2e-4)
    assert feedforward.name == "none"
    np.testing.assert_allclose(feedforward.current(reference), 2e-4 * reference.acceleration)
    assert np.all(feedforward.friction(reference) == 0.0)
    with pytest.raises(GreyboxError, match="finite"):
        InertiaFeedForward(float("nan"))
