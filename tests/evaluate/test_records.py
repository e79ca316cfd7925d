"""The PDF report of ``greybox evaluate`` (issue 31, item 8): page 1 is text, not Markdown, and every figure's
caption fits on its page."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from matplotlib.backends import backend_pdf  # noqa: E402

from greybox.data.log import AxisLog  # noqa: E402
from greybox.data.prepare import prepare  # noqa: E402
from greybox.evaluate.records import evaluate_models, write_evaluation_pdf  # noqa: E402
from greybox.evaluate.table import Table  # noqa: E402
from greybox.models.friction import CoulombModel  # noqa: E402


def _log(seed: int) -> AxisLog:
    time = np.arange(1500) * 0.002
    position = 20.0 * np.sin(0.5 * np.pi * time)
    velocity = np.gradient(position, time)
    rng = np.random.default_rng(seed)
    return AxisLog(time=time, position=position, source=f"log_{seed}.csv",
                   effort=0.4 * np.tanh(velocity / 0.5) + 0.01 * velocity + rng.normal(0, 0.02, time.size))


#: Drawing the report's pages takes about ten seconds: left out of the default run.
pytestmark = pytest.mark.slow


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


def test_page_one_is_text_without_markdown(pages):
    _, texts = pages[0]
    lines = [line for text, _ in texts for line in text.splitlines()]
    assert any("Test errors" == line.strip() for line in lines)
    assert not any(line.lstrip().startswith(("|", "#")) or "|---" in line for line in lines)
    header = next(line for line in lines if line.startswith("model"))
    row = next(line for line in lines if line.startswith("plain"))
    assert header.index("RMSE") < len(row)  # columns padded: a row is as wide as its header


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
