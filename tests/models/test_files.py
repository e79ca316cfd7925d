"""Model files: round trip without pickle, format versioning, clear errors."""

from __future__ import annotations

import io
import json
import math
import zipfile

import numpy as np
import pytest
from model_files import write_members
from sklearn.base import BaseEstimator

from greybox import atomic
from greybox.errors import ModelFileError, ParameterError
from greybox.models import files, registry
from greybox.models.files import FORMAT_VERSION, load_model, save_model


class ToyModel(BaseEstimator):
    """A small estimator with every kind of learned attribute a model file must hold."""

    def __init__(self, gain=1.5, bounds=(0.0, 2.0), label="toy", first_stage=None):
        self.gain = gain
        self.bounds = bounds
        self.label = label
        self.first_stage = first_stage

    def fit(self, x, y):
        x = np.asarray(x, dtype=float)
        self.coef_ = np.linalg.lstsq(np.column_stack([x, np.sin(x), np.ones_like(x)]), y, rcond=None)[0]
        self.offset_ = float(np.mean(y) / 3.0)
        self.n_iter_ = np.int64(7)
        self.converged_ = np.bool_(True)
        self.history_ = [0.1, 1 / 3, 2e-300]
        self.info_ = {"states": np.arange(12, dtype=np.float32).reshape(3, 4), "note": "ok", "bounds": (1, 2)}
        self.names_ = np.array(["z1", "z2"])
        self.missing_ = float("nan")
        self.limit_ = float("-inf")
        return self

    def predict(self, x):
        x = np.asarray(x, dtype=float)
        base = 0.0 if self.first_stage is None else self.first_stage.predict(x)
        return self.gain * (self.coef_[0] * x + self.coef_[1] * np.sin(x) + self.coef_[2]) + self.offset_ + base


def _check_toy(model):
    """The load check of the toy kind: refuse an incomplete learned state (coef_ must hold 3 numbers)."""
    if np.shape(getattr(model, "coef_", None)) != (3,):
        raise ParameterError("coef_ must hold 3 coefficients")


@pytest.fixture(autouse=True)
def toy_registered(monkeypatch):
    monkeypatch.setitem(registry.MODEL_CLASSES, "toy", ToyModel)
    real_check = files.check_fitted
    monkeypatch.setattr(files, "check_fitted",
                        lambda model: _check_toy(model) if isinstance(model, ToyModel) else real_check(model))


@pytest.fixture
def data():
    rng = np.random.default_rng(0)
    x = rng.uniform(-3, 3, 200)
    return x, 2.0 * x + np.sin(x) / 7 + rng.normal(0, 0.1, 200)


def _rewrite_json(path, change):
    """Rewrite model.json inside a saved file with ``change(document)`` applied."""
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    document = json.loads(members["model.json"])
    change(document)
    members["model.json"] = json.dumps(document).encode()
    write_members(path, members)


def test_round_trip_predicts_bit_identically(tmp_path, data):
    x, y = data
    model = ToyModel(gain=1.0 / 3.0).fit(x, y)
    path = save_model(model, tmp_path / "toy.gbm")
    loaded = load_model(path)
    assert type(loaded) is ToyModel
    assert np.array_equal(loaded.predict(x), model.predict(x))
    assert loaded.predict(x).tobytes() == model.predict(x).tobytes()
    assert loaded.get_params() == model.get_params()
    assert isinstance(loaded.bounds, tuple)


def test_learned_attributes_keep_values_and_types(tmp_path, data):
    model = ToyModel().fit(*data)
    loaded = load_model(save_model(model, tmp_path / "toy.gbm"))
    assert loaded.coef_.dtype == np.float64 and np.array_equal(loaded.coef_, model.coef_)
    assert loaded.info_["states"].dtype == np.float32
    assert np.array_equal(loaded.info_["states"], model.info_["states"])
    assert loaded.info_["bounds"] == (1, 2) and loaded.info_["note"] == "ok"
    assert loaded.history_ == model.history_  # exact floats, including 1/3 and a subnormal-range value
    assert loaded.n_iter_ == 7 and loaded.converged_ is True
    assert list(loaded.names_) == ["z1", "z2"]
    assert math.isnan(loaded.missing_) and loaded.limit_ == float("-inf")


