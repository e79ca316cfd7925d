"""Static friction models: Coulomb + viscous (IDIM-LS) and Stribeck + viscous."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
import scipy.io
import scipy.signal
from friction_signals import motion_log, velocity_profile
from model_files import write_members

from greybox.data.log import AxisLog
from greybox.errors import ParameterError
from greybox.identify.static import fit_stribeck
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, StribeckModel, stribeck_curve
from greybox.models.friction.coulomb import coulomb_friction


def log_with(current_of):
    log = motion_log(velocity_profile(20.0, seed=11))
    return log.replace(effort=current_of(log))


def test_coulomb_recovers_noise_free_parameters_exactly():
    log = log_with(lambda g: 0.002 * g.acceleration + 0.7 * np.sign(g.velocity) + 0.004 * g.velocity - 0.15)
    model = CoulombModel(fit_offset=True).fit(log)
    assert model.J_ == pytest.approx(0.002, rel=1e-10)
    assert model.coulomb_pos_ == model.coulomb_neg_ == pytest.approx(0.7, rel=1e-10)
    assert model.viscous_pos_ == model.viscous_neg_ == pytest.approx(0.004, rel=1e-10)
    assert model.offset_ == pytest.approx(-0.15, rel=1e-10)
    np.testing.assert_allclose(model.predict(log), log.effort, atol=1e-10)
    assert model.n_params == 4


def test_coulomb_inertia_is_never_negative():
    """Data whose best unconstrained fit has J < 0: J is held at 0 and the rest refitted by least squares."""
    log = log_with(lambda g: -0.001 * g.acceleration + 0.7 * np.sign(g.velocity) + 0.004 * g.velocity)
    unconstrained = np.linalg.lstsq(np.column_stack((log.acceleration, np.sign(log.velocity), log.velocity)),
                                    log.effort, rcond=None)[0]
    assert unconstrained[0] == pytest.approx(-0.001, rel=1e-8)
    model = CoulombModel().fit(log)
    assert model.J_ == 0.0
    friction_only = np.linalg.lstsq(np.column_stack((np.sign(log.velocity), log.velocity)), log.effort,
                                    rcond=None)[0]
    assert model.coulomb_pos_ == pytest.approx(friction_only[0], rel=1e-9)
    assert model.viscous_pos_ == pytest.approx(friction_only[1], rel=1e-9)


def test_asymmetric_coulomb_recovers_each_direction():
    truth = {"coulomb_pos": 0.6, "coulomb_neg": 0.8, "viscous_pos": 0.003, "viscous_neg": 0.005}
    log = log_with(lambda g: 0.001 * g.acceleration + coulomb_friction(g.velocity, **truth))
    model = CoulombModel(asymmetric=True).fit(log)
    for name, value in truth.items():
        assert getattr(model, name + "_") == pytest.approx(value, rel=1e-10)
    assert model.offset_ == 0.0 and model.n_params == 5
    with pytest.raises(ParameterError, match="not separately identifiable"):
        CoulombModel(asymmetric=True, fit_offset=True).fit(log)


def test_min_speed_leaves_slow_samples_out():
    # a different friction below 1 mm/s: excluded, the fit is exact on the rest
    log = log_with(lambda g: np.where(np.abs(g.velocity) < 1.0, 5.0, 0.7 * np.sign(g.velocity)))
    model = CoulombModel(min_speed=1.0).fit(log)
    assert model.coulomb_pos_ == pytest.approx(0.7, rel=1e-10)
    assert model.J_ == pytest.approx(0.0, abs=1e-12)


def test_static_models_are_odd():
    log = log_with(lambda g: 0.001 * g.acceleration + np.sign(g.velocity) * stribeck_curve(g.velocity, 0.9, 0.6, 3.0))
    mirrored = log.replace(velocity=-log.velocity, acceleration=-log.acceleration, effort=-log.effort)
    for model in (CoulombModel().fit(log), StribeckModel().fit(log)):
        np.testing.assert_allclose(model.predict(mirrored), -model.predict(log), rtol=0, atol=1e-15)


def test_stribeck_recovers_noise_free_parameters():
    log = log_with(lambda g: 0.0015 * g.acceleration
                   + np.sign(g.velocity) * stribeck_curve(g.velocity, 0.9, 0.6, 3.0) + 0.004 * g.velocity + 0.05)
    model = StribeckModel(fit_offset=True).fit(log)
    assert model.static_ == pytest.approx(0.9, rel=1e-6)
    assert model.coulomb_ == pytest.approx(0.6, rel=1e-6)
    assert model.v_s_ == pytest.approx(3.0, rel=1e-5)
    assert model.viscous_ == pytest.approx(0.004, rel=1e-6)
    assert model.J_ == pytest.approx(0.0015, rel=1e-6)
    assert model.offset_ == pytest.approx(0.05, rel=1e-5)
    assert model.n_params == 6


def test_stribeck_curve_decays_from_static_to_coulomb():
    v = np.array([-1e6, -3.0, 0.0, 3.0, 1e6])
    s = stribeck_curve(v, 0.9, 0.6, 3.0)
    np.testing.assert_allclose(s, [0.6, 0.6 + 0.3 / np.e, 0.9, 0.6 + 0.3 / np.e, 0.6])


#: Different Stribeck curves for positive and negative motion (magnitudes for the negative one).
ASYMMETRIC_TRUTH = {"coulomb": 0.6, "static": 0.9, "v_s": 3.0, "viscous": 0.004,
                    "coulomb_neg": 0.7, "static_neg": 1.2, "v_s_neg": 8.0, "viscous_neg": 0.006}


def asymmetric_stribeck(velocity, t):
    """Friction of the asymmetric Stribeck model with the parameters ``t``, written out [A]."""
    speed = np.abs(velocity)
    positive = t["coulomb"] + (t["static"] - t["coulomb"]) * np.exp(-speed / t["v_s"]) + t["viscous"] * velocity
    negative = (-(t["coulomb_neg"] + (t["static_neg"] - t["coulomb_neg"]) * np.exp(-speed / t["v_s_neg"]))
                + t["viscous_neg"] * velocity)
    return np.where(velocity > 0.0, positive, np.where(velocity < 0.0, negative, 0.0))


@pytest.fixture(scope="module")
def asymmetric_log():
    return log_with(lambda g: 0.0015 * g.acceleration + asymmetric_stribeck(g.velocity, ASYMMETRIC_TRUTH))


def test_asymmetric_stribeck_recovers_each_direction(asymmetric_log):
    model = StribeckModel(asymmetric=True).fit(asymmetric_log)
    for name, value in ASYMMETRIC_TRUTH.items():
        assert getattr(model, name + "_") == pytest.approx(value, rel=1e-6), name
    assert model.J_ == pytest.approx(0.0015, rel=1e-6)
    assert model.offset_ == 0.0 and model.n_params == 9
    np.testing.assert_allclose(model.predict(asymmetric_log), asymmetric_log.effort, rtol=0, atol=1e-6)
    rows = {row.name: row.value for row in model.parameter_table()}
    assert rows["v_s"] == model.v_s_ and rows["v_s_neg"] == model.v_s_neg_
    assert rows["static_neg"] == model.static_neg_ and rows["coulomb"] == model.coulomb_


def test_asymmetric_stribeck_fit_returns_both_directions(asymmetric_log):
    g = asymmetric_log
    params = fit_stribeck(g.velocity, g.acceleration, g.effort, asymmetric=True)
    for name, value in ASYMMETRIC_TRUTH.items():
        assert params[name] == pytest.approx(value, rel=1e-6), name
    assert params["offset"] == 0.0 and params["sse"] < 1e-8


def test_asymmetric_stribeck_with_equal_directions_is_the_symmetric_model():
    log = log_with(lambda g: 0.001 * g.acceleration + np.sign(g.velocity) * stribeck_curve(g.velocity, 0.9, 0.6, 3.0)
                   + 0.004 * g.velocity)
    symmetric = StribeckModel().fit(log)
    asymmetric = StribeckModel(asymmetric=True).fit(log)
    for name in ("coulomb", "static", "v_s", "viscous"):  # odd data: both directions fit alike
        assert getattr(asymmetric, name + "_neg_") == pytest.approx(getattr(asymmetric, name + "_"), rel=1e-6)
    for name in ("J", "coulomb", "static", "v_s", "viscous"):
        setattr(asymmetric, name + "_", getattr(symmetric, name + "_"))
        if name != "J":
            setattr(asymmetric, name + "_neg_", getattr(symmetric, name + "_"))
    mirrored = log.replace(velocity=-log.velocity, acceleration=-log.acceleration)
    np.testing.assert_array_equal(asymmetric.predict(log), symmetric.predict(log))
    np.testing.assert_array_equal(asymmetric.predict(mirrored), -asymmetric.predict(log))


def test_asymmetric_stribeck_refuses_an_offset(asymmetric_log):
    with pytest.raises(ParameterError, match="not separately identifiable"):
        StribeckModel(asymmetric=True, fit_offset=True).fit(asymmetric_log)
    g = asymmetric_log
    with pytest.raises(ParameterError, match="not separately identifiable"):
        fit_stribeck(g.velocity, g.acceleration, g.effort, asymmetric=True, fit_offset=True)
    with pytest.raises(ParameterError, match="asymmetric must be True or False"):
        StribeckModel(asymmetric="True").fit(asymmetric_log)


def test_asymmetric_stribeck_model_file_round_trip(asymmetric_log, tmp_path):
    model = StribeckModel(asymmetric=True).fit(asymmetric_log)
    loaded = load_model(save_model(model, tmp_path / "asymmetric.gbm"))
    assert loaded.asymmetric and loaded.v_s_neg_ == model.v_s_neg_
    unseen = motion_log(velocity_profile(8.0, seed=5))
    np.testing.assert_array_equal(loaded.predict(unseen), model.predict(unseen))


def test_symmetric_stribeck_file_without_the_asymmetric_flag_loads(asymmetric_log, tmp_path):
    """A model file written before the asymmetric variant existed: no flag, no ``*_neg_`` attributes."""
    model = StribeckModel(fit_offset=True).fit(asymmetric_log)
    path = save_model(model, tmp_path / "symmetric.gbm")
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    content = json.loads(members["model.json"])
    del content["model"]["params"]["asymmetric"]
    assert not any(name.endswith("_neg_") for name in content["model"]["attributes"])
    members["model.json"] = json.dumps(content).encode()
    old = tmp_path / "old.gbm"
    write_members(old, members)
    loaded = load_model(old)
    assert not loaded.asymmetric
    np.testing.assert_array_equal(loaded.predict(asymmetric_log), model.predict(asymmetric_log))
    assert [row.name for row in loaded.parameter_table()] == [row.name for row in model.parameter_table()]


def test_asymmetric_stribeck_linear_part_reproduces_the_prediction(asymmetric_log):
    model = StribeckModel(asymmetric=True).fit(asymmetric_log)
    part = model.linear_part(asymmetric_log)
    assert part.names == ("J", "coulomb_pos", "static_pos", "coulomb_neg", "static_neg", "viscous_pos", "viscous_neg")
    np.testing.assert_array_equal(part.lower, np.zeros(7))
    np.testing.assert_allclose(part.columns @ model.linear_coefficients() + part.fixed, model.predict(asymmetric_log),
                               rtol=0, atol=1e-12)
    new = model.linear_coefficients() * np.array([1.0, 1.1, 0.9, 1.2, 0.8, 1.3, 0.7])
    model.set_linear_coefficients(new)
    np.testing.assert_array_equal(model.linear_coefficients(), new)
    np.testing.assert_allclose(model.predict(asymmetric_log), part.columns @ new + part.fixed, rtol=0, atol=1e-12)


def emps_log(path):
    """The EMPS estimation run at 1 kHz, prepared as the benchmark's IDIM-LS script does (positions in mm)."""
    data = scipy.io.loadmat(path)
    time = data["t"].ravel()
    position = 1e3 * data["qm"].ravel()
    force = float(data["gtau"].ravel()[0]) * data["vir"].ravel()
    step = time[1] - time[0]
    b, a = scipy.signal.butter(4, 100.0 / (0.5 / step))
    smooth = scipy.signal.filtfilt(b, a, position)
    velocity = np.gradient(smooth, step)
    log = AxisLog(time=time, position=position, effort=force, velocity=velocity,
                  acceleration=np.gradient(velocity, step), effort_unit="N", source=str(path))
    return log.select(slice(49, None))


