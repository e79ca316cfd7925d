"""A report a person can send (issue 31, item 8): ``evaluate --out report.pdf``, ``predict --plot x.pdf``, legends
outside the data and every colour explained."""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from greybox.cli import main  # noqa: E402
from greybox.data.io import write_log  # noqa: E402
from greybox.data.log import AxisLog  # noqa: E402
from greybox.data.prepare import prepare  # noqa: E402
from greybox.evaluate.figures import residual_vs_position, time_comparison  # noqa: E402
from greybox.models.files import save_model  # noqa: E402
from greybox.models.friction import CoulombModel  # noqa: E402
from greybox.predict.plot import plot_process  # noqa: E402
from greybox.predict.process import predict_process  # noqa: E402


def _log(seed: int = 0) -> AxisLog:
    time = np.arange(4000) * 0.002
    position = 20.0 * np.sin(0.5 * np.pi * time)
    velocity = np.gradient(position, time)
    rng = np.random.default_rng(seed)
    return AxisLog(time=time, position=position,
                   effort=0.4 * np.tanh(velocity / 0.5) + 0.01 * velocity + rng.normal(0, 0.02, time.size))


@pytest.fixture()
def fitted(tmp_path):
    write_log(_log(), tmp_path / "test.csv")
    model = CoulombModel().fit(prepare([_log()]))
    save_model(model, tmp_path / "c.gbm")
    return tmp_path, model


def _pages(path) -> int:
    return len(re.findall(rb"/Type /Page\b", path.read_bytes()))


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_evaluate_writes_one_pdf_of_tables_and_figures(fitted, capsys):
    directory, _ = fitted
    report = directory / "report.pdf"
    args = ["evaluate", str(directory / "c.gbm"), "--test", str(directory / "test.csv"), "--out", str(report)]
    assert main(args) == 0
    assert report.is_file() and report.read_bytes().startswith(b"%PDF")
    assert _pages(report) == 4  # tables, then the three figures
    assert main(args) == 2 and "--force" in capsys.readouterr().err  # an existing report is kept
    assert main([*args, "--force"]) == 0


def test_predict_draws_a_pdf(fitted):
    directory, _ = fitted
    assert main(["predict", str(directory / "c.gbm"), str(directory / "test.csv"), "--out",
                 str(directory / "p.csv"), "--plot", str(directory / "p.pdf"), "--quiet"]) == 0
    assert (directory / "p.pdf").read_bytes().startswith(b"%PDF")


def _legends_outside_their_axes(figure) -> int:
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    count = 0
    for ax in figure.axes:
        legend = ax.get_legend()
        if legend is None or not ax.get_visible():
            continue
        box = legend.get_window_extent(renderer)
        for other in figure.axes:  # over no axes of the figure, its own included
            if other.get_visible():
                area = other.get_window_extent(renderer)
                assert box.x0 >= area.x1 - 1 or box.x1 <= area.x0 + 1 or box.y1 <= area.y0 + 1 \
                    or box.y0 >= area.y1 - 1, (legend.get_texts()[0].get_text(), other.get_title())
        count += 1
    return count


def test_legends_of_predict_and_evaluate_lie_outside_the_data(fitted):
    import matplotlib.pyplot as plt

    _, model = fitted
    runs = prepare([_log(1)])
    result = predict_process(model, runs[0])
    for figure in (plot_process(result), time_comparison(runs, {"coulomb": model.predict(runs[0])}, None),
                   residual_vs_position(runs, {"coulomb": model.predict(runs[0]), "b": model.predict(runs[0])},
                                        None)):
        assert _legends_outside_their_axes(figure) >= 1
        plt.close(figure)


def test_the_residual_figure_explains_its_point_colours(fitted):
    import matplotlib.pyplot as plt

    _, model = fitted
    runs = prepare([_log(1)])
    figure = residual_vs_position(runs, {"coulomb": model.predict(runs[0])}, None)
    labels = [text.get_text() for ax in figure.axes if ax.get_legend() for text in ax.get_legend().get_texts()]
    assert {"samples, v +", "samples, v -", "mean, v +", "mean, v -"} <= set(labels)
    plt.close(figure)


@pytest.mark.slow
def test_the_evidence_figure_explains_its_bar_colours(tmp_path, monkeypatch):
    import matplotlib.pyplot as plt

    from greybox.discover.report import plot_evidence
    from greybox.discover.workflow import discover
    from studies.discovery import StudyCase, case_logs

    train, test, _ = case_logs(StudyCase("position_periodic_force", 1.5, 2, "coulomb", 10.0))
    result = discover(CoulombModel(), train, test, seed=2, max_effects=1)
    original = plt.Figure.savefig
    shown = []

    def keep(figure, *args, **kwargs):
        legends = [*figure.legends, *(ax.get_legend() for ax in figure.axes if ax.get_legend())]
        shown.append([text.get_text() for legend in legends for text in legend.get_texts()])
        return original(figure, *args, **kwargs)

    monkeypatch.setattr(plt.Figure, "savefig", keep)
    plot_evidence(result, tmp_path / "evidence.png")
    assert {"added in this step", "passes, not added", "does not pass"} <= set(shown[0])


def test_the_wall_time_of_a_command_counts_from_the_start_of_its_process():
    """The printed 'done in ... s wall' of a command starts when Python did, not after the imports."""
    import subprocess
    import sys

    code = ("import time; time.sleep(0.3); from greybox.cli import process_age_s; "
            "print(process_age_s())")
    age = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)
    assert age >= 0.3  # the sleep before the import is counted
