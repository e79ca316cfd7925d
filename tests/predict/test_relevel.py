"""Re-levelling on the log's own air moves: the air found without the program, a changed friction scaled away,
the chunk's factor carried where it has too few air samples."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.predict.relevel import MIN_AIR_S, Relevel, air_samples, level_direction, relevelled

DT = 0.002


def _stroke_log(rng, *, friction=0.8, cut=0.3, noise=0.02, seconds=30.0):
    """Strokes of 3 s at 10 mm/s in -x (a cut of ``cut`` A in the middle second) and 1 s back at 30 mm/s in +x;
    the plant's friction ``friction`` times the model's."""
    period = np.concatenate([np.full(int(3.0 / DT), -10.0), np.full(int(1.0 / DT), 30.0)])
    velocity = np.tile(period, int(seconds / 4.0))
    n = velocity.size
    time = np.arange(n) * DT
    model = np.where(velocity < 0, -1.0, 1.2)  # the model's friction per direction [A]
    phase = np.tile(np.arange(period.size), int(seconds / 4.0))
    cutting = (velocity < 0) & (phase >= int(1.0 / DT)) & (phase < int(2.0 / DT))
    process = np.where(cutting, -cut, 0.0)
    measured = friction * model + process + noise * rng.standard_normal(n)
    return time, velocity, model, measured, cutting


def test_air_is_found_without_the_program_and_the_scale_fitted_on_it():
    time, velocity, model, measured, cutting = _stroke_log(np.random.default_rng(0))
    air = air_samples(measured - model, model, velocity, width=50)
    assert not (air & cutting).any()  # no cut sample counted as air
    assert air[velocity > 0].mean() > 0.8 and air[(velocity < 0) & ~cutting].mean() > 0.6
    _, factors = relevelled(measured - model, level_direction(velocity), air, template=model)
    assert factors["negative"] == pytest.approx(-0.2, abs=0.005) and factors["positive"] == pytest.approx(-0.2,
                                                                                                         abs=0.005)


def test_a_relevelled_chunk_keeps_the_cut_and_removes_the_friction_change():
    time, velocity, model, measured, cutting = _stroke_log(np.random.default_rng(1), friction=0.75)
    scaled = Relevel(sample_time=DT).model(time, measured, model, velocity)
    process = measured - scaled
    plain = measured - model
    assert abs(np.mean(plain[cutting]) + 0.3) > 0.2  # without: the friction's fall is in the cut's force
    assert np.mean(process[cutting]) == pytest.approx(-0.3, rel=0.02)
    assert abs(np.mean(process[~cutting & (velocity != 0)])) < 0.005


def test_a_chunk_without_enough_air_carries_the_previous_factor():
    time, velocity, model, measured, _ = _stroke_log(np.random.default_rng(2), friction=0.8)
    level = Relevel(sample_time=DT)
    level.model(time, measured, model, velocity)
    first = dict(level.corrections_)
    short = slice(0, int(0.5 * MIN_AIR_S / DT))  # half the air it needs, in -x only
    level.model(time[short], measured[short], model[short], velocity[short])
    assert level.corrections_ == first and level.chunks_[-1]["air_s"] == {"negative": 0.0, "positive": 0.0}


@pytest.mark.slow  # a fit, a log written, predicted streamed and whole twice: 8 s
def test_predict_relevels_a_streamed_log_as_a_whole_one_and_refuses_a_fleet(tmp_path):
    from greybox.data.io import write_log
    from greybox.data.prepare import prepare
    from greybox.data.reading import read_prepared
    from greybox.errors import GreyboxError
    from greybox.models.files import save_model
    from greybox.models.friction import CoulombModel
    from greybox.predict import predict_logs
    from greybox.predict.process import predict_process
    from greybox.twin import make_dataset

    model = CoulombModel(fit_offset=True).fit(prepare([make_dataset("X", "A", seed=3, duration_s=5)])[0])
    save_model(model, tmp_path / "model.gbm")
    write_log(make_dataset("X", "C", seed=4, duration_s=16, cutting=True).replace(extras={}),
              tmp_path / "cut.parquet")
    done = predict_logs(tmp_path / "model.gbm", tmp_path / "cut.parquet", out=tmp_path / "out.parquet", chunk_s=4.0,
                        relevel=True)
    import pyarrow.parquet as pq

    table = pq.read_table(tmp_path / "out.parquet").to_pandas()
    whole = predict_process(model, read_prepared(str(tmp_path / "cut.parquet"), {}), chunk_s=4.0, relevel=True)
    plain = predict_process(model, read_prepared(str(tmp_path / "cut.parquet"), {}), chunk_s=4.0)
    np.testing.assert_allclose(table["current_process_A"], whole.process, atol=1e-9)
    assert not np.allclose(whole.process, plain.process) and len(whole.attrs["relevel"]) == 4
    assert done.written
    with pytest.raises(GreyboxError, match="relevel"):
        predict_logs(tmp_path / "model.gbm", [tmp_path / "cut.parquet", tmp_path / "cut.parquet"],
                     out=tmp_path / "fleet", relevel=True)
