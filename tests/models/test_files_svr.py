"""SVR-based models survive a save/load round trip without pickle."""

from __future__ import annotations

import numpy as np
import pytest
from model_files import write_members
from svr_runs import FIXED, sweep_run

from greybox.models import files, registry
from greybox.models.svr import SVRCurrentModel


def test_saved_and_loaded_model_predicts_identically(tmp_path, monkeypatch):
    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    model = SVRCurrentModel(**FIXED).fit(sweep_run(1))
    path = files.save_model(model, tmp_path / "svr.gbm")
    loaded = files.load_model(path)
    test = sweep_run(3, n=1000)
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))
    table, loaded_table = model.hyperparameters_table(), loaded.hyperparameters_table()
    assert np.isnan(table.pop("cv_rmse")) and np.isnan(loaded_table.pop("cv_rmse"))
    assert loaded_table == table


@pytest.mark.parametrize("target", ["residual", "current"])
def test_grey_box_model_with_nested_gms_stage_round_trips(tmp_path, monkeypatch, target):
    from svr_runs import SVR_FIXED, gms_run, quick_gms

    from greybox.models.friction.gms import GMSModel
    from greybox.models.gmssvr import GMSSVRModel

    monkeypatch.setitem(registry.MODEL_CLASSES, "gms", GMSModel)
    monkeypatch.setitem(registry.MODEL_CLASSES, "gmssvr", GMSSVRModel)
    model = GMSSVRModel(gms=quick_gms(), target=target, **SVR_FIXED).fit(gms_run(1, n=6000))
    loaded = files.load_model(files.save_model(model, tmp_path / "gmssvr.gbm"))
    assert loaded.target == target
    test = gms_run(2, n=2000)
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))
    np.testing.assert_array_equal(loaded.states(test)[0], model.states(test)[0])


def test_the_kernel_weights_round_trip_and_a_file_with_bad_ones_is_refused(tmp_path, monkeypatch):
    import json
    import zipfile

    from greybox.errors import ModelFileError

    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    model = SVRCurrentModel(**FIXED, velocity_weight=9.0).fit(sweep_run(1))
    path = files.save_model(model, tmp_path / "svr.gbm")
    loaded = files.load_model(path)
    np.testing.assert_array_equal(loaded.input_weights_, [1.0, 9.0])
    test = sweep_run(3, n=1000)
    np.testing.assert_array_equal(loaded.predict(test), model.predict(test))

    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    member = json.loads(members["model.json"])["model"]["attributes"]["input_weights_"]["__ndarray__"]
    for bad in ([1.0, -9.0], [1.0, 9.0, 1.0]):
        buffer = __import__("io").BytesIO()
        np.save(buffer, np.array(bad), allow_pickle=False)
        hostile = tmp_path / f"hostile_{len(bad)}_{bad[1]:g}.gbm"
        write_members(hostile, {**members, member: buffer.getvalue()})
        with pytest.raises(ModelFileError, match="input_weights_ must hold one positive weight per input"):
            files.load_model(hostile)


def test_a_file_from_before_the_kernel_weights_predicts_with_the_isotropic_kernel(tmp_path, monkeypatch):
    monkeypatch.setitem(registry.MODEL_CLASSES, "svr", SVRCurrentModel)
    model = SVRCurrentModel(**FIXED).fit(sweep_run(1))
    test = sweep_run(3, n=1000)
    expected = model.predict(test)
    del model.input_weights_
    loaded = files.load_model(files.save_model(model, tmp_path / "old.gbm"))
    assert not hasattr(loaded, "input_weights_")
    np.testing.assert_array_equal(loaded.predict(test), expected)
    assert loaded.hyperparameters_table()["velocity_weight"] == 1.0
