"""``greybox live`` as a command: stdin to stdout, one-line refusals with status 2, SIGTERM closes the
recording and the stats and exits with 143."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from live_helpers import EXAMPLE_AXIS, joined, json_batches, run_cli

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

#: Seconds a command under test may take before the test gives up on it.
TIMEOUT_S = 60


def greybox(*args, **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "greybox", "live", *map(str, args)], text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kwargs)


@pytest.mark.slow
def test_stdin_to_stdout_equals_predict(model_file, offline, cut_raw):
    path = model_file("gmssvr")
    process = greybox(path, "--source", "-", "--axis-config", EXAMPLE_AXIS)
    out, err = process.communicate("\n".join(json_batches(cut_raw, (10,))), timeout=TIMEOUT_S)
    assert process.returncode == 0, err
    live = joined(out.splitlines())
    np.testing.assert_allclose(live["current_model_A"], offline(path)["current_model_A"].to_numpy(), rtol=0, atol=1e-9)
    assert "stats: " in err.splitlines()[-1] and "Traceback" not in err


def test_bad_options_give_one_line_and_status_2(model_file, capsys):
    path = model_file("coulomb")
    cases = [(["--source", "tcp://x"], "--source tcp://x"),
             (["--source", "mqtt://127.0.0.1:1883"], "needs a host and a topic"),
             (["--source", "mqtt://127.0.0.1:99999/t"], "port"),
             (["--source", "-", "--limit", "force_process_N=abc"], "--limit force_process_N=abc"),
             (["--source", "-", "--limit-hold", "soon"], "--limit-hold soon"),
             (["--source", "-", "--sink", "file.txt"], "--sink file.txt")]
    for argv, words in cases:
        assert run_cli(["live", path, *argv]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0] and err[0].startswith("greybox live: error:"), (argv, err)
    for argv, words in [(["--max-gap", "1"], "argument --max-gap: must be a number of steps above 1"),
                        (["--latency", "fast"], "argument --latency: invalid choice: 'fast'")]:
        with pytest.raises(SystemExit) as stop:  # refused while the command line is parsed
            run_cli(["live", path, "--source", "-", *argv])
        err = capsys.readouterr().err.strip().splitlines()
        assert stop.value.code == 2 and len(err) == 1 and words in err[0], (argv, err)


def test_an_unreachable_broker_is_one_line(model_file, capsys):
    from live_helpers import free_port

    status = run_cli(["live", model_file("coulomb"), "--source", f"mqtt://127.0.0.1:{free_port()}/in",
                      "--connect-timeout", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "no broker answered within 1 s" in err[0]


@pytest.mark.slow
def test_sigterm_closes_the_recording_and_the_stats(model_file, cut_raw, tmp_path):
    path = model_file("gms")
    record, stats = tmp_path / "rec", tmp_path / "stats.json"
    process = greybox(path, "--source", "-", "--axis-config", EXAMPLE_AXIS, "--record", record, "--stats", stats)
    try:
        process.stdin.write("\n".join(json_batches(cut_raw, (10,))) + "\n")  # the stream stays open
        process.stdin.flush()
        first = process.stdout.readline()  # estimates are coming out
        assert json.loads(first)["time_s"][0] == 0.0
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline and not record.is_dir():
            time.sleep(0.05)
        time.sleep(0.5)
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=TIMEOUT_S)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 143, err
    files = sorted(record.iterdir())
    assert len(files) == 1 and files[0].suffix == ".parquet"  # closed, no temporary left
    table = pd.read_parquet(files[0])
    counts = json.loads(stats.read_text())
    assert len(table) == counts["samples_estimated"] > 0
    assert counts["samples_received"] == counts["samples_estimated"] + counts["skipped"] + counts["waiting"]
    assert counts["lost"].get("stopped before their look-ahead arrived", 0) > 0
    assert "terminated (SIGTERM)" in err and "Traceback" not in err
    assert os.path.exists(stats)


def test_broker_tests_skip_naming_the_package_without_mosquitto(monkeypatch, request):
    import live_helpers

    monkeypatch.setattr(live_helpers, "mosquitto_binary", lambda: None)
    with pytest.raises(pytest.skip.Exception, match="package 'mosquitto'"):
        request.getfixturevalue("broker")


@pytest.mark.slow
def test_sigkill_loses_at_most_a_second_of_the_recording(model_file, cut_raw, tmp_path):
    path = model_file("gms")
    record = tmp_path / "rec"
    process = greybox(path, "--source", "-", "--axis-config", EXAMPLE_AXIS, "--record", record)
    try:
        out = []
        for message in json_batches(cut_raw, (10,)):  # the stream stays open, as a broker's would
            process.stdin.write(message + "\n")
            process.stdin.flush()
        while sum(len(json.loads(line)["time_s"]) for line in out) < len(cut_raw) - 200:
            out.append(process.stdout.readline())
        process.kill()
        process.wait(timeout=TIMEOUT_S)
    finally:
        if process.poll() is None:
            process.kill()
    sent = joined(out)
    parts = sorted(record.glob("live-*.parquet"))
    assert parts and all(".part-" in part.name for part in parts)  # the file in progress: its parts
    table = pd.concat([pd.read_parquet(part) for part in parts], ignore_index=True)
    lost_s = sent["time_s"][-1] - table["time_s"].iloc[-1]
    assert lost_s <= 1.0, f"{lost_s:.3f} s of estimates lost"
    n = len(table)
    np.testing.assert_array_equal(table["time_s"].to_numpy(), sent["time_s"][:n])
    np.testing.assert_allclose(table["force_process_N"].to_numpy(), sent["force_process_N"][:n], rtol=0, atol=1e-9)


def test_the_config_file_gives_options_the_command_line_overrides(model_file, tmp_path, capsys):
    config = tmp_path / "live.toml"
    config.write_text('source = "-"\nsink = "file.txt"\nlimit = ["force_process_N=5"]\n')
    # the sink of the file is overridden; the limit on the force, without an axis file, is refused at the start
    assert run_cli(["live", model_file("coulomb"), "--config", config, "--sink", "-"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--limit force_process_N: no such output column" in err[0], err
    assert "the force needs --axis-config" in err[0]
    config.write_text('sink = "-"\n')
    assert run_cli(["live", model_file("coulomb"), "--config", config]) == 2
    assert "--source is required" in capsys.readouterr().err
