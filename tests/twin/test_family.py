"""The family of truth axes: laws against their plain-Python references, physics, drawing, files."""

from __future__ import annotations

import json
import math

import family_reference as ref
import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin.cutting import CuttingSpec
from greybox.twin.family import FAMILY_RANGES, draw_member, member_dataset, synthesize_family
from greybox.twin.laws import TRUTH_LAWS, BacklashScrewLaw, BristleLaw, DahlLaw, MaxwellSlipLaw
from greybox.twin.laws.bristle import bristle_update
from greybox.twin.laws.dahl import dahl_kernel, dahl_update

STEP = 0.25e-3


def sine_motion(amplitude_mm=0.5, frequency_hz=1.0, duration_s=2.0, centre=-250.0):
    t = np.arange(int(duration_s / STEP) + 1) * STEP
    w = 2 * math.pi * frequency_hz
    return (centre + amplitude_mm * np.sin(w * t), amplitude_mm * w * np.cos(w * t),
            -amplitude_mm * w * w * np.sin(w * t))


def ramp_motion(speed_mm_s, duration_s=0.5, start=-250.0):
    t = np.arange(int(duration_s / STEP) + 1) * STEP
    return start + speed_mm_s * t, np.full_like(t, speed_mm_s), np.zeros_like(t)


# ------------------------------------------------------------------ kernels against references
def test_bristle_kernel_matches_plain_python_reference():
    x, v, _ = sine_motion()
    law = BristleLaw(1.2, 0.7, 3.0, 1.5, 2e-3, 0.01)
    got = law.friction_samples(x, v, STEP, 8)
    want = ref.bristle(x, v, 8, law.stiffness_A_mm, law.damping_A_s_mm, law.static_A, law.coulomb_ratio,
                       law.stribeck_velocity_mm_s, law.stribeck_shape)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("alpha", [0.5, 1.0, 1.7])
def test_dahl_kernel_matches_plain_python_reference(alpha):
    x, v, _ = sine_motion(amplitude_mm=0.02, frequency_hz=2.0)
    law = DahlLaw(0.9, 5e-3, alpha)
    np.testing.assert_allclose(law.friction_samples(x, v, STEP, 8),
                               ref.dahl(x, 8, 0.9, 0.9 / 5e-3, alpha), rtol=1e-12, atol=1e-12)


def test_backlash_kernel_matches_plain_python_reference():
    x, v, a = sine_motion(amplitude_mm=0.3)
    law = BacklashScrewLaw(0.01, 0.4, 2e-3, 0.8, 0.7, 3.0, 1.5, 1e-3, 0.7, 2e-3)
    response = law.respond(x, v, a, STEP, 8, 4e-4)
    friction, table = ref.backlash_screw(x, v, a, STEP, 8, law, 0.7 * 4e-4)
    np.testing.assert_allclose(response.friction_A, friction, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(response.inertia_A, 0.3 * 4e-4 * a[::8] + table, rtol=1e-12, atol=1e-12)


def test_maxwell_slip_law_reaches_its_stribeck_level_in_steady_sliding():
    law = MaxwellSlipLaw((0.5, 0.5), (1e-3, 2e-3), 0.8, 2.0, 2.0, 0.0)
    for speed in (0.5, 2.0, 20.0):
        x, v, _ = ramp_motion(speed)
        level = 1.0 * (0.8 + 0.2 * math.exp(-(speed / 2.0) ** 2))
        assert law.friction_samples(x, v, STEP, 8)[-1] == pytest.approx(level, rel=1e-9)


# ------------------------------------------------------------------ exactness and physics
def test_bristle_update_is_exact_one_step_equals_many():
    z0, g = -0.8e-3, 1.1e-3
    one = bristle_update(z0, 2e-3, g)
    many = z0
    for _ in range(64):
        many = bristle_update(many, 2e-3 / 64, g)
    assert one == pytest.approx(many, rel=1e-12)


def test_bristle_steady_state_is_the_stribeck_curve():
    law = BristleLaw(1.2, 0.7, 3.0, 1.5, 2e-3, 0.01)
    for speed in (-15.0, -1.0, 2.0, 30.0):
        x, v, _ = ramp_motion(speed)
        steady = math.copysign(1.2 * ref.stribeck(speed, 0.7, 3.0, 1.5), speed)
        assert law.friction_samples(x, v, STEP, 8)[-1] == pytest.approx(steady, rel=1e-9)


@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0])
def test_dahl_update_is_exact_one_step_equals_many(alpha):
    one = dahl_update(-0.3, 4e-3, 1.0, 200.0, alpha)
    many = -0.3
    for _ in range(100):
        many = dahl_update(many, 4e-5, 1.0, 200.0, alpha)
    assert one == pytest.approx(many, rel=1e-10, abs=1e-12)


