"""Chunked prediction equals the one-shot prediction for every model kind, the state carried across chunks."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.errors import LogError, ParameterError
from greybox.models.chunked import chunk_slices, iter_chunks, predict_chunked, samples_per_chunk
from greybox.models.friction import GMSModel, GMSState
from greybox.models.registry import MODEL_CLASSES
from greybox.twin import make_dataset

#: Quick settings per kind (short searches, no Bayesian optimisation).
QUICK = {
    "coulomb": {},
    "stribeck": {},
    "lugre": {"n_starts": 1, "max_iter": 80},
    "gms": {"n_starts": 1, "max_iter": 80},
    "svr": {"optimize": False, "n_subset": 300},
    "gmssvr": {"optimize": False, "n_subset": 300, "gms": GMSModel(n_starts=1, max_iter=80)},
}

#: Chunk length [s] that puts many chunk boundaries inside motions.
CHUNK_S = 0.77


@pytest.fixture(scope="module")
def train_log():
    return prepare([make_dataset("X", "A", seed=3, duration_s=12)])[0]


@pytest.fixture(scope="module")
def cut_log():
    return prepare([make_dataset("X", "C", seed=4, duration_s=10, cutting=True)])[0]


@pytest.fixture(scope="module")
def models(train_log):
    return {kind: MODEL_CLASSES[kind](**QUICK[kind]).fit(train_log) for kind in MODEL_CLASSES}


def test_every_registered_kind_is_covered():
    assert set(QUICK) == set(MODEL_CLASSES)


def test_chunk_boundaries_fall_inside_motions(cut_log):
    slices = chunk_slices(len(cut_log), samples_per_chunk(cut_log.sample_time, CHUNK_S))
    moving = [abs(cut_log.velocity[s.start]) > 1.0 for s in slices[1:]]
    assert len(slices) > 10 and sum(moving) >= 5


@pytest.mark.parametrize("kind", sorted(MODEL_CLASSES))
def test_chunked_equals_one_shot(models, cut_log, kind):
    model = models[kind]
    one_shot = model.predict(cut_log)
    chunked = predict_chunked(model, cut_log, chunk_s=CHUNK_S)
    np.testing.assert_allclose(chunked, one_shot, rtol=0, atol=1e-10)


def test_gmssvr_with_current_target(models, train_log, cut_log):
    model = MODEL_CLASSES["gmssvr"](**{**QUICK["gmssvr"], "target": "current"}).fit(train_log)
    np.testing.assert_allclose(predict_chunked(model, cut_log, chunk_s=CHUNK_S), model.predict(cut_log),
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("kind", ["lugre", "gms", "gmssvr"])
def test_restarting_the_state_at_each_chunk_would_differ(models, cut_log, kind):
    """The equality above rests on the carried state: chunks each started at rest differ."""
    model = models[kind]
    step = cut_log.sample_time
    slices = chunk_slices(len(cut_log), samples_per_chunk(step, CHUNK_S))
    restarted = np.concatenate([model.predict_chunk(cut_log.select(s), sample_time=step)[0] for s in slices])
    assert np.max(np.abs(restarted - model.predict(cut_log))) > 1e-3


def test_initial_states(models):
    assert models["coulomb"].initial_state() is None
    assert models["svr"].initial_state() is None
    assert models["lugre"].initial_state() == 0.0
    state = models["gmssvr"].initial_state()
    assert isinstance(state, GMSState) and not state.z.any() and not state.mode.any()


def test_jittered_time_stamps_chunk_at_the_run_step(models, cut_log):
    """Chunks use the whole run's step, so jitter that moves a chunk's median step changes nothing."""
    rng = np.random.default_rng(0)
    time = cut_log.time + rng.uniform(-2e-4, 2e-4, len(cut_log))
    time[0] = cut_log.time[0]
    jittered = cut_log.replace(time=time)
    for kind in ("lugre", "gms", "gmssvr"):
        np.testing.assert_allclose(predict_chunked(models[kind], jittered, chunk_s=CHUNK_S),
                                   models[kind].predict(jittered), rtol=0, atol=1e-10)


def test_several_runs_restart_at_each_run(models, cut_log, train_log):
    model = models["gms"]
    runs = [cut_log, train_log]
    np.testing.assert_allclose(predict_chunked(model, runs, chunk_s=CHUNK_S), model.predict(runs), rtol=0, atol=1e-10)


def test_iter_chunks_covers_the_run_in_order(models, cut_log):
    pieces = list(iter_chunks(models["stribeck"], cut_log, chunk_s=CHUNK_S))
    starts = [s.start for s, _ in pieces]
    stops = [s.stop for s, _ in pieces]
    assert starts[0] == 0 and stops[-1] == len(cut_log) and starts[1:] == stops[:-1]
    assert all(len(current) == s.stop - s.start for s, current in pieces)


@pytest.mark.parametrize("n, size", [(10, 3), (10, 5), (11, 5), (1, 4), (2, 2), (7, 100)])
def test_chunk_slices_partition_with_at_least_two_samples(n, size):
    slices = chunk_slices(n, size)
    covered = np.concatenate([np.arange(n)[s] for s in slices])
    np.testing.assert_array_equal(covered, np.arange(n))
    assert all(s.stop - s.start <= size + 1 for s in slices)
    if n >= 2:
        assert all(s.stop - s.start >= 2 for s in slices)


def test_bad_chunk_lengths_and_units(models, cut_log):
    with pytest.raises(ParameterError, match="positive number of seconds"):
        predict_chunked(models["gms"], cut_log, chunk_s=0.0)
    with pytest.raises(ParameterError, match="at least 2 samples"):
        chunk_slices(10, 1)
    force_log = cut_log.replace(effort_unit="N")
    for kind in ("gms", "coulomb"):
        with pytest.raises(LogError, match="fitted on A"):
            predict_chunked(models[kind], force_log)


@pytest.fixture(scope="module")
def augmented(train_log):
    """A model of 'greybox discover': GMS base plus a drift with the time since the run start, a ripple and the
    pre-sliding refinement (its play-operator states carry over from chunk to chunk)."""
    from greybox.models.augmented import AugmentedModel

    return AugmentedModel(base=GMSModel(n_starts=1, max_iter=80),
                          effects=[("thermal_drift", 3.0), ("position_periodic_force", 10.0),
                                   "inertia_mismatch", "presliding_hysteresis"], refine_shapes=False).fit(train_log)


def test_augmented_model_of_discover_chunks_like_one_shot(augmented, cut_log):
    assert [entry["name"] for entry in augmented.effects_][0] == "thermal_drift"
    late = cut_log.replace(time=cut_log.time + 1000.0)  # the drift counts from the run's own start
    for log in (cut_log, late):
        np.testing.assert_allclose(predict_chunked(augmented, log, chunk_s=CHUNK_S), augmented.predict(log),
                                   rtol=0, atol=1e-10)


def test_augmented_chunks_need_the_run_start_and_the_base_state(augmented, cut_log):
    """Chunks each taken as a run of their own differ: the drift restarts and the GMS base starts at rest."""
    step = cut_log.sample_time
    slices = chunk_slices(len(cut_log), samples_per_chunk(step, CHUNK_S))
    restarted = np.concatenate([augmented.predict_chunk(cut_log.select(s), sample_time=step)[0] for s in slices])
    assert np.max(np.abs(restarted - augmented.predict(cut_log))) > 1e-3
    base_state, scaled_state, run_start, presliding = augmented.initial_state()  # scaled: what the terms scale
    assert isinstance(base_state, GMSState) and isinstance(scaled_state, GMSState)
    assert run_start is None and presliding is None
