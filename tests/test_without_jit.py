"""The compiled kernels' tests once more with numba's compiler off (``NUMBA_DISABLE_JIT=1``).

Each kernel then runs as the plain Python it is written in, against the same references. A kernel that
leans on what only compiled code does (integers wrapping around, numba's choice of integer types) fails
here, and a coverage tool run this way sees the kernels' lines.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]

#: Test files of the compiled kernels: GMS and LuGre, SVR kernel sums, plant laws, JSON numbers and MCAP
#: records, the controller and the controlled plants, the twin's plant and the truth laws of the family of axes,
#: the ageing twin's play, the live stream's zero-phase filter, the kernel models' frame (kernel sum, hand-over,
#: input flags), the local span and the reversals of the operating region.
KERNEL_TESTS = ("models/friction/test_kernels.py", "models/kernel/test_rbf.py", "twin/test_plant_laws.py",
                "data/test_json_numbers.py", "data/test_mcap_io.py", "control/test_pid.py",
                "control/test_plants.py", "twin/test_plant.py", "twin/test_family.py", "twin/test_ageing.py",
                "live/test_zerophase.py", "models/kernel/test_expansion.py", "data/test_operating.py")


@pytest.mark.slow
def test_kernel_tests_pass_with_the_compiler_off():
    environment = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-W", "error::RuntimeWarning",
               *(str(ROOT / "tests" / name) for name in KERNEL_TESTS)]
    result = subprocess.run(command, cwd=ROOT, env=environment, capture_output=True, text=True, timeout=1200)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert " passed" in result.stdout and " skipped" not in result.stdout