def test_nested_fitted_model_round_trips(tmp_path, data):
    x, y = data
    first = ToyModel(gain=0.5).fit(x, y)
    model = ToyModel(first_stage=first).fit(x, y - first.predict(x))
    loaded = load_model(save_model(model, tmp_path / "two_stage.gbm"))
    assert isinstance(loaded.first_stage, ToyModel)
    assert loaded.predict(x).tobytes() == model.predict(x).tobytes()


def test_unfitted_model_round_trips(tmp_path):
    loaded = load_model(save_model(ToyModel(gain=3.0), tmp_path / "plain.gbm"))
    assert loaded.get_params() == ToyModel(gain=3.0).get_params()
    assert not hasattr(loaded, "coef_")


def test_file_is_a_zip_with_readable_json_and_npy(tmp_path, data):
    path = save_model(ToyModel().fit(*data), tmp_path / "toy.gbm")
    with zipfile.ZipFile(path) as archive:
        document = json.loads(archive.read("model.json"))
        assert document["format"] == "greybox-model"
        assert document["format_version"] == FORMAT_VERSION
        assert document["model"]["kind"] == "toy"
        assert document["model"]["params"]["gain"] == 1.5
        member = document["model"]["attributes"]["coef_"]["__ndarray__"]
        assert np.load(io.BytesIO(archive.read(member)), allow_pickle=False).shape == (3,)


def test_same_model_gives_same_bytes(tmp_path, data):
    model = ToyModel().fit(*data)
    first = save_model(model, tmp_path / "a.gbm").read_bytes()
    second = save_model(model, tmp_path / "b.gbm").read_bytes()
    assert first == second


def test_existing_file_is_not_overwritten_unless_asked(tmp_path, data):
    path = tmp_path / "toy.gbm"
    path.write_bytes(b"user data")
    with pytest.raises(ModelFileError, match=r"toy.gbm.*exists.*overwrite=True"):
        save_model(ToyModel(), path)
    assert path.read_bytes() == b"user data"
    save_model(ToyModel().fit(*data), path, overwrite=True)
    assert isinstance(load_model(path), ToyModel)
    assert [p.name for p in tmp_path.iterdir()] == ["toy.gbm"]  # no temporary files left