def test_dahl_is_rate_independent():
    slow, fast = sine_motion(0.02, 1.0, 2.0), sine_motion(0.02, 2.0, 1.0)
    law = DahlLaw(0.9, 5e-3, 1.3)
    np.testing.assert_allclose(dahl_kernel(slow[0], 16, 0.9, 180.0, 1.3), dahl_kernel(fast[0], 8, 0.9, 180.0, 1.3),
                               atol=1e-9)
    assert np.max(np.abs(law.friction_samples(*slow[:2], STEP, 8))) <= 0.9


def test_dahl_with_exponent_below_one_reaches_its_level_after_finite_travel():
    # y^(1/2) falls linearly: from y = 1 (F = 0) to 0 after |dx| = 2 F_c / sigma_0
    assert dahl_update(0.0, 2 * 1.0 / 200.0 * 1.0001, 1.0, 200.0, 0.5) == 1.0
    assert dahl_update(0.0, 2 * 1.0 / 200.0 * 0.99, 1.0, 200.0, 0.5) < 1.0


def test_backlash_motor_crosses_the_play_with_nut_friction_only_then_drives_the_table():
    # forward, reverse, back: after the reversal the motor travels the play before the table follows
    play = 0.02
    law = BacklashScrewLaw(play, 0.3, 1e-3, 0.8, 0.8, 3.0, 2.0, 1e-3, 0.7, 2e-3)
    speed = 2.0
    t = np.arange(int(1.0 / STEP) + 1) * STEP
    v = np.where(t < 0.5, speed, -speed)
    x = -250.0 + np.concatenate(([0.0], np.cumsum(v[1:]) * STEP))
    response = law.respond(x, v, np.zeros_like(x), STEP, 1, 4e-4)
    after = np.flatnonzero(t >= 0.5)
    gap_steps = after[:int(round(play / (speed * STEP))) - 1]
    # while the play is open: the nut's Dahl friction alone (saturates at -0.3 A within 10 um)
    assert np.all(np.abs(response.friction_A[gap_steps]) <= 0.3 + 1e-12)
    assert response.friction_A[gap_steps[-1]] == pytest.approx(-0.3, abs=1e-3)
    # then nut plus guideway in sliding: -(0.3 + 0.8 * Stribeck ratio at 2 mm/s)
    sliding = -(0.3 + 0.8 * ref.stribeck(speed, 0.8, 3.0, 2.0))
    assert response.friction_A[-1] == pytest.approx(sliding, rel=1e-6)


def test_backlash_contact_pulse_carries_the_tables_momentum():
    law = BacklashScrewLaw(0.005, 0.3, 1e-3, 0.8, 0.8, 3.0, 2.0, 1e-3, 0.7, 2e-3)
    t = np.arange(int(0.2 / STEP) + 1) * STEP
    v = np.full_like(t, 5.0)
    v[0] = 0.0
    x = -250.0 + np.concatenate(([0.0], np.cumsum(v[1:]) * STEP))
    response = law.respond(x, v, np.zeros_like(x), STEP, 1, 4e-4)
    assert np.sum(response.inertia_A) * STEP == pytest.approx(0.7 * 4e-4 * 5.0, rel=0.01)


# ------------------------------------------------------------------ drawing members
def test_members_are_reproducible_cycle_the_laws_and_do_not_depend_on_the_family_size():
    members = [draw_member(i, 3) for i in range(8)]
    assert [m.law for m in members] == list(TRUTH_LAWS) * 2
    assert draw_member(5, 3) == members[5]
    assert draw_member(5, 4) != members[5]


