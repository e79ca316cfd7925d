"""The dashboard in a real browser: headless Chromium shows the tables and the figures, without console errors."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from greybox.cli import main
from greybox.twin.ageing import synthesize_history

CHROMIUM = next((shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(name)), None)


def _chromium(tmp_path, *args) -> subprocess.CompletedProcess:
    return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                           f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr", "--v=0", *args],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
@pytest.mark.skipif(CHROMIUM is None, reason="no chromium program (.ci/run installs it: apt-get install chromium)")
def test_dashboard_renders_in_chromium(tmp_path):
    from matplotlib.image import imread

    logs = synthesize_history(["X"], 4, 6, tmp_path / "logs", truth_channels=())
    assert main(["monitor", *map(str, logs), "--history", str(tmp_path / "h"), "--out", str(tmp_path / "r"),
                 "--baseline-days", "3"]) == 0
    page = (tmp_path / "r" / "index.html").as_uri()
    dom = _chromium(tmp_path, "--dump-dom", page)
    assert dom.returncode == 0
    for text in ("Axes, most severe first", "Alarms", "twin / X (severity", "Interactive charts"):
        assert text in dom.stdout
    # plotly drew the interactive chart offline (its script is inline): the div holds its SVG, titled per feature
    assert 'id="axis-0"' in dom.stdout and 'class="main-svg"' in dom.stdout and "local_excess [A]" in dom.stdout
    # and the friction-along-travel map as a heat map: plotly drew its cells (an image layer) and its colour bar
    travel = dom.stdout[dom.stdout.index('id="travel-0"'):]
    assert "friction along the travel" in travel and 'class="hm"' in travel and "colorbar" in travel
    shot = tmp_path / "shot.png"
    run = _chromium(tmp_path, "--window-size=1200,2400", f"--screenshot={shot}", page)
    assert run.returncode == 0 and shot.is_file()
    console = [line for line in run.stderr.splitlines() + dom.stderr.splitlines() if "CONSOLE" in line]
    assert console == []  # no script errors, no resource failures logged by the page
    pixels = np.round(255 * imread(shot)[..., :3]).astype(int)
    blue = np.all(np.abs(pixels - [31, 119, 180]) <= 12, axis=2)  # the daily values drawn in the figure
    assert np.count_nonzero(blue.any(axis=1)) > 100  # on many rows: the plotted lines, not the heading's rule
