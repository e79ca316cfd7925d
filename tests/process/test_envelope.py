"""The teach-in envelope: what it learns from good parts, re-levelling, its limits, its file."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from process_parts import good_parts, make_part
from scipy.stats import t as student

from greybox.errors import GreyboxError
from greybox.process.envelope import Envelope, band_count, level_direction, relevelled


def test_band_count_recovers_the_number_of_independent_values_behind_part_maxima():
    rng = np.random.default_rng(3)
    maxima = np.abs(rng.standard_t(40, size=(400, 250))).max(axis=1)
    estimate, upper = band_count(maxima, 40, 1.0)
    assert estimate == pytest.approx(250, rel=0.15) and upper > estimate
    few, few_upper = band_count(maxima[:10], 40, 1.0)
    assert few_upper / few == pytest.approx(student_chi2_ratio(10))


def student_chi2_ratio(n):
    from scipy.stats import chi2

    return chi2.ppf(0.95, 2 * n) / (2 * n)


def test_band_count_of_correlated_values_is_smaller_than_their_number():
    rng = np.random.default_rng(4)
    noise = rng.standard_normal((300, 5000))
    kernel = np.ones(50) / np.sqrt(50)  # a moving sum of 50: unit variance, correlated over 50 values
    smoothed = np.array([np.convolve(row, kernel, mode="valid") for row in noise])
    estimate, _ = band_count(np.abs(smoothed).max(axis=1), 1e6, 1.0)
    # fewer than the values, and more than the windows (L / w, the earlier rule's count, undercounts maxima)
    assert 2 * 4950 / 50 < estimate < 4950 / 2


def test_level_direction_holds_the_last_motion_at_rest():
    v = np.array([0, 0, -1, -1, 0, 0, 2, 2, 0.0])
    np.testing.assert_array_equal(level_direction(v), [1, 1, -1, -1, -1, -1, 1, 1, 1])


def test_envelope_learns_the_cut_where_the_parts_cut_and_sets_its_limits_by_the_rule():
    parts = good_parts(12, seed=1)
    envelope = Envelope(false_alarm_rate=1e-3, smoothing_s=0.1).fit(parts, unit="A")
    reference = next(p for p in parts if len(p.time) == envelope.reference_velocity_.size)
    time = np.arange(envelope.centre_.size) * envelope.sample_time_
    start = reference.time[np.flatnonzero(reference.velocity)[0]]
    inside = (time > start + 1.2) & (time < start + 4.8)
    outside = (time < start + 0.8) | (time > start + 5.2)
    assert envelope.cut_[inside].all() and not envelope.cut_[outside].any()
    assert envelope.cut_load_ == pytest.approx(2.0, abs=0.05)  # friction 1 + cut 1 on the raw signal
    # the band from the effective count: a part's largest deviation passes it with probability 1e-3 / 2
    per_value = 2 * student.sf(envelope.band_factor_ / math.sqrt(1 + 1 / 12), 5 * 11)
    assert 1 - (1 - per_value) ** envelope.band_count_ == pytest.approx(0.5e-3)
    assert 1 <= envelope.band_count_ < envelope.centre_.size
    assert envelope.air_.any() and not (envelope.air_ & envelope.cut_).any()


def test_relevelling_removes_a_friction_change_that_the_plain_envelope_flags():
    from greybox.process.check import check_part

    rng = np.random.default_rng(5)
    teach = good_parts(10, seed=2)
    warm = make_part(99, rng, friction=0.8)
    plain = Envelope().fit(teach)
    levelled = Envelope(relevel=True).fit(teach)
    assert check_part(plain, warm).flagged
    done = check_part(levelled, warm)
    assert not done.flagged
    assert done.offsets["negative"] == pytest.approx(0.2, abs=0.02)  # raw: an offset, -0.8 + 1 in -x
    assert done.offsets["positive"] == pytest.approx(-0.2, abs=0.02)


def test_relevelling_a_models_signal_scales_the_models_current_to_the_air():
    signal = np.array([0.5, 0.5, 2.5, 2.5, -0.3, -0.3])  # 0.5 x the template in air, plus a cut of 2
    template = np.array([1.0, 1.0, 1.0, 1.0, -1.0, -1.0])
    direction = np.array([1, 1, 1, 1, -1, -1.0])
    air = np.array([True, True, False, False, True, True])
    out, factors = relevelled(signal, direction, air, template=template)
    np.testing.assert_allclose(out, [0, 0, 2, 2, 0, 0], atol=1e-12)
    assert factors == {"negative": pytest.approx(0.3), "positive": pytest.approx(0.5)}
    teach = good_parts(6, seed=3, with_level=True)
    envelope = Envelope(relevel=True).fit(teach)
    assert envelope.scaled_
    warm = make_part(7, np.random.default_rng(1), friction=0.75, with_level=True)
    from greybox.process.check import check_part

    done = check_part(envelope, warm)
    assert not done.flagged and done.cut_load == pytest.approx(1.0, abs=0.02)


def test_an_envelope_file_round_trips_and_bad_files_are_refused_by_name(tmp_path):
    envelope = Envelope(relevel=True).fit(good_parts(5, seed=4), unit="A", signal={"kind": "raw"})
    path = envelope.save(tmp_path / "env.json")
    again = Envelope.load(path)
    for name in Envelope._ARRAYS:
        np.testing.assert_array_equal(getattr(again, name), getattr(envelope, name))
    assert again.band_factor_ == envelope.band_factor_ and again.relevel and again.signal_ == {"kind": "raw"}
    content = json.loads(path.read_text())

    def refused(change, match):
        bad = json.loads(json.dumps(content))
        change(bad)
        target = tmp_path / "bad.json"
        target.write_text(json.dumps(bad))
        with pytest.raises(GreyboxError, match=f"bad.json: not a valid envelope file.*{match}"):
            Envelope.load(target)

    refused(lambda c: c.update(format="pickle"), "format")
    refused(lambda c: c.update(format="greybox-envelope/1"), "earlier band rule: teach it again")
    refused(lambda c: c.update(band_count_=0.5), "out of range")
    refused(lambda c: c["arrays"]["centre_"].pop(), "centre_")
    refused(lambda c: c["arrays"]["cut_"].__setitem__(0, 1), "cut_")
    refused(lambda c: c.update(band_factor_="5"), "band_factor_")
    refused(lambda c: c["params"].update(false_alarm_rate=2.0), "false-alarm rate")
    refused(lambda c: c["arrays"]["spread_"].__setitem__(3, -1.0), "spread")
    refused(lambda c: c["params"].update(code="__import__('os')"), "params")
    (tmp_path / "nan.json").write_text(path.read_text().replace('"cut_load_": ', '"cut_load_": NaN, "x": ', 1))
    with pytest.raises(GreyboxError, match="nan.json: not a valid envelope file"):
        Envelope.load(tmp_path / "nan.json")
    with pytest.raises(GreyboxError, match="missing.json: cannot read"):
        Envelope.load(tmp_path / "missing.json")


def test_teach_in_refuses_too_few_parts_and_bad_settings():
    with pytest.raises(GreyboxError, match="at least 3"):
        Envelope().fit(good_parts(2))
    with pytest.raises(GreyboxError, match="false-alarm rate"):
        Envelope(false_alarm_rate=0.0).fit(good_parts(3))
