"""``greybox.models.plant``: a fleet run's manifest, the machine of a log, the models directory of --per-machine."""

from __future__ import annotations

import json

import pytest

from greybox.errors import GreyboxError
from greybox.models.plant import (
    MANIFEST,
    MODELS_FORMAT,
    load_manifest,
    machine_models,
    machine_of,
    model_of_log,
    partition,
    read_manifest,
)


def test_the_machine_of_a_log_is_its_folder_made_safe_for_a_path(tmp_path):
    assert machine_of(tmp_path / "mill 1" / "monday.csv") == "mill_1"
    assert machine_of("plant/mill-2.b/x.mcap") == "mill-2.b"
    assert partition("") == "_" and partition("a/b") == "a_b"


def test_a_manifest_is_read_by_its_format_and_anything_else_is_none(tmp_path):
    assert load_manifest(tmp_path) == {} and read_manifest(tmp_path, MODELS_FORMAT) == {}
    (tmp_path / MANIFEST).write_text(json.dumps({"format": "greybox-fleet", "logs": []}))
    assert load_manifest(tmp_path)["format"] == "greybox-fleet"
    assert read_manifest(tmp_path, MODELS_FORMAT) == {}  # another kind of run
    for unreadable in ("{not json", "[1, 2]", "\udcff"):
        (tmp_path / MANIFEST).write_text(unreadable, errors="surrogateescape")
        assert load_manifest(tmp_path) == {}


def test_a_log_gets_the_model_of_its_machine_listed_as_trained(tmp_path):
    models = tmp_path / "models"
    (models / "mill1").mkdir(parents=True)
    for name in ("X.gbm", "Y.gbm", "Z.gbm"):
        (models / "mill1" / name).write_bytes(b"model")
    entries = [{"status": "ok", "machine": "mill1", "axis": "X", "output": "mill1/X.gbm"},
               {"status": "skipped", "machine": "mill1", "axis": "Y", "output": "mill1/Y.gbm"},
               {"status": "failed", "machine": "mill1", "axis": "Z", "output": "mill1/Z.gbm"},
               {"status": "ok", "machine": "mill2", "axis": "X", "output": "mill2/X.gbm"}]  # file not there
    (models / MANIFEST).write_text(json.dumps({"format": MODELS_FORMAT, "models": entries}))
    assert machine_models(models) == {"mill1": {"X": str(models / "mill1" / "X.gbm"),
                                                "Y": str(models / "mill1" / "Y.gbm")}}
    log = tmp_path / "mill1" / "monday.csv"
    assert model_of_log(models, log, "Y") == str(models / "mill1" / "Y.gbm")
    with pytest.raises(GreyboxError, match="has models of axes X, Y .*give --axis NAME"):
        model_of_log(models, log)
    with pytest.raises(GreyboxError, match="--axis Z: machine mill1 has models of axes X, Y"):
        model_of_log(models, log, "Z")
    with pytest.raises(GreyboxError, match=r"no trained model of machine mill2 .*\(machines: mill1\)"):
        model_of_log(models, tmp_path / "mill2" / "monday.csv", "X")
    with pytest.raises(GreyboxError, match="without the _manifest.json of 'greybox train --per-machine'"):
        machine_models(tmp_path)
