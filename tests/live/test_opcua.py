"""``greybox live --source opc.tcp://...`` against a real asyncua server in the test process: the estimates equal
``greybox predict`` on the same samples; the log-in, the variables and the server are checked at the start (one
line, exit 2); a malformed value is one line and the stream goes on; a server restart is survived and counted."""

from __future__ import annotations

import _thread
import datetime
import io
import math
import threading

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, free_port, joined, run_cli, wait_until

from greybox.errors import GreyboxError
from greybox.live.opcua import OpcUaOptions, parse_nodes, parse_opcua_address
from greybox.live.opcua_samples import stamp_seconds
from greybox.live.run import run_live


def live_until(model_path, source: str, options: OpcUaOptions, *, act, until, timeout_s: float = 20.0, **kwargs):
    """Run ``run_live`` here (the main thread) on an OPC UA source; a helper thread does ``act()`` once it has
    started and stops it, as Ctrl-C does, once ``until(output, lines)`` holds. Returns (output, lines)."""
    out, said, failed = io.StringIO(), [], []
    finished = threading.Event()

    def drive():
        try:
            wait_until(lambda: finished.is_set() or any(line.startswith("greybox live:") for line in said), "start",
                       timeout_s)
            if finished.is_set():
                return
            act()
            wait_until(lambda: finished.is_set() or until(out.getvalue(), said), "the estimates", timeout_s)
        except BaseException as exc:  # re-raised in the test
            failed.append(exc)
        if not finished.is_set():
            _thread.interrupt_main()

    helper = threading.Thread(target=drive, daemon=True)
    helper.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_live(model_path, source=source, opcua=options, axis_config_path=EXAMPLE_AXIS, stdout=out,
                     say=said.append, **kwargs)
    finally:
        finished.set()
        helper.join(5.0)
    if failed:
        raise AssertionError(f"{failed[0]!r}; the lines said: {said}") from failed[0]
    return out.getvalue(), said


def estimated(output: str) -> int:
    rows = [line for line in output.splitlines() if line.strip() and '"alarm"' not in line]
    return len(joined(rows)["time_s"]) if rows else 0


@pytest.mark.parametrize("kind, seconds", [("coulomb", 1.0), pytest.param("gmssvr", None, marks=pytest.mark.slow)])
def test_estimates_equal_predict(kind, seconds, opcua_server, model_file, offline, cut_raw):
    """Each sample written to the server's variables, one at a time, comes out as ``greybox predict`` has it (the
    first second of the cutting log in the default run, all of it in the slow one)."""
    path = model_file(kind)
    log = cut_raw if seconds is None else cut_raw.select(slice(0, int(round(seconds / cut_raw.sample_time))))
    expected = offline(path) if seconds is None else offline(path, log, name=f"cut-{seconds:g}s")
    axis = opcua_server.axis()
    axis.publish(log, 0, 1)  # the values the subscription starts with: the log's first sample
    output, said = live_until(path, opcua_server.url, OpcUaOptions(nodes=axis.node_ids()),
                              act=lambda: axis.publish(log, 1, every=25),
                              until=lambda out, _: estimated(out) >= len(log))
    live = joined(output.splitlines())
    assert list(live) == list(expected.columns) and len(expected) == len(log)
    for name in expected.columns:  # the tolerance of the other sources' tests: rounding only
        np.testing.assert_allclose(live[name], expected[name].to_numpy(), rtol=0, atol=1e-9, err_msg=name)
    assert f"reading {opcua_server.url}" in said[0]
    assert f"0 rejected), {len(log)} samples received, {len(log)} estimated, 0 dropped" in said[-1], said
    assert "0 gap(s), 0 disconnection(s)" in said[-1], said