def test_coulomb_model_is_the_emps_idim_ls_estimator(real_data):
    """Published IDIM-LS estimates (Janot et al. 2019): M 95.1089 kg, Fv 203.5034 N s/m, Fc 20.3935 N,
    offset -3.1648 N; asymmetric: M 95.1540, Fv+ 166.7061, Fc+ 20.1440, Fv- 240.4236, Fc- 20.6277.
    The benchmark decimates by 10 before the fit; at 1 kHz the estimates agree within 2 %."""
    log = emps_log(real_data("EMPS") / "DATA_EMPS.mat")
    model = CoulombModel(fit_offset=True).fit(log)
    assert model.effort_unit_ == "N"
    assert 1e3 * model.J_ == pytest.approx(95.1089, rel=0.01)
    assert 1e3 * model.viscous_pos_ == pytest.approx(203.5034, rel=0.02)
    assert model.coulomb_pos_ == pytest.approx(20.3935, rel=0.02)
    assert model.offset_ == pytest.approx(-3.1648, rel=0.05)
    relerr = 100 * np.linalg.norm(model.predict(log) - log.effort) / np.linalg.norm(log.effort)
    assert relerr < 5.0
    asym = CoulombModel(asymmetric=True).fit(log)
    assert 1e3 * asym.J_ == pytest.approx(95.1540, rel=0.01)
    assert 1e3 * asym.viscous_pos_ == pytest.approx(166.7061, rel=0.02)
    assert asym.coulomb_pos_ == pytest.approx(20.1440, rel=0.02)
    assert 1e3 * asym.viscous_neg_ == pytest.approx(240.4236, rel=0.02)
    assert asym.coulomb_neg_ == pytest.approx(20.6277, rel=0.02)


@pytest.mark.parametrize("asymmetric, fit_offset", [(False, False), (False, True), (True, False)])
def test_the_kept_stribeck_columns_are_the_regressors_to_the_last_bit(asymmetric, fit_offset):
    from greybox.identify.static import _StribeckColumns, stribeck_regressors

    rng = np.random.default_rng(3)
    velocity = 20.0 * rng.standard_normal(2000)
    velocity[::9] = 0.0
    acceleration = rng.standard_normal(2000)
    columns = _StribeckColumns(velocity, acceleration, asymmetric, fit_offset)
    trials = [(3.0, 1.0), (3.0, 0.2), (0.7, 0.2), (3.0, 1.0)] if asymmetric else [3.0, 0.2, 3.0]
    for v_s in trials:  # one direction moved at a time, both, and back
        np.testing.assert_array_equal(columns.at(v_s), stribeck_regressors(velocity, acceleration, v_s, fit_offset))