def test_failed_write_leaves_old_file_and_no_temporary(tmp_path, data, monkeypatch):
    path = save_model(ToyModel(gain=2.0), tmp_path / "toy.gbm")
    before = path.read_bytes()

    def broken_replace(source, target):
        raise OSError("disk full")

    monkeypatch.setattr(atomic.os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        save_model(ToyModel().fit(*data), path, overwrite=True)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["toy.gbm"]


def test_newer_format_version_is_refused(tmp_path):
    path = save_model(ToyModel(), tmp_path / "future.gbm")
    _rewrite_json(path, lambda d: d.update(format_version=FORMAT_VERSION + 1))
    with pytest.raises(ModelFileError, match=r"future\.gbm.*newer greybox"):
        load_model(path)


def test_unknown_kind_is_refused(tmp_path):
    path = save_model(ToyModel(), tmp_path / "alien.gbm")
    _rewrite_json(path, lambda d: d["model"].update(kind="os.system"))
    with pytest.raises(ModelFileError, match=r"alien\.gbm.*unknown model kind 'os.system'"):
        load_model(path)


def test_unknown_parameter_is_refused(tmp_path):
    path = save_model(ToyModel(), tmp_path / "odd.gbm")
    _rewrite_json(path, lambda d: d["model"]["params"].update(colour="red"))
    with pytest.raises(ModelFileError, match=r"odd\.gbm.*colour"):
        load_model(path)


def test_pickled_array_member_is_refused(tmp_path, data):
    path = save_model(ToyModel().fit(*data), tmp_path / "pickled.gbm")
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    member = json.loads(members["model.json"])["model"]["attributes"]["coef_"]["__ndarray__"]
    buffer = io.BytesIO()
    np.save(buffer, np.array([object()], dtype=object), allow_pickle=True)
    members[member] = buffer.getvalue()
    write_members(path, members)
    with pytest.raises(ModelFileError, match=r"pickled\.gbm.*cannot be read"):
        load_model(path)


@pytest.mark.parametrize(
    "content, message",
    [(b"not a zip", "not a ZIP"), (None, "model.json missing"), (b"{broken", "not valid JSON")],
)
def test_damaged_files_are_refused(tmp_path, content, message):
    path = tmp_path / "bad.gbm"
    if content is None:
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("other.txt", "x")
    elif content.startswith(b"{"):
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("model.json", content)
    else:
        path.write_bytes(content)
    with pytest.raises(ModelFileError, match=rf"bad\.gbm.*{message}"):
        load_model(path)


def test_missing_file_is_refused(tmp_path):
    with pytest.raises(ModelFileError, match=r"nothing\.gbm.*no such model file"):
        load_model(tmp_path / "nothing.gbm")


def test_values_that_need_pickle_are_refused_at_save(tmp_path, data):
    model = ToyModel().fit(*data)
    model.cache_ = np.array([object()], dtype=object)
    with pytest.raises(ModelFileError, match=r"cache_.*dtype object"):
        save_model(model, tmp_path / "toy.gbm")
    model.cache_ = {1: 2.0}
    with pytest.raises(ModelFileError, match="not a string"):
        save_model(model, tmp_path / "toy.gbm")
    assert not any(tmp_path.iterdir())


def test_unregistered_class_is_refused(tmp_path):
    class Unregistered(ToyModel):
        pass

    with pytest.raises(ModelFileError, match="Unregistered is not registered"):
        save_model(Unregistered(), tmp_path / "x.gbm")


# ------------------------------------------------------------ real models
def _axis_run(seed: int, n: int = 1500, dt: float = 0.002):
    """A prepared run: two-tone reversing motion, effort from inertia + Coulomb/viscous + noise [A]."""
    from greybox.data.log import AxisLog

    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    w1, w2 = 2 * np.pi * 0.7, 2 * np.pi * 2.3
    position = 20 * np.sin(w1 * t) + 2 * np.sin(w2 * t + seed)
    velocity = 20 * w1 * np.cos(w1 * t) + 2 * w2 * np.cos(w2 * t + seed)
    acceleration = -20 * w1**2 * np.sin(w1 * t) - 2 * w2**2 * np.sin(w2 * t + seed)
    effort = 2e-3 * acceleration + 1.5 * np.tanh(velocity / 2.0) + 0.01 * velocity + rng.normal(0, 0.05, n)
    return AxisLog(time=t, position=position, effort=effort, velocity=velocity, acceleration=acceleration,
                   source=f"run{seed}.csv")


def _real_models():
    from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel

    return [
        CoulombModel(fit_offset=True),
        CoulombModel(asymmetric=True),
        StribeckModel(),
        LuGreModel(n_starts=1, max_iter=40),
        GMSModel(n_elements=3, n_starts=1, max_iter=40),
    ]


@pytest.mark.parametrize("model", _real_models(), ids=lambda m: type(m).__name__)
def test_real_models_round_trip_bit_identically(tmp_path, model):
    train, test = [_axis_run(0), _axis_run(1)], _axis_run(2)
    model.fit(train)
    loaded = load_model(save_model(model, tmp_path / "model.gbm"))
    assert type(loaded) is type(model)
    assert loaded.get_params() == model.get_params()
    assert loaded.predict(test).tobytes() == model.predict(test).tobytes()
    assert loaded.predict(train).tobytes() == model.predict(train).tobytes()


@pytest.mark.parametrize("kind", ["stribeck", "lugre", "gms"])
def test_symmetric_model_files_from_before_the_asymmetric_option_still_load(tmp_path, kind):
    """Files written before ``asymmetric`` existed lack it (and every ``_neg_`` attribute): they load as symmetric."""
    model = registry.model_class(kind)(**({"max_iter": 40, "n_starts": 1} if kind != "stribeck" else {}))
    train, test = [_axis_run(0)], _axis_run(2)
    model.fit(train)
    path = save_model(model, tmp_path / "old.gbm")

    def as_before(document):
        entry = document["model"]
        assert entry["params"].pop("asymmetric") is False
        assert not any(name.endswith("_neg_") for name in entry["attributes"])

    _rewrite_json(path, as_before)
    loaded = load_model(path)
    assert loaded.asymmetric is False
    assert loaded.predict(test).tobytes() == model.predict(test).tobytes()


def test_registry_names_every_current_model():
    from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
    from greybox.models.gmssvr import GMSSVRModel
    from greybox.models.svr import SVRCurrentModel

    expected = {"coulomb": CoulombModel, "stribeck": StribeckModel, "lugre": LuGreModel, "gms": GMSModel,
                "svr": SVRCurrentModel, "gmssvr": GMSSVRModel}
    for kind, cls in expected.items():
        assert registry.model_class(kind) is cls
        assert registry.model_kind(cls()) == kind


def test_discovered_models_are_files_but_not_trainable_kinds():
    from greybox.models.augmented import AugmentedModel

    assert registry.model_class("augmented") is AugmentedModel
    assert registry.model_kind(AugmentedModel()) == "augmented"
    assert "augmented" not in registry.MODEL_CLASSES  # what `greybox train --model` offers


@pytest.fixture(scope="module")
def gms_file(tmp_path_factory):
    from greybox.models.friction import GMSModel

    path = tmp_path_factory.mktemp("gms") / "gms.gbm"
    save_model(GMSModel(n_elements=3, n_starts=1, max_iter=40).fit([_axis_run(0)]), path)
    return path


@pytest.mark.parametrize("attribute", ["k_", "alpha_", "J_", "effort_unit_"])
def test_missing_learned_attribute_is_one_clear_error(tmp_path, gms_file, attribute):
    path = tmp_path / "cut.gbm"
    path.write_bytes(gms_file.read_bytes())
    _rewrite_json(path, lambda document: document["model"]["attributes"].pop(attribute))
    with pytest.raises(ModelFileError, match=rf"cut\.gbm: invalid GMSModel.*{attribute[:-1]}"):
        load_model(path)


@pytest.mark.parametrize("change, message", [
    (lambda d: d["model"]["attributes"].update(slip_rate_=-1.0), "C must be positive"),
    (lambda d: d["model"]["attributes"].update(k_=[1.0, 2.0]), "malformed|same length"),
    (lambda d: d["model"]["attributes"].update(J_="heavy"), "malformed|not finite|could not convert"),
    (lambda d: d["model"]["params"].update(n_elements=-2), "n_elements must be a positive integer"),
])
def test_inconsistent_learned_state_is_refused(tmp_path, gms_file, change, message):
    path = tmp_path / "odd.gbm"
    path.write_bytes(gms_file.read_bytes())
    _rewrite_json(path, change)
    with pytest.raises(ModelFileError, match=rf"odd\.gbm: invalid GMSModel.*({message})"):
        load_model(path)


def test_flipped_byte_is_called_damaged_not_a_foreign_file(tmp_path, gms_file):
    data = bytearray(gms_file.read_bytes())
    with zipfile.ZipFile(gms_file) as archive:
        info = archive.getinfo("model.json")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)  # first byte of the member's data
    data[start + 10] ^= 0x01
    path = tmp_path / "flipped.gbm"
    path.write_bytes(bytes(data))
    with pytest.raises(ModelFileError, match=r"flipped\.gbm: damaged model file"):
        load_model(path)


