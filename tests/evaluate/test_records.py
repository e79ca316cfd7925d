"""The records and PDF report of ``greybox evaluate``: page 1 is text, not Markdown, and every figure's caption fits
on its page (issue 31, item 8); the errors inside and outside each model's training region (issue 30)."""

from __future__ import annotations

import warnings

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from matplotlib.backends import backend_pdf  # noqa: E402

from greybox.data.log import AxisLog  # noqa: E402
from greybox.data.prepare import prepare  # noqa: E402
from greybox.evaluate.records import evaluate_models, write_evaluation_pdf  # noqa: E402
from greybox.evaluate.regimes import TRAINING_REGION_NAMES  # noqa: E402
from greybox.evaluate.report import training_region_table  # noqa: E402
from greybox.evaluate.table import Table  # noqa: E402
from greybox.metrics import rmse  # noqa: E402
from greybox.models.estimator import EXTRAPOLATION_WARNING_SHARE, outside_any  # noqa: E402
from greybox.models.files import load_model, save_model  # noqa: E402
from greybox.models.friction import CoulombModel  # noqa: E402


def _log(seed: int) -> AxisLog:
    time = np.arange(1500) * 0.002
    position = 20.0 * np.sin(0.5 * np.pi * time)
    velocity = np.gradient(position, time)
    rng = np.random.default_rng(seed)
    return AxisLog(time=time, position=position, source=f"log_{seed}.csv",
                   effort=0.4 * np.tanh(velocity / 0.5) + 0.01 * velocity + rng.normal(0, 0.02, time.size))


