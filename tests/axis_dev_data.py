"""The independent development data beside the repository (``../shared/data/independent``), for the tests.

:func:`axis_dev` reads one log of ``axis_dev`` (an axis exported as a controller would, written apart from
greybox) and prepares it, or skips the calling test with a reason naming the missing file.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from greybox.data.io import read_log
from greybox.data.prepare import prepare

#: The independent development data: ``../shared/data/independent`` beside the repository.
INDEPENDENT = Path(__file__).resolve().parents[2] / "shared" / "data" / "independent"


def axis_dev(name: str):
    """The prepared run of ``axis_dev/<name>.csv``; skips when the development data are absent.

    Parameters
    ----------
    name : str
        File stem, e.g. ``"aircut_B"``.
    """
    path = INDEPENDENT / "axis_dev" / f"{name}.csv"
    if not path.is_file():
        pytest.skip(f"independent development data not found: no file {path}")
    (run,) = prepare(read_log(path))
    return run