def test_each_variable_with_its_own_jittered_stamp_and_no_time_variable(opcua_server, model_file, offline, cut_raw):
    """A server that stamps each variable as it writes it, no time variable: the values of a sample (stamps within
    0.4 ms of each other) are matched, its time is their stamps' mean, and the jitter of the samples' times (beyond
    the 25 % tolerance) is bridged by --max-gap as ``greybox predict --resample --max-gap`` bridges it."""
    path = model_file("coulomb")
    log = cut_raw.select(slice(0, 500))
    rng = np.random.default_rng(3)
    times = 1e3 + log.time + rng.uniform(-0.3e-3, 0.3e-3, len(log))  # each sample's moment [s since 1970]
    columns = ("position_mm", "velocity_mm_s", "current_A")
    # whole microseconds (a datetime's resolution), as the client reads them back
    stamps = {column: np.array([stamp_seconds(datetime.datetime.fromtimestamp(value, tz=datetime.timezone.utc))
                                for value in np.round(1e6 * (times + rng.uniform(-0.2e-3, 0.2e-3, len(log)))) / 1e6])
              for column in columns}
    mean = np.array([math.fsum(values) / len(values) for values in zip(*(stamps[column] for column in columns))])
    assert np.diff(mean).max() > 1.25 * log.sample_time  # a jitter beyond the tolerance, bridged by --max-gap
    expected = offline(path, log.replace(time=mean), name="cut-stamped",
                       extra=["--resample", "0.002", "--max-gap", "5"])
    axis = opcua_server.axis()
    axis.publish_stamped(log, stamps, 0, 1)
    output, said = live_until(path, opcua_server.url, OpcUaOptions(nodes=axis.node_ids(columns)),
                              act=lambda: axis.publish_stamped(log, stamps, 1, every=25),
                              until=lambda out, _: estimated(out) >= len(expected), sample_time=0.002, max_gap=5.0)
    live = joined(output.splitlines())
    assert len(live["time_s"]) == len(expected)
    for name in ("time_s", "current_model_A", "current_process_A"):
        np.testing.assert_allclose(live[name], expected[name].to_numpy(), rtol=0, atol=1e-9, err_msg=name)
    assert "0 gap(s)" in said[-1] and "0 rejected" in said[-1], said


