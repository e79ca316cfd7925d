"""The compiled kernels' cache lives outside the installed sources."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import greybox


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_numba_cache_is_kept_out_of_the_package_directory(tmp_path):
    package = Path(greybox.__file__).resolve().parent
    env = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    script = ("import greybox, numba.core.config as c, greybox.models.friction.kernels; print(c.CACHE_DIR)")
    printed = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    cache = Path(printed.stdout.strip())
    assert cache == tmp_path / "greybox" / "numba"
    assert package not in cache.parents


def test_a_cache_directory_the_user_chose_is_kept(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "mine")}
    printed = subprocess.run([sys.executable, "-c", "import greybox, numba.core.config as c; print(c.CACHE_DIR)"],
                             env=env, capture_output=True, text=True, check=True)
    assert printed.stdout.strip() == str(tmp_path / "mine")