def test_format_1_files_are_read_with_the_old_attribute_names(tmp_path, gms_file):
    """Version 1 named the GMS slip rate C_ (as the SVR's regularisation), its viscous coefficient mu_ and s0_."""
    reference = load_model(gms_file)
    path = tmp_path / "v1.gbm"
    path.write_bytes(gms_file.read_bytes())

    def to_version_1(document):
        document["format_version"] = 1
        attributes = document["model"]["attributes"]
        for old, new in (("C_", "slip_rate_"), ("mu_", "viscous_"), ("s0_", "s_0_")):
            attributes[old] = attributes.pop(new)

    _rewrite_json(path, to_version_1)
    old = load_model(path)
    assert (old.slip_rate_, old.viscous_, old.s_0_) == (reference.slip_rate_, reference.viscous_, reference.s_0_)
    run = _axis_run(3)
    np.testing.assert_array_equal(old.predict(run), reference.predict(run))


def test_every_single_flipped_byte_is_one_model_file_error(tmp_path, gms_file):
    """Whichever byte is damaged, loading ends in a ModelFileError (never another exception)."""
    original = gms_file.read_bytes()
    path = tmp_path / "flip.gbm"
    failures = []
    for position in range(len(original)):
        data = bytearray(original)
        data[position] ^= 0x10 if position % 2 else 0x01
        path.write_bytes(bytes(data))
        try:
            load_model(path)
        except ModelFileError:
            pass
        except Exception as error:  # noqa: BLE001 - the test looks for any other exception
            failures.append(f"byte {position}: {type(error).__name__}: {error}")
    assert not failures, "\n".join(failures[:5])