#: Drawing the report's pages takes about ten seconds: the tests of the pages are left out of the default run.
slow = pytest.mark.slow


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    runs = prepare([_log(0), _log(1)])
    models = {"a_model_with_a_long_name": CoulombModel().fit(runs), "plain": CoulombModel(fit_offset=False).fit(runs)}
    records, predictions = evaluate_models(models, runs, ["log_0", "log_1"])
    drawn = []
    original = backend_pdf.PdfPages.savefig

    def keep(document, figure=None, **kwargs):
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        drawn.append((figure, [(text.get_text(), text.get_window_extent(renderer)) for text in figure.texts]))
        return original(document, figure, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(backend_pdf.PdfPages, "savefig", keep)
        write_evaluation_pdf(tmp_path_factory.mktemp("pdf") / "report.pdf", records, predictions, runs,
                             ["log_0", "log_1"])
    return drawn


@slow
def test_page_one_is_text_without_markdown(pages):
    _, texts = pages[0]
    lines = [line for text, _ in texts for line in text.splitlines()]
    assert any("Test errors" == line.strip() for line in lines)
    assert not any(line.lstrip().startswith(("|", "#")) or "|---" in line for line in lines)
    header = next(line for line in lines if line.startswith("model"))
    row = next(line for line in lines if line.startswith("plain"))
    assert header.index("RMSE") < len(row)  # columns padded: a row is as wide as its header


@slow
def test_every_caption_and_text_lies_on_its_page(pages):
    for figure, texts in pages:
        page = figure.bbox
        for text, extent in texts:
            assert page.x0 - 1 <= extent.x0 and extent.x1 <= page.x1 + 1, text
            assert page.y0 - 1 <= extent.y0 and extent.y1 <= page.y1 + 1, text


def test_a_table_as_text_pads_its_columns():
    lines = Table("T", ["model", "RE [%]"], [["a", "4.1"], ["longer", "12.35"]], ["note"]).to_text()
    assert lines[0] == "T" and lines[-1] == "note"
    assert lines[1] == "model   RE [%]" and lines[3] == "a          4.1" and lines[4] == "longer   12.35"


def _window_log(name: str, amplitude_mm: float, offset_mm: float = 0.0, seed: int = 3) -> AxisLog:
    """A prepared sine of ``amplitude_mm`` about ``offset_mm`` (1.5 s at 2 ms), the current of Coulomb + viscous
    friction plus noise."""
    time = np.arange(750) * 0.002
    position = offset_mm + amplitude_mm * np.sin(2.0 * np.pi * time)
    velocity = np.gradient(position, time)
    rng = np.random.default_rng(seed)
    log = AxisLog(time=time, position=position, source=f"{name}.csv",
                  effort=0.4 * np.tanh(velocity / 0.5) + 0.01 * velocity + rng.normal(0, 0.02, time.size))
    return prepare([log])[0]


@pytest.fixture(scope="module")
def narrow():
    """A Coulomb model trained on a 10 mm window."""
    return CoulombModel().fit(_window_log("train", 5.0))


def _notes(models, runs, names):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        records, _ = evaluate_models(models, runs, names)
    return records, [str(w.message) for w in caught]


def test_the_rows_split_the_samples_by_the_models_own_training_region(narrow):
    runs = [_window_log("wide", 12.0, seed=4), _window_log("same", 5.0, seed=5)]
    records, _ = _notes({"c": narrow}, runs, ["wide", "same"])
    record = records[0]
    inside, outside = (record["regimes"][name] for name in TRAINING_REGION_NAMES)
    flags = [outside_any(narrow.outside_training(run)) for run in runs]
    beyond = np.concatenate(flags)
    assert 0 < beyond.sum() < beyond.size  # a test that can tell
    assert inside["n"] + outside["n"] == record["n"] == record["regimes"]["all"]["n"]
    assert outside["n"] == beyond.sum()
    measured = np.concatenate([run.effort for run in runs])
    predicted = narrow.predict(runs)
    assert outside["rmse"] == pytest.approx(rmse(measured[beyond], predicted[beyond]))
    assert inside["rmse"] == pytest.approx(rmse(measured[~beyond], predicted[~beyond]))
    region = record["training_region"]
    assert region["share"] == pytest.approx(beyond.mean())
    for name, run, flag in zip(["wide", "same"], runs, flags):
        log = region["per_log"][name]
        assert log["share"] == pytest.approx(flag.mean())
        assert log["inside"]["n"] + log["outside"]["n"] == len(run)
        assert log["by"]["position"] == pytest.approx(narrow.outside_training(run)["position"].mean())
    table = training_region_table(records)
    assert [row[0] for row in table.rows] == ["c"]  # the noise floor has no training region: no row
    assert table.rows[0][2] == str(inside["n"]) and table.rows[0][5] == str(outside["n"])


def test_the_note_names_the_log_and_the_model_only_above_the_threshold(narrow):
    """The same sine shifted along the axis: a little and a lot of it beyond the trained window."""
    little, much = _window_log("little", 5.0, offset_mm=0.005), _window_log("much", 5.0, offset_mm=3.0)
    shares = [outside_any(narrow.outside_training(run)).mean() for run in (little, much)]
    assert shares[0] < EXTRAPOLATION_WARNING_SHARE < shares[1]  # the premise of the test
    _, quiet = _notes({"c": narrow}, [little], ["little"])
    assert not [note for note in quiet if "trained on" in note]
    records, notes = _notes({"c": narrow}, [little, much], ["little", "much"])
    said = [note for note in notes if "trained on" in note]
    assert len(said) == 1 and said[0].startswith(f"much.csv: {100 * shares[1]:.1f} % of the samples lie outside "
                                                 "what model c was trained on (positions ")
    part = records[0]["training_region"]["per_log"]["much"]
    assert f"RMSE there {part['outside']['rmse']:.3g} A against {part['inside']['rmse']:.3g} A inside" in said[0]


def test_a_model_file_without_its_training_region_gets_one_note_and_no_rows(narrow, tmp_path):
    old = CoulombModel().fit(_window_log("train", 5.0))
    del old.position_range_mm_, old.velocity_range_mm_s_, old.effort_range_  # as a file written before the record
    loaded = load_model(save_model(old, tmp_path / "old.gbm"))
    runs = [_window_log("wide", 12.0, seed=4), _window_log("much", 5.0, offset_mm=3.0)]
    records, notes = _notes({"old": loaded, "c": narrow}, runs, ["wide", "much"])
    about_old = [note for note in notes if note.startswith("old:")]
    assert len(about_old) == 1 and "no record of its training region" in about_old[0]
    assert not [note for note in notes if "model old" in note]
    by_name = {record["model"]: record for record in records}
    assert not set(TRAINING_REGION_NAMES) & set(by_name["old"]["regimes"])
    assert by_name["old"]["training_region"]["share"] is None
    assert set(TRAINING_REGION_NAMES) <= set(by_name["c"]["regimes"])
    rows = {row[0]: row for row in training_region_table(records).rows}
    assert set(rows["old"][1:]) == {"–"} and rows["c"][1] != "–"
