"""The fleet engine (greybox.fleet) on a local Dask cluster: how its workers set numba's threads."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

#: A main script as a user's (or a benchmark's) would be: it imports numba before it starts the cluster, so
#: a spawned worker, which imports the parent's main script first, has numba's settings read before Dask
#: sets the worker's environment variables.
SCRIPT = '''
import numba

from greybox.fleet import _run_on_cluster


def task(job):
    threads = numba.get_num_threads()  # launches numba's threads
    compiled = numba.njit(lambda x: x + job)  # compiled only now: numba reads its settings again
    return {"status": "ok", "threads": threads, "value": compiled(1)}


if __name__ == "__main__":
    results = {}
    _run_on_cluster(task, [(0, 1)], None, 1, lambda index, entry: results.update(entry))
    print(repr(results))
'''


@pytest.mark.slow
def test_a_worker_compiles_after_launching_its_threads_and_runs_them_on_one(tmp_path):
    # before: the worker read NUMBA_NUM_THREADS = 2 when it imported the script, launched two threads, then
    # Dask set it to 1 and the next compilation failed ("Cannot set NUMBA_NUM_THREADS to a different value")
    script = tmp_path / "fleet_main.py"
    script.write_text(SCRIPT)
    env = {name: value for name, value in os.environ.items() if name != "NUMBA_DISABLE_JIT"}
    env.update(NUMBA_NUM_THREADS="2", PYTHONPATH=os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                                                   env.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    result = ast.literal_eval(done.stdout.strip().splitlines()[-1])
    assert result["status"] == "ok", result
    assert result["value"] == 2 and result["threads"] == 1  # the task's kernels on one thread