def test_save_verified_writes_a_file_that_predicts_what_the_model_did(tmp_path):
    from greybox.models.files import save_verified
    from greybox.models.friction import CoulombModel

    runs = [_axis_run(1), _axis_run(2)]
    model = CoulombModel().fit(runs)
    path = save_verified(model, tmp_path / "c.gbm", runs)
    loaded = load_model(path)
    for run in runs:
        np.testing.assert_array_equal(loaded.predict(run), model.predict(run))
    with pytest.raises(ModelFileError, match="file exists"):
        save_verified(model, path, runs)


def test_a_saved_model_that_predicts_otherwise_is_refused_naming_the_file(tmp_path):
    """The comparison is bit for bit: predictions off by one ulp on one run are refused."""
    from greybox.models.files import save_verified
    from greybox.models.friction import CoulombModel

    runs = [_axis_run(1), _axis_run(2)]
    model = CoulombModel().fit(runs)
    fitted = [model.predict(run) for run in runs]
    fitted[1] = np.nextafter(fitted[1], np.inf)
    with pytest.raises(ModelFileError, match=r"c\.gbm: the saved model does not reproduce"):
        save_verified(model, tmp_path / "c.gbm", runs, predictions=fitted)


def test_check_fitted_refuses_an_implausible_parameter_and_a_state_that_streams_otherwise(gms_file):
    from greybox.models.files import check_fitted

    model = load_model(gms_file)
    check_fitted(model)
    model.J_ = 1e300
    with pytest.raises(ParameterError, match="J = 1e.300 in magnitude"):
        check_fitted(model)
    model = load_model(gms_file)
    whole = model.predict_chunk

    def drifting(run, state=None, *, sample_time):  # a state that predicts otherwise chunk by chunk
        current, after = whole(run, state, sample_time=sample_time)
        return (current if state is None else current + 1.0), after

    model.predict_chunk = drifting
    with pytest.raises(ParameterError, match="chunked and one-shot prediction of a probe run differ"):
        check_fitted(model)


# -- the digest and the plant's signature (issue 41) -----------------------------------------------------------


def _members_of(path) -> dict:
    with zipfile.ZipFile(path) as archive:
        return {name: archive.read(name) for name in archive.namelist()}


def _write_raw(path, members) -> None:
    """Write the members as they are (a stale digest kept): an edit by hand with a ZIP tool."""
    with zipfile.ZipFile(path, "w") as archive:
        for name, content in members.items():
            archive.writestr(name, content)


def test_a_member_changed_added_or_removed_after_saving_is_refused_naming_it(tmp_path, data):
    path = save_model(ToyModel().fit(*data), tmp_path / "m.gbm")
    members = _members_of(path)
    assert json.loads(members[files.DIGEST_MEMBER])["members"].keys() == set(members) - {
        files.DIGEST_MEMBER}
    edited = dict(members, **{"model.json": members["model.json"].replace(b'"gain": 1.5', b'"gain": 2.0')})
    assert edited["model.json"] != members["model.json"]
    _write_raw(path, edited)
    with pytest.raises(ModelFileError, match=r"m\.gbm: member model\.json was changed after the file was written"):
        load_model(path)
    array = next(name for name in members if name.startswith("arrays/"))
    _write_raw(path, {name: data for name, data in members.items() if name != array})
    with pytest.raises(ModelFileError, match=rf"member {array} of the file's digest is missing"):
        load_model(path)
    _write_raw(path, {**members, "arrays/999_extra.npy": members[array]})
    with pytest.raises(ModelFileError, match="member arrays/999_extra.npy is not in the file's digest"):
        load_model(path)


def test_a_file_without_a_digest_loads_with_a_warning(tmp_path, data):
    path = save_model(ToyModel().fit(*data), tmp_path / "old.gbm")
    _write_raw(path, {name: content for name, content in _members_of(path).items()
                      if name != files.DIGEST_MEMBER})
    with pytest.warns(UserWarning, match="written before model files carried a digest"):
        load_model(path)