def test_a_user_logs_in_with_a_password(opcua_server, model_file, cut_raw, tmp_path, capsys, monkeypatch):
    axis = opcua_server.axis()
    axis.publish(cut_raw, 0, 1)
    source = opcua_server.url.replace("opc.tcp://", "opc.tcp://user@")
    output, said = live_until(model_file("coulomb"), source, OpcUaOptions(nodes=axis.node_ids(), password="secret"),
                              act=lambda: axis.publish(cut_raw, 1, 200),
                              until=lambda out, _: estimated(out) >= 199)
    assert estimated(output) == 199 + 1 - 0  # the first sample and the 199 after it, the tail at the idle time
    wrong = tmp_path / "password"
    wrong.write_text("guess\n")
    capsys.readouterr()
    status = run_cli(["live", model_file("coulomb"), "--source", source, *axis.node_options(),
                      "--opcua-password-file", wrong, "--connect-timeout", "5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert "refused the connection" in err[0] and "guess" not in err[0], err


def test_a_secured_connection_with_a_certificate(opcua_server, model_file, cut_raw):
    """Basic256Sha256, signed and encrypted, with the client's certificate and the server's one pinned."""
    axis = opcua_server.axis()
    axis.publish(cut_raw, 0, 1)
    options = OpcUaOptions(nodes=axis.node_ids(), security="Basic256Sha256,SignAndEncrypt",
                           cert_file=str(opcua_server.client_cert), key_file=str(opcua_server.client_key),
                           server_cert_file=str(opcua_server.server_cert))
    output, said = live_until(model_file("coulomb"), opcua_server.url, options,
                              act=lambda: axis.publish(cut_raw, 1, 100), until=lambda out, _: estimated(out) >= 100)
    assert estimated(output) == 100


def test_a_server_other_than_the_pinned_one_is_refused(opcua_server, model_file, capsys):
    axis = opcua_server.axis()
    status = run_cli(["live", model_file("coulomb"), "--source", opcua_server.url, *axis.node_options(),
                      "--opcua-security", "Basic256Sha256,SignAndEncrypt", "--opcua-cert", opcua_server.client_cert,
                      "--opcua-key", opcua_server.client_key, "--opcua-server-cert", opcua_server.client_cert,
                      "--connect-timeout", "5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert f"--source {opcua_server.url}: the server's certificate is not the one of --opcua-server-cert" in err[0]


def test_a_node_the_server_lacks_is_refused_at_the_start(opcua_server, model_file, tmp_path, capsys):
    axis = opcua_server.axis()
    config = tmp_path / "live.toml"  # the options in the configuration file, as the command line takes them
    nodes = [f"{column}={node}" for column, node in axis.node_ids().items() if column != "current_A"]
    config.write_text(f'source = "{opcua_server.url}"\nnode = {nodes + ["current_A=ns=2;s=No.Such.Node"]!r}\n'
                      'sampling_ms = 2\npublishing_ms = 10\n'.replace("'", '"'))
    status = run_cli(["live", model_file("coulomb"), "--config", config])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert err[0].endswith(f"error: --node current_A=ns=2;s=No.Such.Node: no such variable on {opcua_server.url} "
                      "(BadNodeIdUnknown)"), err


def test_a_server_that_does_not_answer_is_one_line(model_file, capsys):
    status = run_cli(["live", model_file("coulomb"), "--source", f"opc.tcp://127.0.0.1:{free_port()}", "--node",
                      "time_s=ns=2;s=T", "--node", "position_mm=ns=2;s=P", "--connect-timeout", "2"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert "no OPC UA server answered within 2 s" in err[0], err


@pytest.mark.parametrize("argv, says", [
    (["--source", "-", "--node", "time_s=ns=2;s=T"], "--node applies to an opc.tcp:// source"),
    (["--source", "opc.tcp://localhost:4840"], "needs --node COLUMN=NODEID"),
    (["--source", "opc.tcp://u:pw@localhost:4840", "--node", "time_s=ns=2;s=T"], "a password in the address"),
    (["--source", "opc.tcp://localhost:4840", "--node", "time_s"], "give COLUMN=NODEID"),
    (["--source", "opc.tcp://localhost:4840", "--node", "time_s=ns=2;s=T", "--opcua-security", "Basic128,Sign"],
     "give POLICY,MODE"),
    (["--source", "opc.tcp://localhost:4840", "--node", "time_s=ns=2;s=T", "--opcua-security",
      "Basic256Sha256,SignAndEncrypt"], "needs the client certificate and its key"),
])
def test_options_are_checked_before_connecting(argv, says, model_file, capsys):
    status = run_cli(["live", model_file("coulomb"), *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and says in err[0], err
    assert "pw" not in err[0]


def test_a_malformed_value_is_one_line_and_the_stream_goes_on(opcua_server, model_file, cut_raw):
    axis = opcua_server.axis()
    axis.publish(cut_raw, 0, 1)

    def act():
        axis.publish(cut_raw, 1, 100)
        axis.write({"time_s": float(cut_raw.time[100]), "position_mm": float(cut_raw.position[100]),
                    "velocity_mm_s": float(cut_raw.velocity[100]), "current_A": "overload"})
        axis.publish(cut_raw, 101, 200)
        axis.write({"time_s": float(cut_raw.time[200]), "position_mm": float("nan"),
                    "velocity_mm_s": float(cut_raw.velocity[200]), "current_A": float(cut_raw.effort[200])})
        axis.publish(cut_raw, 201, 300)

    output, said = live_until(model_file("coulomb"), opcua_server.url, OpcUaOptions(nodes=axis.node_ids()), act=act,
                              until=lambda out, _: estimated(out) >= 297)
    skipped = [line for line in said if "skipped" in line]
    assert len(skipped) == 2, said
    assert "column 'current_A' holds 'overload', not a number" in skipped[0]
    assert "channel 'position_mm' holds nan" in skipped[1], skipped
    live = joined(output.splitlines())
    assert live["time_s"][-1] == pytest.approx(cut_raw.time[299])  # the stream went on past both


@pytest.mark.slow  # the client finds the server back after 1 s at the earliest: 3-4 s
def test_a_server_restart_is_survived_and_counted(own_opcua_server, model_file, cut_raw, tmp_path):
    import json

    axis = own_opcua_server.axis()
    axis.publish(cut_raw, 0, 1)
    stats = tmp_path / "stats.json"

    def act():
        axis.publish(cut_raw, 1, 200)
        own_opcua_server.restart()
        axis.publish(cut_raw, 200, 201)

    resumed = []

    def until(out, said):
        if not resumed and any("OPC UA server connection back" in line for line in said):
            resumed.append(True)
            axis.publish(cut_raw, 201, 400)
        return estimated(out) >= 300

    output, said = live_until(model_file("coulomb"), own_opcua_server.url, OpcUaOptions(nodes=axis.node_ids()), act=act,
                              until=until, stats_path=stats)
    assert sum("OPC UA server connection lost; reconnecting" in line for line in said) == 1, said
    assert not any("Traceback" in line for line in said)
    counters = json.loads(stats.read_text())
    assert counters["disconnections"] == 1
    live = joined(output.splitlines())
    assert live["time_s"][-1] >= cut_raw.time[300]


def test_addresses_and_nodes_are_read():
    address = parse_opcua_address("opc.tcp://plc@cnc.plant:4841/UA/Server")
    assert (address.host, address.port, address.path, address.username) == ("cnc.plant", 4841, "UA/Server", "plc")
    assert address.url == "opc.tcp://cnc.plant:4841/UA/Server" and parse_opcua_address("opc.tcp://h").port == 4840
    assert parse_nodes(["position_mm=ns=2;s=X.Pos"]) == {"position_mm": "ns=2;s=X.Pos"}
    with pytest.raises(GreyboxError, match="given twice"):
        parse_nodes(["a=ns=2;s=1", "a=ns=2;s=2"])
    with pytest.raises(GreyboxError, match="same node id"):
        OpcUaOptions(nodes={"a": "ns=2;s=1", "b": "ns=2;s=1"})


def _last_time(lines) -> float | None:
    """Time [s] of the newest estimate among JSON output lines, None before the first."""
    try:
        return float(joined(list(lines))["time_s"][-1])
    except (IndexError, ValueError, KeyError):
        return None


@pytest.mark.slow  # a greybox process of its own (its start takes seconds) and a restart of the server
def test_the_command_survives_a_server_restart_in_lines_of_its_own(own_opcua_server, model_file, cut_raw, tmp_path):
    """The command as a service runs it: a restart of the server is one line out and one back, counted; the client
    library's own reports (warnings, tracebacks of the reconnection attempts) do not reach stderr."""
    import json

    from live_helpers import LiveProcess

    axis = own_opcua_server.axis()
    axis.publish(cut_raw, 0, 1)
    stats = tmp_path / "stats.json"
    live = LiveProcess(model_file("coulomb"), "--source", own_opcua_server.url, *axis.node_options(),
                       "--axis-config", EXAMPLE_AXIS, "--stats", stats)
    estimates = []
    reader = threading.Thread(target=lambda: estimates.extend(live.process.stdout), daemon=True)
    reader.start()
    try:
        wait_until(lambda: live.said("reading opc.tcp://") or live.process.poll() is not None, "the start", 60)
        axis.publish(cut_raw, 1, 200)
        own_opcua_server.restart(down_s=1.5)
        wait_until(lambda: live.said("OPC UA server connection back"), "the reconnection", 30)
        axis.publish(cut_raw, 200, 400)
        # the last sample estimated once the stream is idle (how the samples split into runs depends on the pace
        # of this writer: a loaded machine may pause it longer than the idle timeout, which ends a run there)
        wait_until(lambda: _last_time(estimates) == pytest.approx(cut_raw.time[399]), "the last sample's estimate", 30)
    except AssertionError as exc:
        raise AssertionError(f"{exc}: {live.lines}") from None
    finally:
        status = live.stop()
    reader.join(5)
    assert status == 143, live.lines
    assert sum("OPC UA server connection lost; reconnecting" in line for line in live.lines) == 1, live.lines
    assert sum("OPC UA server connection back after" in line for line in live.lines) == 1, live.lines
    assert not [line for line in live.lines if "Traceback" in line or "asyncua" in line or "WARNING" in line]
    counters = json.loads(stats.read_text())
    assert counters["disconnections"] == 1 and counters["rejected"] == 0
    assert joined(estimates)["time_s"][-1] == pytest.approx(cut_raw.time[399])


def test_the_configuration_of_the_docs_runs(opcua_server, model_file, cut_raw, tmp_path, capsys):
    """The TOML example of docs/live.md, its server and axis those of the test server, as the configuration of the
    command; stopped by an alarm at the first estimate (exit status 3) while the test writes samples."""
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[2] / "docs" / "live.md").read_text(encoding="utf-8")
    section = page[page.index("## From an OPC UA server"):page.index("## Speed")]
    example = re.search(r"```toml\n(.*?)```", section, re.DOTALL).group(1)
    axis = opcua_server.axis()
    config = tmp_path / "opcua.toml"
    config.write_text(example.replace("opc.tcp://cnc1.plant:4840", opcua_server.url)
                      .replace("Axis.X.", f"{axis.name}.")
                      .replace('"examples/axis_x.toml"', f'"{EXAMPLE_AXIS.as_posix()}"'))
    axis.publish(cut_raw, 0, 1)
    finished = threading.Event()

    def write():
        for start in range(1, len(cut_raw) - 10, 10):
            if finished.is_set():
                return
            axis.publish(cut_raw, start, start + 10)

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    try:
        status = run_cli(["live", model_file("coulomb"), "--config", config, "--limit", "current_process_A=1e-12",
                          "--exit-on-alarm"])
    finally:
        finished.set()
        writer.join(30)
    captured = capsys.readouterr()
    assert status == 3, captured.err
    assert f"reading {opcua_server.url}" in captured.err and "force_process_N" in captured.out
