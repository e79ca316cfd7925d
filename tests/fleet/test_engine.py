"""The fleet engine (greybox.fleet.engine) on a local Dask cluster: how its workers set numba's threads."""

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

from greybox.fleet.engine import _run_on_cluster


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


# -- output names of a fleet run (greybox.fleet.engine.log_names, encode_name, check_names) --------------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from greybox.errors import GreyboxError  # noqa: E402
from greybox.fleet.engine import (  # noqa: E402
    MANIFEST,
    MAX_NAME_BYTES,
    check_names,
    decode_name,
    encode_name,
    expand_logs,
    log_names,
)

#: A folder or file name: any characters a POSIX file name may hold (no "/" or NUL), never "." or "..".
_PART = st.text(st.characters(blacklist_characters="/\x00", blacklist_categories=("Cs",)), min_size=1,
                max_size=12).filter(lambda name: name not in (".", ".."))


@settings(max_examples=150, deadline=None)
@given(st.lists(st.lists(_PART, min_size=1, max_size=4).map(lambda parts: "/plant/" + "/".join(parts)),
                min_size=1, max_size=12, unique=True))
def test_no_two_distinct_logs_share_an_output_name_and_each_name_gives_its_path_back(paths):
    # distinct files (a path that is a file is no other file's folder)
    paths = [path for path in paths if not any(other.startswith(path + "/") for other in paths)]
    names = [encode_name(name) for name in log_names(paths)]
    assert len(set(names)) == len(paths)
    for path, name in zip(paths, names):
        assert "/" not in name and "\x00" not in name  # one directory level, "log=<name>"
        assert path.endswith("/" + decode_name(name))  # reversible: the relative path, suffix kept


def test_the_cases_that_collided_get_distinct_names():
    # were all "log=log", "log=X", "log=run_1": six logs, three outputs
    logs = ["/p/a/m2/log.mcap", "/p/b/m2/log.mcap", "/p/c/X.mcap", "/p/c/X.parquet", "/p/c/run 1.mcap",
            "/p/c/run_1.mcap"]
    names = [encode_name(name) for name in log_names(logs)]
    assert names == ["a%2Fm2%2Flog.mcap", "b%2Fm2%2Flog.mcap", "c%2FX.mcap", "c%2FX.parquet", "c%2Frun%201.mcap",
                     "c%2Frun_1.mcap"]
    check_names(logs, names)


def test_names_a_file_system_would_merge_or_cannot_hold_are_refused():
    logs = ["/p/m/Log.mcap", "/p/m/log.mcap"]
    with pytest.raises(GreyboxError, match="ignores case"):
        check_names(logs, [encode_name(name) for name in log_names(logs)])
    long = ["/p/m/" + "x" * MAX_NAME_BYTES + ".mcap", "/p/n/a.mcap"]
    with pytest.raises(GreyboxError, match="longer than 255 bytes"):
        check_names(long, [encode_name(name) for name in log_names(long)])


def test_a_fleet_output_inside_the_input_tree_is_not_read_back_as_logs(tmp_path):
    (tmp_path / "m1").mkdir()
    (tmp_path / "m1" / "a.csv").write_text("t\n")
    results = tmp_path / "results" / "machine=m1" / "axis=X" / "log=m1%2Fa.csv"
    results.mkdir(parents=True)
    (results / "part-0.parquet").write_bytes(b"")
    assert expand_logs([str(tmp_path)], exclude=[tmp_path / "results"]) == [tmp_path / "m1" / "a.csv"]
    # an earlier run's output (its manifest there) is left out also when not excluded by name
    (tmp_path / "results" / MANIFEST).write_text("{}")
    assert expand_logs([str(tmp_path)]) == [tmp_path / "m1" / "a.csv"]
    assert expand_logs([str(tmp_path / "**" / "*.*")]) == [tmp_path / "m1" / "a.csv"]


#: A main script whose one job kills the worker running it (as the kernel's OOM killer would).
DYING = '''
import os
from dataclasses import dataclass

import dask

from greybox.fleet.engine import _run_on_cluster


@dataclass(frozen=True)
class Job:
    log: str


def task(job):
    os._exit(9)


if __name__ == "__main__":
    results = {}
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        jobs = [(0, Job("/plant/mill1/monday.mcap"))]
        _run_on_cluster(task, jobs, None, 1, lambda index, entry: results.update(entry))
    print(repr(results))
'''


@pytest.mark.slow
def test_a_job_whose_worker_died_is_reported_by_its_log(tmp_path):
    # before: "lost on the cluster: KilledWorker: ('task-5f2c...', ...)", naming a Dask task, not the log
    script = tmp_path / "dying_main.py"
    script.write_text(DYING)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                                        os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    result = ast.literal_eval(done.stdout.strip().splitlines()[-1])
    assert result["status"] == "failed"
    assert result["error"].startswith("/plant/mill1/monday.mcap: lost on the cluster (the worker running it died")


def test_a_workers_warnings_go_to_the_manifest_and_the_summary_as_note_lines():
    import warnings

    from greybox.fleet.engine import attempt, fleet_summary

    def work():
        warnings.warn("the log's clock jumps\nsecond line", UserWarning, stacklevel=2)
        warnings.warn("the log's clock jumps\nsecond line", UserWarning, stacklevel=2)
        return {"output": "x"}

    entry = {"log": "/plant/m1/a.mcap", **attempt("a.mcap", work)}
    assert entry["status"] == "ok" and entry["notes"] == ["the log's clock jumps"]
    manifest = {"counts": {"ok": 1, "skipped": 0, "failed": 0}, "cluster": {"workers": 1, "scheduler": "local"},
                "seconds": 1.0, "logs": [entry]}
    lines, status = fleet_summary(manifest, "logs", "predicted", lambda e: e["error"])
    assert status == 0 and lines[-1] == "  note: a.mcap: the log's clock jumps"


def test_folders_whose_names_give_one_machine_name_are_refused():
    from greybox.fleet.engine import check_machines

    check_machines(["/p/a/m2/log.mcap", "/p/b/m2/log.mcap"])  # one name in two places: one machine, by design
    with pytest.raises(GreyboxError, match="the folders 'run 1' and 'run_1' both give the machine name run_1"):
        check_machines(["/p/run 1/a.mcap", "/p/run_1/b.mcap"])