def test_drawn_parameters_lie_in_their_documented_ranges():
    for index in range(40):
        member = draw_member(index, 11)
        plant, law = member.plant, member.plant.law
        for name, (low, high, *_rest) in law.RANGES.items():
            if hasattr(law, name):
                assert low <= getattr(law, name) <= high, (law.name, name)
        for name in ("inertia_A_s2_mm", "viscous_A_s_mm", "preload_gain", "tilt_gain", "lead_gain", "load_gain",
                     "cogging_A"):
            low, high = FAMILY_RANGES[name][:2]
            assert low <= getattr(plant, name) <= high, name
        assert FAMILY_RANGES["noise_std_A"][0] <= member.noise.std_A <= FAMILY_RANGES["noise_std_A"][1]
        assert plant.cogging_period_mm == pytest.approx(plant.lead_mm / round(plant.lead_mm / plant.cogging_period_mm))


def test_member_log_components_add_up_and_carry_the_member():
    member = draw_member(3, 0)
    log = member_dataset(member, "A", duration_s=5.0)
    e = log.extras
    np.testing.assert_allclose(e["truth_current_A"],
                               e["truth_friction_A"] + e["truth_inertia_A"] + e["truth_cogging_A"], atol=1e-12)
    assert log.attrs["family_member"] == {"index": 3, "family_seed": 0, "law": "backlash_screw", "repeat": 0}
    assert log.attrs["plant"]["law"]["law"] == "backlash_screw"
    step = member.sensors.position_resolution_mm
    assert np.allclose(np.round(log.position / step) * step, log.position, atol=1e-9)


def test_a_cut_loads_the_screw_and_raises_the_friction_by_the_load_gain():
    member = draw_member(2, 0)
    air = member_dataset(member, "C", duration_s=10.0)
    cut = member_dataset(member, "C", duration_s=10.0, cutting=CuttingSpec(strength_A=1.0))
    process, inertia = cut.extras["truth_process_A"], cut.extras["truth_inertia_A"]
    assert np.any(process != 0)
    extra = cut.extras["truth_friction_A"] - air.extras["truth_friction_A"]
    load = member.plant.load_gain * (np.abs(inertia + process) - np.abs(inertia))
    in_cut = process != 0
    assert np.all(np.abs(extra[in_cut]) <= np.abs(load[in_cut]) + 1e-12)
    assert np.median(np.abs(extra[in_cut]) / np.abs(load[in_cut])) > 0.9  # sliding: the direction is near +-1
    np.testing.assert_array_equal(extra[~in_cut], 0.0)


def test_bad_member_index_and_family_size_are_refused():
    with pytest.raises(GreyboxError, match="index"):
        draw_member(-1, 0)
    with pytest.raises(GreyboxError, match="family size"):
        synthesize_family(0, 1, "unused")


# ------------------------------------------------------------------ files and command line
def test_synthesize_family_writes_members_and_a_catalogue_and_keeps_existing_files(tmp_path):
    written = synthesize_family(2, 5, tmp_path, ["A"], duration_s=3.0)
    assert [p.relative_to(tmp_path).as_posix() for p in written] == [
        f"member_000/{draw_member(0, 5).axis}_A.mcap", f"member_001/{draw_member(1, 5).axis}_A.mcap"]
    catalogue = json.loads((tmp_path / "family.json").read_text())
    assert [m["law"] for m in catalogue["members"]] == ["maxwell_slip", "lugre_bristle"]
    before = written[0].read_bytes()
    with pytest.raises(GreyboxError, match="file exists"):
        synthesize_family(2, 6, tmp_path, ["A"], duration_s=3.0)
    assert written[0].read_bytes() == before


def test_the_documented_ranges_are_the_drawn_ranges():
    from pathlib import Path

    from greybox.twin.family import ranges_markdown

    docs = (Path(__file__).resolve().parents[2] / "docs" / "synthetic-axis.md").read_text()
    assert ranges_markdown() in docs