def test_a_signed_file_is_checked_with_the_plants_key(tmp_path, data, monkeypatch):
    model = ToyModel().fit(*data)
    monkeypatch.delenv(files.KEY_ENV, raising=False)
    monkeypatch.delenv(files.KEY_FILE_ENV, raising=False)
    unsigned = save_model(model, tmp_path / "unsigned.gbm")
    monkeypatch.setenv(files.KEY_ENV, "plant secret")
    signed = save_model(model, tmp_path / "signed.gbm")
    assert json.loads(_members_of(signed)[files.DIGEST_MEMBER])["hmac_sha256"]
    load_model(signed)
    with pytest.raises(ModelFileError, match="unsigned.gbm: not signed, and the plant's key is set"):
        load_model(unsigned)
    # a forger who edits a member and recomputes the digest cannot sign it without the key
    members = _members_of(signed)
    forged = dict(members, **{"model.json": members["model.json"].replace(b'"gain": 1.5', b'"gain": 2.0')})
    write_members(signed, forged, key=b"another key")
    with pytest.raises(ModelFileError, match="signature does not match the plant's key"):
        load_model(signed)
    write_members(signed, forged)
    with pytest.raises(ModelFileError, match="not signed"):
        load_model(signed)
    monkeypatch.delenv(files.KEY_ENV)
    assert load_model(signed).gain == 2.0  # without the key a consistent digest is all that is checked
    key_file = tmp_path / "key"
    key_file.write_bytes(b"plant secret\n")
    monkeypatch.setenv(files.KEY_FILE_ENV, str(key_file))
    write_members(signed, members, key=b"plant secret")  # the key file holds the same key
    load_model(signed)
    key_file.write_bytes(b"")
    with pytest.raises(ModelFileError, match="the model key file is empty"):
        load_model(signed)


def test_a_file_with_an_operating_record_tells_an_older_greybox_it_is_newer(tmp_path):
    """Format 4 added the ``operating`` record, format 5 its ``reversals``: a greybox that reads up to 4 says
    "newer greybox" (not a record error), and version-3 files (with or without that record) and version-4
    files (without ``reversals``) still load and predict the same; a version-4 file's region flags the motion
    by its grid alone, as before."""
    from export_logs import write_export_logs

    from greybox.cli import main
    from greybox.data.io import read_log
    from greybox.data.prepare import prepare

    logs = write_export_logs(tmp_path)
    path = tmp_path / "c.gbm"
    assert main(["train", "--model", "coulomb", "--train", str(logs["aircut_1"]), "--out", str(path),
                 "--quiet"]) == 0
    with zipfile.ZipFile(path) as archive:
        document = json.loads(archive.read("model.json"))
    assert document["format_version"] == FORMAT_VERSION == 5
    assert "reversals" in document["records"]["training"]["operating"]
    with pytest.raises(ModelFileError, match=r"c\.gbm: model file format version 5 was written by a newer greybox"):
        files.check_format(document, path, name=files.FORMAT_NAME, newest=4, what="model file")
    run = prepare([read_log(logs["aircut_1"])])[0]
    reference = load_model(path).predict(run)
    for name, change in (("v3.gbm", lambda d: d.update(format_version=3)),
                         ("v3_plain.gbm", lambda d: (d.update(format_version=3),
                                                     d["records"]["training"].pop("operating")))):
        older = tmp_path / name
        older.write_bytes(path.read_bytes())
        _rewrite_json(older, change)
        loaded, records = load_model(older, records=True)
        assert ("operating" in records["training"]) == (name == "v3.gbm")
        np.testing.assert_array_equal(loaded.predict(run), reference)
    older = tmp_path / "v4.gbm"
    older.write_bytes(path.read_bytes())
    _rewrite_json(older, lambda d: (d.update(format_version=4), d["records"]["training"]["operating"].pop("reversals")))
    loaded, records = load_model(older, records=True)
    np.testing.assert_array_equal(loaded.predict(run), reference)
    operating = records["training"]["operating"]
    assert "reversals" not in operating
    speed, span = operating["speed_edges"], operating["span_edges"]
    window = max(int(round(operating["window_s"] / run.sample_time)), 1)
    seen = {tuple(cell) for cell in operating["cells"]}
    grid_only = [(int(np.searchsorted(speed[1:-1], abs(v), side="right")),
                  int(np.searchsorted(span[1:-1], np.ptp(run.position[max(k - window + 1, 0):k + 1]), side="right")))
                 not in seen for k, v in enumerate(run.velocity)]
    np.testing.assert_array_equal(loaded.outside_training(run)["motion"], grid_only)
