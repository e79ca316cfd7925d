"""``greybox process teach`` and ``check`` on the twin's part series: model force, raw current, both layouts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from greybox.cli import main
from greybox.data.prepare import prepare
from greybox.models.files import save_model
from greybox.models.friction import GMSModel
from greybox.process.envelope import Envelope
from greybox.twin import make_dataset
from greybox.twin.part_series import PartSeriesSpec, ToolEvents, part_program, synthesize_part_series

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    """Eight short parts (a model trained on a cold air cut); part 7 breaks at 4.2 s, part 8 has no blank."""
    root = tmp_path_factory.mktemp("process")
    train = prepare([make_dataset("X", "A", seed=11, duration_s=20)])[0]
    save_model(GMSModel(n_starts=1, max_iter=80).fit(train), root / "x.gbm")
    spec = PartSeriesSpec(parts=8, program=part_program("X", (600.0,)), loading_s=1.0, jitter_s=0.1,
                          events=ToolEvents(breakage_part=7, breakage_time_s=4.2, missing_blank=(8,)))
    synthesize_part_series(spec, 5, root / "parts")
    return root


def test_teach_on_good_parts_and_check_finds_the_breakage_and_the_missing_blank(series, capsys):
    parts = sorted(str(p) for p in (series / "parts").glob("X_part00*.mcap"))
    envelope = series / "force.json"
    assert main(["process", "teach", str(series / "x.gbm"), *parts[:6], "--axis-config", str(EXAMPLE),
                 "--relevel", "--out", str(envelope)]) == 0
    out = capsys.readouterr().out
    assert "envelope of the force signal [N] from 6 parts" in out
    assert json.loads(envelope.read_text())["signal"]["kind"] == "force"
    assert Envelope.load(envelope).blocks_  # the twin's parts carry their NC block numbers: aligned block by block
    report = series / "report"
    assert main(["process", "check", str(envelope), str(series / "parts" / "X_series.mcap"), "--out",
                 str(report)]) == 0
    out = capsys.readouterr().out
    assert "8 parts checked" in out
    rows = {int(r["part"]): r for r in json.loads((report / "report.json").read_text())["parts"]}
    assert not any(rows[k]["flagged"] for k in range(1, 7))
    assert "missing cut" in rows[7]["kinds"] and "missing cut" in rows[8]["kinds"]
    stretches = json.loads((report / "report.json").read_text())["stretches"]
    first = min((s for s in stretches if s["part"] == 7), key=lambda s: s["start_s"])
    assert first["kind"] == "missing cut" and abs(first["start_s"] - 4.2) <= 0.2
    assert any(p.suffix == ".png" for p in report.iterdir())
    # the report directory is not written into again without --force
    assert main(["process", "check", str(envelope), parts[0], "--out", str(report)]) == 2
    assert "not empty" in capsys.readouterr().err


def test_raw_envelope_and_one_line_refusals(series, capsys, tmp_path):
    parts = sorted(str(p) for p in (series / "parts").glob("X_part00*.mcap"))
    raw = tmp_path / "raw.json"
    assert main(["process", "teach", "--raw", *parts[:6], "--out", str(raw)]) == 0
    assert "envelope of the raw signal [A]" in capsys.readouterr().out
    assert main(["process", "teach", "--raw", *parts[:6], "--out", str(raw)]) == 2  # exists
    assert "exists" in capsys.readouterr().err
    assert main(["process", "teach", str(series / "x.gbm"), "--out", str(tmp_path / "e.json")]) == 2
    assert "at least one log" in capsys.readouterr().err
    assert main(["process", "teach", "--raw", *parts[:2], "--out", str(tmp_path / "two.json")]) == 2
    assert "at least 3 good parts" in capsys.readouterr().err
    (tmp_path / "bad.json").write_text("{not json")
    assert main(["process", "check", str(tmp_path / "bad.json"), parts[0], "--out", str(tmp_path / "r")]) == 2
    error = capsys.readouterr().err
    assert "bad.json: not a valid envelope file" in error and "Traceback" not in error
    other = tmp_path / "other.gbm"
    other.write_bytes((series / "x.gbm").read_bytes() + b" ")
    force = series / "force.json"
    if force.exists():
        assert main(["process", "check", str(force), parts[0], "--model", str(other), "--out",
                     str(tmp_path / "r2")]) == 2
        assert "SHA-256 differs" in capsys.readouterr().err


def test_a_csv_series_without_part_column_is_split_at_its_rests(series, capsys, tmp_path):
    from greybox.data.io import read_log, write_log

    long = read_log(series / "parts" / "X_series.mcap")
    write_log(long.replace(extras={}), tmp_path / "series.csv")
    parts = sorted(str(p) for p in (series / "parts").glob("X_part00*.mcap"))
    raw = tmp_path / "raw.json"
    assert main(["process", "teach", "--raw", *parts[:6], "--out", str(raw), "--relevel", "--min-rest", "0.8"]) == 0
    assert main(["process", "check", str(raw), str(tmp_path / "series.csv"), "--out", str(tmp_path / "r")]) == 0
    assert "8 parts checked" in capsys.readouterr().out
    rows = json.loads((tmp_path / "r" / "report.json").read_text())["parts"]
    assert [r["part"] for r in rows] == list(range(1, 9))  # counted in order, split at the 1 s loading rests
    assert [r["flagged"] for r in rows] == [False] * 6 + [True, True]
