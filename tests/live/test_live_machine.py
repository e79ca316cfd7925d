"""A machine model live: one session per axis, fed from messages of every axis's columns or from one topic per
axis; each axis's estimates equal ``greybox predict`` of that axis."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from live_helpers import run_cli

from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.live.estimator import LiveEstimator
from greybox.live.machine import MachineSession
from greybox.live.run import run_live
from greybox.live.session import LiveSession
from greybox.live.sinks import LineSink
from greybox.live.sources import Received
from greybox.models.friction import CoulombModel, GMSModel
from greybox.models.machine import MachineModel, save_machine
from greybox.twin import make_dataset


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    """A machine model of X (Coulomb) and Y (GMS), a cutting log of both axes (CSV, one table) and the table
    ``greybox predict`` writes for each axis."""
    import pandas as pd

    root = tmp_path_factory.mktemp("machine")
    models = {"X": CoulombModel(fit_offset=True).fit(prepare([make_dataset("X", "A", seed=3, duration_s=4)])[0]),
              "Y": GMSModel(n_starts=1, max_iter=40).fit(prepare([make_dataset("Y", "A", seed=5, duration_s=4)])[0])}
    save_machine(MachineModel(models), root / "machine")
    x = make_dataset("X", "C", seed=4, duration_s=1.2, cutting=True).replace(extras={})
    y = make_dataset("Y", "C", seed=6, duration_s=1.2, cutting=True).replace(extras={})
    n = min(len(x), len(y))
    x, y = x.select(slice(0, n)), y.select(slice(0, n)).replace(time=x.time[:n])
    write_log([x, y], root / "cut.csv")
    expected = {}
    for axis in ("X", "Y"):
        out = root / f"{axis}.csv"
        assert run_cli(["predict", root / "machine" / f"{axis}.gbm", root / "cut.csv", "--axis", axis, "--out", out,
                        "--quiet"]) == 0
        expected[axis] = pd.read_csv(out)
    return root, {"X": x, "Y": y}, expected


def by_axis(lines) -> dict:
    rows = [json.loads(line) for line in lines if line.strip()]
    out = {}
    for row in rows:
        out.setdefault(row["axis"], []).append(row)
    return {axis: {name: np.concatenate([row[name] for row in got]) for name in got[0] if name not in ("seq", "axis")}
            for axis, got in out.items()}


def test_messages_of_every_axis_feed_every_axis(machine):
    root, logs, expected = machine
    header = (root / "cut.csv").read_text().splitlines()
    out, said = io.StringIO(), []
    run_live(root / "machine", source="-", stdin=io.StringIO("\n".join(header)), stdout=out, say=said.append)
    live = by_axis(out.getvalue().splitlines())
    assert set(live) == {"X", "Y"}
    for axis in ("X", "Y"):
        np.testing.assert_allclose(live[axis]["current_model_A"], expected[axis]["current_model_A"].to_numpy(),
                                   rtol=0, atol=1e-9)
    assert said[-2].startswith("X stats:") and said[-1].startswith("Y stats:")


def test_one_topic_per_axis(machine):
    """Messages on topics ending in the axis name hold that axis's plain columns."""
    from greybox.models.files import load_model

    root, logs, expected = machine
    out = io.StringIO()
    sessions = {axis: LiveSession(LiveEstimator(load_model(root / "machine" / f"{axis}.gbm")), LineSink(out),
                                  say=lambda line: None, axis=axis, subtopic=axis) for axis in ("X", "Y")}
    session = MachineSession(sessions, say=lambda line: None)
    for k in range(0, len(logs["X"]), 10):
        for axis, log in logs.items():
            part = log.select(slice(k, k + 10))
            payload = json.dumps({"time_s": part.time.tolist(), "position_mm": part.position.tolist(),
                                  "velocity_mm_s": part.velocity.tolist(), "current_A": part.effort.tolist()})
            session.handle(Received(payload, f"message on machine/{axis}", 0.0, f"machine/{axis}"))
    session.finish()
    live = by_axis(out.getvalue().splitlines())
    for axis in ("X", "Y"):
        np.testing.assert_allclose(live[axis]["current_model_A"], expected[axis]["current_model_A"].to_numpy(),
                                   rtol=0, atol=1e-9)
    session.handle(Received('{"time_s": 9, "Z_position_mm": 1, "Z_current_A": 0}', "stray", 0.0, "machine/all"))
    assert session.stats.rejected == 1
