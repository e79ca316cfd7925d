"""The compensation workflow's feed-forward models: loaded from files, fitted by kind, named."""

from __future__ import annotations

import pytest

from greybox.control.plants import ModelPlant, TwinPlant
from greybox.control.workflow import feedforward_models, synthesises_training
from greybox.errors import GreyboxError, ModelFileError
from greybox.models.files import save_model
from greybox.models.friction import CoulombModel


@pytest.fixture(scope="module")
def twin_runs():
    from greybox.data.prepare import prepare
    from greybox.twin import make_dataset

    return prepare([make_dataset("X", "A", seed=3, duration_s=4.0)])


def test_files_and_fitted_kinds_are_named_by_kind_and_by_origin_when_a_kind_repeats(tmp_path, twin_runs):
    plant = TwinPlant.for_axis("X")
    save_model(CoulombModel().fit(twin_runs), tmp_path / "shop.gbm")
    built, lines = [], []

    def build(kind):
        built.append(kind)
        return CoulombModel(fit_offset=True)

    models = feedforward_models(plant, model_files=[tmp_path / "shop.gbm"], kinds=["coulomb", "coulomb"],
                                build=build, train_runs=twin_runs, progress=lines.append)
    assert list(models) == ["coulomb (shop)", "coulomb (fitted)"]
    assert built == ["coulomb"]  # a kind given twice is fitted once
    assert models["coulomb (fitted)"].fit_offset and hasattr(models["coulomb (fitted)"], "J_")
    assert len(lines) == 1 and lines[0].startswith("fitted coulomb on 1 run(s)")


def test_a_model_plant_needs_training_runs_and_a_rotary_model_does_not_fit_a_linear_plant(tmp_path, twin_runs):
    plant = ModelPlant(_gms(twin_runs), name="p")
    assert not synthesises_training(plant) and synthesises_training(TwinPlant.for_axis("X"))
    with pytest.raises(GreyboxError, match="model plant need training logs"):
        feedforward_models(plant, kinds=["coulomb"], build=lambda kind: CoulombModel())
    with pytest.raises(GreyboxError, match="no feed-forward model"):
        feedforward_models(plant)
    with pytest.raises(ModelFileError, match="nope.gbm: no such model file"):
        feedforward_models(plant, model_files=[tmp_path / "nope.gbm"])
    rotary = [run.replace(motion="rotary", effort_unit="A") for run in twin_runs]
    save_model(CoulombModel().fit(rotary), tmp_path / "c.gbm")
    with pytest.raises(GreyboxError, match="c.gbm: a rotary axis, the plant p is a linear one"):
        feedforward_models(plant, model_files=[tmp_path / "c.gbm"])


def _gms(runs):
    from greybox.models.friction import GMSModel

    return GMSModel(n_elements=2, n_starts=1, max_iter=30).fit(runs)
