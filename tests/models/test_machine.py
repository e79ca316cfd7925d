"""``greybox.models.machine``: a machine model, one model file per axis and a manifest, saved and loaded checked."""

from __future__ import annotations

import json

import pytest

from greybox.data.prepare import prepare
from greybox.errors import ModelFileError
from greybox.models.files import load_model
from greybox.models.friction import StribeckModel
from greybox.models.machine import MANIFEST, MachineModel, load_machine, save_machine
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def fitted():
    """A Stribeck model of each of the axes X, Y (linear) and C (rotary) of the twin."""
    return {axis: StribeckModel().fit(prepare([make_dataset(axis, "A", k, duration_s=10)])[0])
            for k, axis in enumerate("XYC")}


def test_machine_model_round_trip_and_refusals(tmp_path, fitted):
    directory = tmp_path / "machine"
    written = save_machine(MachineModel(models=fitted, name="m"), directory)
    assert [path.name for path in written] == ["X.gbm", "Y.gbm", "C.gbm", MANIFEST]
    loaded = load_machine(directory)
    assert loaded.axes == ["X", "Y", "C"] and loaded.name == "m"
    assert loaded.models["C"].motion_ == "rotary"
    with pytest.raises(ModelFileError, match="file exists"):
        save_machine(MachineModel(models=fitted), directory)
    manifest = json.loads((directory / MANIFEST).read_text())

    def broken(change):
        document = json.loads(json.dumps(manifest))
        change(document)
        (directory / MANIFEST).write_text(json.dumps(document))
        with pytest.raises(ModelFileError) as error:
            load_machine(directory)
        return str(error.value)

    assert "keeps it as X.gbm" in broken(lambda d: d["axes"]["X"].update(model="../X.gbm"))
    assert "the manifest says 'gms'" in broken(lambda d: d["axes"]["Y"].update(kind="gms"))
    assert "'linear' axis" in broken(lambda d: d["axes"]["C"].update(motion="linear"))
    assert "newer greybox" in broken(lambda d: d.update(format_version=99))
    assert "letters and digits" in broken(lambda d: d["axes"].update({"../Z": d["axes"]["X"]}))
    (directory / MANIFEST).write_text("{not json")
    with pytest.raises(ModelFileError, match="not a JSON manifest"):
        load_machine(directory)
    with pytest.raises(ModelFileError, match="holding a machine model"):
        load_model(directory)
