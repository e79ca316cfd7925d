"""SVR-based models survive a save/load round trip without pickle."""

from __future__ import annotations

import numpy as np
import pytest
from test_svr_model import FIXED, sweep_run

from greybox import persistence, registry
from greybox.models.svr import SVRCurrentModel


def test_saved_and_loaded_model_predicts_identically(tmp_path, monkeypatch):
    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    model = SVRCurrentModel(**FIXED).fit(sweep_run(1))
    path = persistence.save_model(model, tmp_path / "svr.gbm")
    loaded = persistence.load_model(path)
    test = sweep_run(3, n=1000)
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))
    table, loaded_table = model.hyperparameters_table(), loaded.hyperparameters_table()
    assert np.isnan(table.pop("cv_rmse")) and np.isnan(loaded_table.pop("cv_rmse"))
    assert loaded_table == table


@pytest.mark.parametrize("target", ["residual", "current"])
def test_grey_box_model_with_nested_gms_stage_round_trips(tmp_path, monkeypatch, target):
    from test_svr_gms import SVR_FIXED, gms_run, quick_gms

    from greybox.friction.gms import GMSModel
    from greybox.models.gmssvr import GMSSVRModel

    monkeypatch.setitem(registry.MODEL_CLASSES, "gms", GMSModel)
    monkeypatch.setitem(registry.MODEL_CLASSES, "gmssvr", GMSSVRModel)
    model = GMSSVRModel(gms=quick_gms(), target=target, **SVR_FIXED).fit(gms_run(1, n=6000))
    loaded = persistence.load_model(persistence.save_model(model, tmp_path / "gmssvr.gbm"))
    assert loaded.target == target
    test = gms_run(2, n=2000)
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))
    np.testing.assert_array_equal(loaded.states(test)[0], model.states(test)[0])
