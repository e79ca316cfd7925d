"""The pages' result tables, rendered from the measured records (:mod:`studies.records`).

A page marks each rendered stretch with two HTML comments, invisible on GitHub and in the built site::

    <!-- record reproduce-exp1 -->
    | model | X train RMSE [A] | ... |
    <!-- end record -->

``reproduce-exp1`` names a view (:data:`VIEWS`): the records it reads and how it renders them.
:func:`render_text` replaces every marked stretch by its view of the records as they are now;
``python scripts/render_results.py`` does so for the README and every page of ``docs/``, and
``tests/studies/test_result_pages.py`` fails while a page differs from its rendering (a figure typed or
changed by hand) or a record is stale.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from greybox.atomic import write_text_atomic
from greybox.errors import GreyboxError
from greybox.evaluate.pattern import paper_pattern, paper_pattern_table, sole_svr_table
from greybox.evaluate.report import (
    MODEL_LABELS,
    experiment_table,
    hyperparameter_table,
    noise_floor_table,
    svr_generalisation_table,
)
from greybox.twin.noise import CurrentNoise

from .arts import MODEL_NAMES as ARTS_MODELS
from .arts import markdown_table as arts_table
from .cutting import detail_table as cutting_detail_table
from .cutting import sweep_table as cutting_sweep_table
from .emps import MODEL_NAMES as EMPS_MODELS
from .emps import markdown_table as emps_table
from .process_head_to_head import RATE, false_alarm_table, head_to_head_table, targets
from .records import ROOT, read_record

__all__ = ["BLOCK", "View", "VIEWS", "PAGES", "render_text", "render_pages", "cited_records"]

#: A marked stretch of a page: the view's name, the rendered text.
BLOCK = re.compile(r"(?P<open><!-- record (?P<view>[\w-]+) -->\n)(?P<body>.*?)(?P<close><!-- end record -->)", re.S)

#: The pages rendered: the README and every Markdown page of the documentation.
PAGES = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))


def _pipe(table) -> str:
    return "\n".join(table.pipe_lines()) + "\n"


def _metrics(record: dict) -> list[dict]:
    return record["figures"]["metrics"]


def _test_re(record: dict, experiment: int, axis: str, model: str) -> float:
    for row in _metrics(record):
        if (row["experiment"], row["axis"], row["model"], row["dataset"]) == (experiment, axis, model, "test"):
            return row["re"]
    raise GreyboxError(f"record {record['name']}: no test record of {model} on {axis} in experiment {experiment}")


def _load(record: dict) -> str:
    return f"load {record['load_before'][0]:.1f} before, {record['load_after'][0]:.1f} after"


def _where(record: dict) -> str:
    return f"{record['cores']} cores, {_load(record)}; commit {record['commit'][:9]}, {record['date'][:10]}"


def _reproduce_run(record: dict) -> str:
    figures = record["figures"]
    return (f"`{record['command']}` (the experiments of `greybox reproduce --out DIR` with {figures['jobs']} jobs)"
            f" took {figures['seconds']:.0f} s wall and {figures['cpu_seconds']:.0f} s of CPU time "
            f"({_where(record)}).\n")


def _reproduce_exp(experiment: int) -> Callable[[dict], str]:
    return lambda record: _pipe(experiment_table(_metrics(record), experiment))


def _reproduce_per_log(record: dict) -> str:
    cells = {}
    for row in _metrics(record):
        if row["experiment"] == 2 and row["dataset"] == "test" and row["model"] != "noise_floor":
            for log, figures in row.get("per_log", {}).items():
                cells.setdefault(row["model"], {})[f"{row['axis']} on {log}"] = figures["re"]
    columns = sorted({column for models in cells.values() for column in models})
    lines = ["| model | " + " | ".join(columns) + " |", "|" + "---|" * (len(columns) + 1)]
    lines += [f"| {MODEL_LABELS.get(model, model)} | " + " | ".join(f"{res[c]:.2f}" if c in res else "–"
                                                                    for c in columns) + " |"
              for model, res in cells.items()]
    return "\n".join(lines) + "\n"


def _reproduce_summary(record: dict) -> str:
    first, second = (experiment_table(_metrics(record), n) for n in (1, 2))
    axes = [name.split()[0] for name in first.header[1:] if name.endswith("test RE [%]") and "paper" not in name]

    def cells(table, label):
        for row in table.rows:
            if row[0] == label:
                values = dict(zip(table.header, row))
                ours = " / ".join(values[f"{axis} test RE [%]"] for axis in axes)
                paper = " / ".join(values[f"{axis} paper test RE [%]"] for axis in axes)
                return ours, "–" if set(paper.split(" / ")) == {"–"} else paper
        return "–", "–"

    labels = [row[0] for row in first.rows] + [row[0] for row in second.rows if row[0] not in
                                               {r[0] for r in first.rows}]
    floor = [label for label in labels if label.startswith("noise floor")]
    lines = [f"| model | exp. 1 (train A, test C) {' / '.join(axes)} | paper | exp. 2 (train A + B, test C + D) "
             f"{' / '.join(axes)} | paper |", "|---|---|---|---|---|"]
    for label in [label for label in labels if label not in floor] + floor:
        lines.append("| " + " | ".join([label, *cells(first, label), *cells(second, label)]) + " |")
    return "\n".join(lines) + "\n"


def _reproduce_table(table_of: Callable, key: str = "metrics") -> Callable[[dict], str]:
    return lambda record: _pipe(table_of(record["figures"][key]))


def _tests_run(record: dict) -> str:
    figures = record["figures"]
    skipped = f", {figures['skipped']} skipped" if figures["skipped"] else ""
    return f"`pytest -q -n 2`: {figures['passed']} passed{skipped} in {figures['seconds']:.0f} s ({_where(record)}).\n"


def _readme_table(reproduction: dict, tests: dict, monitor: dict) -> str:
    checks = paper_pattern(_metrics(reproduction))
    met = sum(check["met"] for check in checks)
    second = " / ".join(f"{_test_re(reproduction, 2, axis, 'gmssvr'):.2f}" for axis in ("X", "Y"))
    figures = tests["figures"]
    skipped = f", {figures['skipped']} skipped" if figures["skipped"] else ""
    return ("| what | figure | page |\n|---|---|---|\n"
            f"| the paper's experiments on the shipped twin (`greybox reproduce --out DIR`) | GMS+SVR test RE X / Y "
            f"{second} % (experiment 2); the paper's pattern: {met} of {len(checks)} checks met; "
            f"{reproduction['figures']['seconds']:.0f} s ({_where(reproduction)}) | [reproduce](docs/reproduce.md) |\n"
            f"| the default test run (`pytest -q -n 2`) | {figures['passed']} passed{skipped} in "
            f"{figures['seconds']:.0f} s ({_where(tests)}) | [installation and tests](docs/install.md) |\n"
            f"{_readme_monitor_row(monitor)}")


def _readme_monitor_row(record: dict) -> str:
    variants = record["figures"]["variants"]
    drifts = [row for row in variants["spindle"]["machines"] if row["kind"] != "none"]
    days = ", ".join(f"{row['kind'].replace('_', ' ')} +{row['delay_days']}" for row in drifts)
    same = all(a.get("delay_days") == b.get("delay_days") and a.get("first") == b.get("first")
               for a, b in zip(variants["spindle"]["machines"], variants["plain"]["machines"]))
    quiet = all(row["n_alarms"] == 0 for row in variants["spindle"]["machines"] if row["kind"] == "none")
    ok = all(row["ok"] for v in ("spindle", "plain") for row in variants[v]["machines"])
    air = [row for row in variants.get("air", {}).get("machines", []) if row["kind"] != "none"]
    before = (f"; every log taken whole as an air cut (the way before): {sum(not row['ok'] for row in air)} of "
              f"{len(air)} drifts missed or late or named wrongly" if air else "")
    return (f"| `greybox monitor` on an independent simulator's production histories, development split "
            f"(`{record['command']}`) | with the spindle-load column: {days} days after onset"
            f"{', the same with --find-cuts' if same else ''}; stable machine {'quiet' if quiet else 'alarmed'} "
            f"(target 7 days, right feature first: {_met(ok)}){before} ({_where(record)}) "
            f"| [monitor](docs/monitor.md) |\n")


def _met(condition: bool) -> str:
    return "met" if condition else "**not met**"


def _monitor_independent(record: dict) -> str:
    variants = record["figures"]["variants"]
    order = ("spindle", "plain", "air")
    names = [v for v in order if v in variants] + sorted(set(variants) - set(order))
    labels = {"spindle": "`spindle`", "plain": "`plain` (`--find-cuts`)", "air": "`air`"}
    lines = ["| machine (truth) | onset | " + " | ".join(labels.get(v, v) for v in names) + " |",
             "|---|---|" + "---|" * len(names)]

    def cell(row: dict) -> str:
        if row["kind"] == "none":
            return f"{row['n_alarms']} alarms"
        if row["first"] is None:
            return "never"
        wrong = "" if row["right_first"] else " (wrong feature)"
        return f"{row['first']}, +{row['delay_days']} days{wrong}"

    machines = [row["machine"] for row in variants[names[0]]["machines"]]
    for i, machine in enumerate(machines):
        rows = [variants[v]["machines"][i] for v in names]
        kind = rows[0]["kind"].replace("_", " ") if rows[0]["kind"] != "none" else "stable"
        lines.append(f"| {machine} {kind} | {rows[0].get('onset', '-')} | " + " | ".join(cell(r) for r in rows) + " |")
    before = [sum(r.get("alarms_before_onset", 0) for r in variants[v]["machines"]) for v in names]
    lines.append("| alarms before an onset | | " + " | ".join(str(b) for b in before) + " |")
    met = " / ".join(f"{v}: {_met(all(r['ok'] for r in variants[v]['machines']))}" for v in names)
    return ("\n".join(lines) + f"\n\nTarget (within 7 days, the right feature first, nothing before an onset, "
            f"nothing on the stable machine): {met}. `{record['command']}` ({_where(record)}).\n")


def _live_cut_force(record: dict) -> str:
    lines = ["| cutting log | velocity | cutting samples | mean cut force, exact [N] | low latency [N] | difference "
             "| rms difference per sample [N] | truth [N] |", "|---|---|---|---|---|---|---|---|"]
    for row in record["figures"]["cut_force"]:
        velocity = "logged" if row["velocity_logged"] else "derived"
        lines.append(f"| {row['log']} | {velocity} | {row['cutting_samples']} | "
                     f"{row['mean_cut_force_exact_N']:.1f} | {row['mean_cut_force_low_N']:.1f} | "
                     f"{100 * row['relative_difference']:.3f} % | {row['rms_difference_N']:.2f} | "
                     f"{row['mean_cut_force_truth_N']:.1f} |")
    return "\n".join(lines) + "\n"


def _live_low_latency(record: dict) -> str:
    end = record["figures"]["end_to_end_low"]
    return (f"`{record['command']}`, {record['seconds']:.0f} s ({_where(record)}): through the local "
            f"Mosquitto at {end['rate_hz']:.0f} Hz in batches of {end['batch']}, with `--latency low`, publish -> "
            f"estimate p50 {end['p50_ms']:.2f} ms, p99 {end['p99_ms']:.2f} ms, max {end['max_ms']:.1f} ms "
            f"({end['answered']} of {end['messages']} messages answered); publish -> alarm "
            f"(`--limit current_process_A={end['alarm_limit_A']:g}`, {end['alarms']} alarm messages raised or "
            f"cleared) p50 {end['alarm_p50_ms']:.2f} ms, p99 {end['alarm_p99_ms']:.2f} ms, max "
            f"{end['alarm_max_ms']:.1f} ms.\n")


def _predict_hour(record: dict) -> str:
    f = record["figures"]
    lines = ["| one-hour log | figure | target |", "|---|---|---|"]
    for fmt, label in (("mcap", "MCAP"), ("parquet", "Parquet")):
        runs = f["predict"][fmt]
        gms, svr = runs["gms"], runs["gmssvr"]
        peak = max(gms["peak_rss_mb"], svr["peak_rss_mb"])
        lines.append(f"| `greybox predict` to Parquet, {label} log streamed: GMS / GMS+SVR | {gms['seconds']:.2f} s / "
                     f"{svr['seconds']:.2f} s wall, ratio **{runs['ratio']:.2f}**; peak {gms['peak_rss_mb']:.0f} / "
                     f"{svr['peak_rss_mb']:.0f} MB | ratio <= 1.5, peak <= 600 MB: "
                     f"{_met(runs['ratio'] <= 1.5 and peak <= 600)} |")
    long = f["long"]
    lines.append(f"| GMS+SVR on a Parquet log three times as long | {long['seconds']:.2f} s, peak "
                 f"{long['peak_rss_mb']:.0f} MB ({long['memory_ratio']:.2f}x the hour's) | memory independent of the "
                 f"length (within 10 %): {_met(long['memory_ratio'] <= 1.1)} |")
    k = f["kernel"]
    lines.append(f"| kernel sums of the hour's SVR inputs ({k['samples']} samples, {k['n_support']} support vectors) | "
                 f"former dense {k['former_s']:.2f} s; compiled {k['compiled_1_thread_s']:.2f} s on 1 thread "
                 f"({k['speedup_1_thread']:.2f}x), {k['compiled_threads_s']:.2f} s on all "
                 f"({k['speedup_threads']:.2f}x); "
                 f"largest difference {k['max_abs_difference_A']:.1e} A | |")
    t = f["train"]
    change = abs(t["test_re_percent"] - t["former_test_re_percent"])
    lines.append(f"| training on X_A + X_B: GMS stage / SVR stage of GMS+SVR | {t['gmssvr_gms_stage_s']:.1f} s / "
                 f"{t['gmssvr_svr_stage_s']:.1f} s: the whole **{t['gmssvr_over_gms_stage']:.2f}x** the GMS stage "
                 f"(SVR stage with the former kernel sums {t['former_svr_stage_s']:.1f} s); test RE on X_C "
                 f"{t['test_re_percent']:.2f} % ({t['former_test_re_percent']:.2f} % with the former sums); "
                 f"{t['n_support']} support vectors | <= 2x, test RE within 0.1 pp: "
                 f"{_met(t['gmssvr_over_gms_stage'] <= 2.0 and change <= 0.1)} |")
    read = f["read"]
    lines.append(f"| reading the hour whole (`read_log`), median of 5 reads | Parquet "
                 f"{read['parquet']['samples_per_s'] / 1e6:.2f} M samples/s; MCAP "
                 f"**{read['mcap']['samples_per_s'] / 1e6:.2f} M samples/s** ({read['mcap']['min_s']:.2f}-"
                 f"{read['mcap']['max_s']:.2f} s), with pyarrow's general JSON reader "
                 f"{read['mcap, general JSON reader']['samples_per_s'] / 1e6:.2f} M samples/s | >= 1 M samples/s: "
                 f"{_met(min(read['parquet']['samples_per_s'], read['mcap']['samples_per_s']) >= 1e6)} |")
    return ("\n".join(lines) + f"\n\n`{record['command']}`, {f['duration_s']:.0f} s of log, all in one run "
            f"({_where(record)}).\n")


def _process_head_to_head(label: str) -> Callable[[dict], str]:
    def view(record: dict) -> str:
        results = record["figures"][label]
        seeds = ", ".join(results["series"])
        good = ", ".join(results["good"])
        parts = record["figures"]["good_parts_per_series"]
        met = "; ".join(f"{name}: " + ", ".join(f"{what} {_met(ok)}" for what, ok in targets(results, name).items()
                                                if ok is not None)
                        for name in ("force, re-levelled", "raw, re-levelled"))
        return (f"Seeds {seeds} (the protocol's series):\n\n{head_to_head_table(results['series'])}\n"
                f"False alarms of all good parts: the series above and {len(results['good'])} series of {parts} "
                f"good parts (seeds {good}; the first 10 taught):\n\n{false_alarm_table(results['false_alarms'])}\n"
                f"Targets: {met}. `{record['command']}`, {record['seconds'] / 60:.1f} min ({_where(record)}).\n")
    return view


def _live_speed(record: dict) -> str:
    f = record["figures"]
    c, share, ends = f["compute"], f["cpu_share"], f["end_to_end"]
    least = c.get("least_cpu_p99_us_per_sample")
    rows = ["| figure | target | measured |", "|---|---|---|",
            f"| compute per sample, CPU time of the thread, one pass ({c['messages']} messages of {c['batch']}) | | "
            f"p50 {c['cpu_p50_us_per_sample']:.1f} us, p99 {c['cpu_p99_us_per_sample']:.1f} us |",
            f"| the same, each message's least CPU time over {c.get('repeats', 1)} passes (the code's own cost) | "
            f"p99 <= 50 us: {_met(least is not None and least <= 50.0)} | "
            + ("–" if least is None else f"p50 {c['least_cpu_p50_us_per_sample']:.1f} us, p99 {least:.1f} us") + " |",
            f"| CPU of {share['axes']} axes at 500 Hz, one pass | | "
            f"{100 * share['share_of_one_core']:.1f} % ({share['cpu_s']:.1f} CPU s for {share['stream_s']:.1f} s) |"]
    passes = ", ".join(f"{100 * value:.1f}" for value in share["pass_shares_of_one_core"])
    rows.append(f"| the same, the median over {len(share['pass_shares_of_one_core'])} passes ({passes} %) | "
                f"<= 25 % of one core: {_met(share['median_share_of_one_core'] <= 0.25)} | "
                f"{100 * share['median_share_of_one_core']:.1f} % |")
    if "least_share_of_one_core" in share:
        rows.append(f"| the same, each message's least CPU time over {share['repeats']} passes (the code's own cost) "
                    "| | "
                    f"{100 * share['least_share_of_one_core']:.1f} % |")
    if "p99_ms" in ends:
        over = f", {ends['over_5_ms']} of {ends['answered']} over 5 ms" if "over_5_ms" in ends else ""
        rows.append(f"| publish -> arrival of the estimate through the local Mosquitto, 500 Hz in batches of "
                    f"{ends['batch']} | p99 <= 5 ms: {_met(ends['p99_ms'] <= 5.0)} | p50 {ends['p50_ms']:.2f} ms, "
                    f"p99 {ends['p99_ms']:.2f} ms, max {ends['max_ms']:.2f} ms{over} |")
        if "live_cpu_share_of_one_core" in ends:
            rows.append(f"| CPU of the `greybox live` process of that run, one axis, all its threads (estimates and "
                        f"MQTT network threads) | | {100 * ends['live_cpu_share_of_one_core']:.1f} % of one core |")
    else:
        rows.append(f"| publish -> arrival of the estimate through the local Mosquitto | p99 <= 5 ms | "
                    f"{ends.get('skipped', 'not measured')} |")
    return ("\n".join(rows) + f"\n\n`{record['command']}` ({f['seconds']:.0f} s of `{Path(f['log']).name}`, "
            f"{f['model']}; {_where(record)}).\n")


# -- the real-data benchmarks and speed (issue 43) --
def _in_study_order(figures: dict, names: tuple) -> dict:
    """The figures with the models in the study's order, and the files in the protocol's (a record keeps its keys
    sorted)."""
    models = {name: figures["models"][name] for name in names if name in figures["models"]}
    ordered = {**figures, "models": models}
    if "files" in figures:
        files = [*figures["protocol"]["train"], *figures["protocol"]["test"]]
        ordered["files"] = {name: figures["files"][name] for name in files}
    return ordered


def _fit_seconds(record: dict) -> str:
    models = record["figures"]["models"]
    order = EMPS_MODELS if record["name"].startswith("emps") else ARTS_MODELS
    return ", ".join(f"`{name}` {models[name]['seconds']:.0f} s" for name in order
                     if name in models and models[name]["seconds"] >= 1)


def _benchmark_run(record: dict) -> str:
    slow = _fit_seconds(record)
    return (f"`{record['command']}` took {record['seconds']:.0f} s wall ({_where(record)})"
            + (f"; the fits of one second or more: {slow}" if slow else "") + ".\n")


def _emps_benchmark(record: dict) -> str:
    models = record["figures"]["models"]
    condition = models["coulomb_idim_ls"]["condition_number"]
    table = emps_table(_in_study_order(record["figures"], EMPS_MODELS))
    return (table + f"\nThe condition number of the decimated observation matrix is "
            f"{condition:.2f}.\n\n" + _benchmark_run(record))


def _emps_targets(record: dict) -> str:
    models = record["figures"]["models"]
    asym, coulomb = models["gms_asym"], models["coulomb_asym_idim_ls"]
    published = record["figures"]["published"]
    return ("| target | reference | measured | met? |\n|---|---|---|---|\n"
            f"| `gms_asym` train relerr <= 3.0 % | published asymmetric IDIM-LS "
            f"{published['coulomb_asym_idim_ls']['train_relerr']:.2f} % | {asym['train_relerr']:.2f} % | "
            f"{_met(asym['train_relerr'] <= 3.0)} |\n"
            f"| `gms_asym` cross-test relerr <= 5.0 % | asymmetric IDIM-LS {coulomb['test_relerr']:.2f} %, published "
            f"symmetric {published['coulomb_idim_ls']['test_relerr']:.2f} % | {asym['test_relerr']:.4f} % | "
            f"{_met(asym['test_relerr'] <= 5.0)} |\n")


def _arts_benchmark(record: dict) -> str:
    return arts_table(_in_study_order(record["figures"], ARTS_MODELS)) + "\n" + _benchmark_run(record)


def _arts_targets(record: dict) -> str:
    models = record["figures"]["models"]
    asym = {name: models[name]["test"]["re"] for name in ("gms_asym",)}
    best = min(models, key=lambda name: models[name]["test"]["re"])
    return ("| target | measured | met? |\n|---|---|---|\n"
            "| asymmetric GMS test RE <= 12 % (symmetric GMS 33 % at the time of the issue, trained and evaluated from "
            "the command line) | " + ", ".join(f"`{name}` {value:.2f} %" for name, value in asym.items())
            + f"; best model of the record `{best}` {models[best]['test']['re']:.2f} % | "
            f"{_met(min(asym.values()) <= 12.0)} |\n")


def _arts_band_budget(record: dict, target: float = 15.0) -> str:
    models = record["figures"]["models"]
    first = next(iter(models.values()))
    floor = first["fast"]["bands"]["floor"]
    allowed = float(np.sqrt(max(target ** 2 - floor ** 2, 0.0)))
    best = min(models, key=lambda name: models[name]["train"]["bands"]["re_band"])
    fitted, fast = models[best]["train"]["bands"]["re_band"], models[best]["fast"]["bands"]["re_band"]
    return (f"- The force above the band is an RE of {floor:.2f} % of the 1-2 Hz files (the floor row of the band "
            f"table), against {first['train']['bands']['floor']:.2f} % on the training files. It rises with the speed "
            f"and no model of the motion predicts it.\n"
            f"- So {target:g} % on the 1-2 Hz files needs an error in the band of at most "
            f"`sqrt({target:g}^2 - {floor:.2f}^2)` = {allowed:.2f} %. The best model of the record in the band, "
            f"`{best}`, has {fitted:.2f} % there **on its own training files**: carried to 1-2 Hz without any loss it "
            f"would still score `hypot({fitted:.2f}, {floor:.2f})` = {np.hypot(fitted, floor):.1f} %. It does lose "
            f"accuracy with speed: {fast:.2f} % in the band at 1-2 Hz.\n")


def _pair(models: dict, names: tuple, key) -> str:
    return " / ".join("–" if name is None or name not in models else f"{key(models[name]):.2f}" for name in names)


def _emps_summary(record: dict) -> str:
    models, published = record["figures"]["models"], record["figures"]["published"]
    rows = (("Coulomb + viscous (IDIM-LS, ours)", ("coulomb_idim_ls", "coulomb_asym_idim_ls")),
            ("Coulomb + viscous (greybox fit)", ("coulomb", "coulomb_asym")),
            ("Stribeck", ("stribeck", "stribeck_asym")), ("LuGre", ("lugre", "lugre_asym")),
            ("GMS, 1 ms", ("gms", "gms_asym")), ("GMS, 2 ms step", ("gms_2ms", None)))
    lines = ["| model | train (DATA_EMPS) symmetric / asymmetric | cross-test (DATA_EMPS_PULSES) symmetric / "
             "asymmetric |",
             "|---|---|---|",
             f"| published IDIM-LS | {published['coulomb_idim_ls']['train_relerr']:.2f} / "
             f"{published['coulomb_asym_idim_ls']['train_relerr']:.2f} | "
             f"{published['coulomb_idim_ls']['test_relerr']:.2f} / – |"]
    lines += [f"| {label} | {_pair(models, names, lambda e: e['train_relerr'])} | "
              f"{_pair(models, names, lambda e: e['test_relerr'])} |" for label, names in rows]
    if "auto" in models:
        auto = models["auto"]
        lines.append(f"| chosen by `--model auto`: `{auto['selection']['chosen']}` | {auto['train_relerr']:.2f} | "
                     f"{auto['test_relerr']:.2f} |")
    return "\n".join(lines) + "\n\n" + _emps_targets(record) + "\n" + _benchmark_run(record)


def _arts_summary(record: dict) -> str:
    models = record["figures"]["models"]
    rows = (("Coulomb + viscous", ("coulomb", "coulomb_asym")), ("Stribeck", ("stribeck", "stribeck_asym")),
            ("LuGre", ("lugre", "lugre_asym")), ("GMS", ("gms", "gms_asym")))
    lines = ["| model | train symmetric / asymmetric | test symmetric / asymmetric | 1-2 Hz tests symmetric / "
             "asymmetric |", "|---|---|---|---|"]
    lines += [f"| {label} | " + " | ".join(_pair(models, names, lambda e, role=role: e[role]["re"])
                                           for role in ("train", "test", "fast")) + " |" for label, names in rows]
    return "\n".join(lines) + "\n\n" + _benchmark_run(record)


def _readme_real_data(emps: dict) -> str:
    asym = emps["figures"]["models"]["gms_asym"]
    return ("| what | figure | page |\n|---|---|---|\n"
            f"| EMPS ball-screw drive, the asymmetric GMS (`{emps['command']}`) | relerr train "
            f"{asym['train_relerr']:.2f} %, cross-test {asym['test_relerr']:.2f} % (target <= 5.0: "
            f"{_met(asym['test_relerr'] <= 5.0)}; published IDIM-LS "
            f"{emps['figures']['published']['coulomb_idim_ls']['test_relerr']:.2f} %); {emps['seconds']:.0f} s "
            f"({_where(emps)}) | [EMPS](docs/emps-benchmark.md) |\n")


def _gms_kernel(record: dict) -> str:
    f = record["figures"]
    c = ("–" if f["c_ns_per_step"] is None else
         f"{f['c_ns_per_step']:.1f} ns/step (numba / C {f['ratio_to_c']:.2f}; largest difference "
         f"{f['c_max_abs_diff']:.1e} A)")
    return ("| quantity | value |\n|---|---|\n"
            f"| numba kernel, N = {f['n_elements']}, {f['n_steps'] / 1e6:g} M steps, best of the repeats | "
            f"{f['ns_per_step']:.1f} ns/step |\n"
            f"| plain C loop (`cc -O2`), same recursion | {c} |\n"
            f"| plain-Python reference ({f['python_steps']} steps) | {f['python_ns_per_step'] / 1000:.2f} us/step "
            f"(numba {f['speedup_vs_python']:.0f}x faster; largest difference {f['python_max_abs_diff']:.1e} A) |\n"
            f"| GMS-4 identification, {f['fit_samples']} samples (180 s at 500 Hz), defaults | "
            f"{f['fit_seconds']:.1f} s, "
            f"{f['fit_evaluations']} simulations, RMSE {f['fit_rmse_A']:.4f} A (noise 0.02 A) |\n"
            f"\n`{record['command']}`, {record['seconds']:.0f} s ({_where(record)}).\n")


def _speed_table(gms: dict, svr: dict, read: dict) -> str:
    g, s, r = gms["figures"], svr["figures"], read["figures"]
    formats = ", ".join(f"{label} {r[f'{fmt}_read_s']:.2f} s / {r[f'{fmt}_peak_mb']:.0f} MB"
                        for fmt, label in (("mcap", "MCAP"), ("parquet", "Parquet"), ("csv", "CSV")))
    c = "" if g["c_ns_per_step"] is None else (f", plain C loop of the same recursion {g['c_ns_per_step']:.1f} ns/step "
                                              f"(ratio {g['ratio_to_c']:.2f})")
    return ("| what | command | figure |\n|---|---|---|\n"
            f"| GMS kernel (N = {g['n_elements']}, {g['n_steps'] / 1e6:g} M steps, best of the repeats) | "
            f"`{gms['command']}` | {g['ns_per_step']:.1f} ns/step compiled, {g['python_ns_per_step']:.0f} ns/step "
            f"plain Python ({g['speedup_vs_python']:.0f}x){c} |\n"
            f"| GMS identification, {g['fit_samples']} samples | same | {g['fit_seconds']:.1f} s, "
            f"{g['fit_evaluations']} simulations |\n"
            f"| reading a one-hour 500 Hz log ({r['n_samples'] / 1e6:.1f} M samples), fresh process, time / peak | "
            f"`{read['command']}` | {formats} |\n"
            f"| SVR prediction, {s['n_samples']} random samples (the kernel's worst case: few terms left out), "
            f"{s['n_support']} support vectors | `{svr['command']}` | compiled expansion {s['compiled_s']:.3f} s vs "
            f"scikit-learn {s['sklearn_s']:.1f} s ({s['speedup']:.1f}x), max difference {s['max_abs_diff']:.1e} A |\n"
            f"\nMeasured: `{gms['command']}` {_where(gms)}; `{read['command']}` {_where(read)}; `{svr['command']}` "
            f"{_where(svr)}.\n")
# -- end of the real-data benchmarks and speed (issue 43) --



# -- the pages of h43pages1 (issue 43): compensate, validation, discover --
#: The feed-forwards of ``greybox compensate`` as the pages name them.
_FEEDFORWARDS = {"none": "inertia only", "coulomb": "Coulomb", "stribeck": "Stribeck", "lugre": "LuGre",
                 "gms": "GMS", "gmssvr": "GMS+SVR"}


def _compensate_rows(record: dict, reference: str) -> list[dict]:
    rows = [row for row in record["figures"]["rows"] if row["reference"] == reference]
    if not rows:
        raise GreyboxError(f"record {record['name']}: no rows of the {reference} reference")
    return rows


def _compensate_tables(record: dict) -> str:
    f = record["figures"]
    lines = []
    for reference, label in (("low-stroke", "Low-stroke reference (0.2 mm)"),
                             ("high-stroke", "High-stroke reference (20 mm)")):
        lines += [f"{label}:", "", "| friction feed-forward | RMS error [um] | max error [um] | RMS vs none [%] |",
                  "|---|---:|---:|---:|"]
        lines += [f"| {row['feedforward']} | {1e3 * row['rms_error_mm']:.4g} | {1e3 * row['peak_error_mm']:.4g} | "
                  f"{100 * row['rms_vs_none']:.1f} |" for row in _compensate_rows(record, reference)]
        lines.append("")
    return (f"`{f['command']}` (`{record['command']}`) took {f['seconds']:.0f} s ({_where(record)}).\n\n"
            + "\n".join(lines))


def _compensate_summary(record: dict) -> str:
    low, high = (_compensate_rows(record, reference) for reference in ("low-stroke", "high-stroke"))
    lines = ["| feed-forward | low stroke | high stroke |", "|---|---|---|"]
    lines += [f"| {_FEEDFORWARDS.get(a['feedforward'], a['feedforward'])} | {1e3 * a['rms_error_mm']:.3f} "
              f"({100 * a['rms_vs_none']:.0f}) | {1e3 * b['rms_error_mm']:.3f} ({100 * b['rms_vs_none']:.0f}) |"
              for a, b in zip(low, high)]
    return ("\n".join(lines) + f"\n\n`{record['command']}`, {record['figures']['seconds']:.0f} s "
            f"({_where(record)}).\n")


def _intervals_cost(record: dict) -> str:
    f = record["figures"]
    return (f"Cost on the shipped data (`{record['command']}`, {f['model'].upper()} on {f['log']}, {f['n_samples']} "
            f"samples; {_where(record)}): the fit took {f['fit_s']:.1f} s, the sandwich intervals over "
            f"{f['n_clusters']} {f['clusters']} {f['intervals_s']:.2f} s (ratio {f['ratio']:.3f}).\n")


#: The bases of ``scripts/discovery_study.py --section emps`` as the pages name them.
_DISCOVER_BASES = {"coulomb --offset": "Coulomb + offset", "gms --offset": "GMS + offset"}


def _named(document: dict) -> str:
    return ", ".join(f"`{effect['name']}`" for effect in document["effects"]) or "none"


def _held_out(held_out: dict) -> str:
    return f"held-out gain {100 * held_out['gain']:.2f} +- {100 * held_out['uncertainty']:.2f} %"


def _refinements(document: dict) -> str:
    refinements = (document.get("base_misfit") or {}).get("refinements", {})
    return "; ".join(f"`{name}` {'kept' if entry['kept'] else 'not kept'} ({_held_out(entry['held_out'])})"
                     for name, entry in refinements.items()) or "none tried"


def _discover_emps(record: dict) -> str:
    bases = record["figures"]
    lines = ["| base | named (in order) | train relerr % | cross-test relerr % | test RMSE [N], 1 kHz | "
             "at constant feed [N] | at reversals [N] | s |", "|---|---|---|---|---|---|---|---|"]
    notes = []
    for key, label in _DISCOVER_BASES.items():
        document, bench = bases[key]["document"], bases[key]["benchmark"]
        regimes = document["test"]["regimes"]
        lines.append(
            f"| {label} | {_named(document)} | "
            f"{bench['train_relerr_before']:.2f} -> {bench['train_relerr_after']:.2f} | "
            f"{bench['test_relerr_before']:.2f} -> {bench['test_relerr_after']:.2f} | "
            f"{document['test_rmse_before']:.2f} -> {document['test_rmse_after']:.2f} | "
            f"{regimes['constant_feed']['rmse_before']:.2f} -> {regimes['constant_feed']['rmse_after']:.2f} | "
            f"{regimes['reversal']['rmse_before']:.2f} -> {regimes['reversal']['rmse_after']:.2f} | "
            f"{document['seconds']:.0f} |")
        effects = "; ".join(
            f"`{effect['name']}` (" + ", ".join(f"{name} {value:.4g}" for name, value in effect["parameters"].items())
            + f"; {_held_out(effect['evidence']['held_out'])})" for effect in document["effects"]) or "none"
        rejected = "; ".join(f"`{entry['name']}` ({', '.join(entry['held_out']['reasons']) or entry['reason']})"
                             if "held_out" in entry else f"`{entry['name']}` ({entry['reason']})"
                             for entry in document["rejected"]) or "none"
        notes.append(f"- **{label}**, verdict `{document['verdict']}`. Named: {effects}. Base refinements: "
                     f"{_refinements(document)}. Passed the null test but not named: {rejected}.")
    return ("\n".join(lines) + "\n\n" + "\n".join(notes) + f"\n\n`{record['command']}` took "
            f"{record['seconds']:.0f} s ({_where(record)}).\n")


def _discover_emps_summary(record: dict) -> str:
    lines = ["| base | named (in order) | train RMSE [N] | cross-test relerr % |", "|---|---|---|---|"]
    for key, label in _DISCOVER_BASES.items():
        document, bench = record["figures"][key]["document"], record["figures"][key]["benchmark"]
        lines.append(f"| {label} | {_named(document)} | {document['train_rmse_before']:.2f} -> "
                     f"{document['train_rmse_after']:.2f} | {bench['test_relerr_before']:.2f} -> "
                     f"{bench['test_relerr_after']:.2f} |")
    return "\n".join(lines) + f"\n\n`{record['command']}`, {record['seconds']:.0f} s ({_where(record)}).\n"
# -- end of the pages of h43pages1 --
def _process_speed(record: dict) -> str:
    f = record["figures"]
    ratio = f["real_time_ratio"]
    return (f"`{record['command']}`: {f['parts']} good parts of the twin ({f['log_s']:.0f} s of log) checked in "
            f"{f['wall_s']:.1f} s {'on one core' if f['one_core'] else 'unpinned (no taskset)'}: "
            f"**{ratio:.1f} x real time** (target at least {f['target_ratio']:g} x: "
            f"{_met(ratio >= f['target_ratio'])});"
            f" {f['flagged']} of them flagged; load {f['load_before'][0]:.1f} before the check, "
            f"{f['load_after'][0]:.1f} after ({_where(record)}).\n")
# -- the predict and monitor pages (issue 43) --
def _cutting_detail(record: dict) -> str:
    f = record["figures"]
    noise = ", ".join(f"{case['name']} {case['noise_rms_A']:.4f} A" for case in f["cases"])
    return (f"At the cut strength {f['detail_strength_A']:g} A:\n\n{cutting_detail_table(f['rows'])}\n"
            f"Current noise rms (`truth_noise_A`): {noise}.\n")


def _cutting_sweep(record: dict) -> str:
    f = record["figures"]
    fits = {}
    for row in f["rows"]:
        fits.setdefault(row["model"], row["fit_s"])
    slow = ", ".join(f"{MODEL_LABELS.get(kind, kind)} {seconds:.0f} s" for kind, seconds in fits.items())
    return (cutting_sweep_table(f["rows"], f["cases"], f["target"])
            + f"\n`{record['command']}` took {record['seconds']:.0f} s wall ({_where(record)}); the fits: {slow}.\n")


def _drift_rate(kind: str, rate: float) -> str:
    return f"{rate * 1000:g} um of play per day" if kind == "backlash" else f"{rate * 100:g} % of the level per day"


def _monitor_detection(record: dict) -> str:
    results = record["figures"]
    order = ("lubrication", "preload", "backlash", "defect")  # a record keeps its keys sorted
    drifts = {kind: results[kind] for kind in sorted(set(results) - {"none"},
                                                    key=lambda k: (order.index(k) if k in order else len(order), k))}
    seeds = len(next(iter(drifts.values()))["delays_days"])
    lines = [f"| drift (rate) | days from onset to the first alarm ({seeds} seeds) | median | within 7 days | "
             "first alarm named | right feature first |", "|---|---|---|---|---|---|"]
    for kind, r in drifts.items():
        delays = ", ".join("never" if d is None else str(d) for d in r["delays_days"])
        named = ", ".join(f"{name} ({r['first_named'].count(name)})"
                          for name in sorted(set(r["first_named"]), key=lambda n: (-r["first_named"].count(n), n)))
        median = "–" if r.get("median_delay_days") is None else f"{r['median_delay_days']:g}"
        right = f"{r['right_first']} of {seeds}"
        lines.append(f"| {kind} ({_drift_rate(kind, r['rate_per_day'])}) | {delays} | {median} | "
                     f"{r['within_7_days']} of {seeds} | {named} | "
                     f"{right if r['right_first'] == seeds else f'**{right}**'} |")
    early = sum(r["false_alarms"] for r in drifts.values())
    watched = next(iter(drifts.values()))["axis_days_watched_stable"]  # the same days before every kind's onset
    text = "\n".join(lines) + (f"\n\nAlarms before an onset: {early} (the {watched} axis-days from the end of the "
                               f"baseline to the onset, in each drift's run)")
    if "none" in results:
        stable = results["none"]
        text += (f"; on the {seeds} stable axes: {stable['false_alarms']} in {stable['axis_days_watched_stable']} "
                 f"axis-days after the baseline")
    total = seeds * len(drifts)
    within = sum(r["within_7_days"] for r in drifts.values())
    right = sum(r["right_first"] for r in drifts.values())
    quiet = early == 0 and results.get("none", {}).get("false_alarms", 0) == 0
    return (text + f". Targets: within 7 days of the onset {within} of {total} ({_met(within == total)}), the right "
            f"feature first {right} of {total} ({_met(right == total)}), nothing before an onset or on a stable axis "
            f"({_met(quiet)}). `{record['command']}`, {record['seconds']:.0f} s ({_where(record)}).\n")


def _monitor_fleet(record: dict) -> str:
    f = record["figures"]
    return ("| logs | samples | predict | monitor | monitor / predict | without detection and dashboard | "
            "target (>= 80 % on one-hour logs) |\n|---|---|---|---|---|---|---|\n"
            f"| {f['logs']} production days of {f['samples'] // f['logs']:,} samples ({f['repeat']} runs of the day's "
            f"programme) | "
            f"{f['samples']:,} | {f['predict_s']:.1f} s ({f['predict_samples_per_s'] / 1e3:.0f} k samples/s) | "
            f"{f['monitor_s']:.1f} s ({f['monitor_samples_per_s'] / 1e3:.0f} k samples/s) | "
            f"**{100 * f['ratio']:.0f} %** | {100 * f['ratio_logs_only']:.0f} % ({f['analysis_s']:.1f} s timed "
            f"alone) | "
            f"{_met(f['ratio'] >= 0.8)} |\n\n"
            f"{f['workers']} worker, {f['model']} reference model, {f['fingerprinted']} logs fingerprinted, "
            f"{f['predict_failed']} failed in predict. `{record['command']}`, {record['seconds']:.0f} s "
            f"({_where(record)}).\n")


def _monitor_query(record: dict) -> str:
    f = record["figures"]
    size, compacted = f["size"], f["compacted"]
    rows = size["machines"] * size["axes"] * size["days"]
    compaction = ("" if "compaction_s" not in f else
                  f"; the last day's {f['files_before_compaction']} row files compacted in {f['compaction_s']:.1f} s")
    return (f"A history of {size['machines']} machines x {size['axes']} axes x {size['days']} days of daily "
            f"fingerprints ({rows:,} rows){compaction}, then `changed_most(history, days=30)` over its "
            f"{compacted['files']} files: median {compacted['median_s']:.2f} s, largest {compacted['max_s']:.2f} s "
            f"of the repeated queries, one DuckDB thread; the shifted axes first: "
            f"{'yes' if compacted['shifted_axes_first'] else '**no**'}. `{record['command']}` ({_where(record)}).\n")
def _predict_relevel(record: dict) -> str:
    f = record["figures"]

    def cell(errors: dict) -> str:
        return f"{errors['mean_pct']:.1f} / {errors['mean_abs_pct']:.1f} / {errors['max_abs_pct']:.1f} %"

    lines = ["| series | chunk | off: mean / mean abs / max abs | on: mean / mean abs / max abs |", "|---|---|---|---|"]
    names = sorted(f["series"], key=lambda name: (name != "warm-up", name))  # a record keeps its keys sorted
    for case in (f["series"][name] for name in names):
        for i, chunk in enumerate(f"{chunk:g}" for chunk in f["chunks_s"]):
            on = case["on"][chunk]
            label = f"{case['what']}, parts {case['parts']} ({on['parts']} parts)" if i == 0 else "same"
            lines.append(f"| {label} | {chunk} s | {cell(case['off']) if i == 0 else 'same'} | {cell(on)} |")
    return ("\n".join(lines) + f"\n\nModel: `{f['model']}`. `{record['command']}`, {record['seconds']:.0f} s "
            f"({_where(record)}).\n")


# -- end of the predict and monitor pages (issue 43) --


# -- the walk-through of usage.md and predict.md, the log formats' reading speed (issue 43, h43pages3) --


def _console(lines: list) -> str:
    return "```\n" + "\n".join(lines) + "\n```\n"


def _walkthrough_predict(record: dict) -> str:
    return _console(record["figures"]["predict_lines"]) + f"\n(`{record['command']}`, {_where(record)}.)\n"


def _walkthrough_table(record: dict) -> str:
    return _console(record["figures"]["table_text"].splitlines())


def _walkthrough_row(record: dict) -> str:
    row = record["figures"]["row_at_10_s"]
    return (f"At 10 s the axis feeds at {row['velocity_mm_s']:.0f} mm/s through the workpiece: the model expects "
            f"{row['current_model_A']:.2f} A of friction, the drive draws {row['current_measured_A']:.2f} A, and the "
            f"{abs(row['current_process_A']):.2f} A more are {abs(row['force_process_N']):.0f} N of feed force (the "
            f"tooth-passing ripple and the current noise of a single sample included).\n")


def _walkthrough_cut(record: dict) -> str:
    f = record["figures"]
    start, end = f["cut_stretch_s"]
    return (f"In the cut the process current stands at {f['cut_mean_current_A']:.2f} A, {f['cut_mean_force_N']:.0f} N "
            f"(its mean from {start:g} to {end:g} s; the true cut there, `truth_process_force_N`, is "
            f"{f['cut_true_force_N']:.0f} N). On the air-cut return stroke (after {f['air_after_s']:g} s) it "
            f"scatters around zero with a standard deviation of {f['air_process_std_A']:.3f} A, the model's "
            f"air-cut error with the log's current noise ({f['noise_rms_A']:.3f} A rms) in it: the resolution of "
            f"the force estimate.\n")


def _walkthrough_interval(record: dict) -> str:
    return _console(record["figures"]["interval_lines"])


def _walkthrough_outside(record: dict) -> str:
    return _console(record["figures"]["evaluate_lines"])


def _walkthrough_stribeck(record: dict) -> str:
    f = record["figures"]
    return (_console(["..."] + f["outside_lines"]) + "\n(a Stribeck model trained on dataset A alone, the 50 mm "
            "window, predicting the cut of trajectory D over the whole travel; D's 1200 mm/min lies inside A's "
            f"speeds). The walk-through's GMS+SVR model, trained on A and B, prints on the same log: "
            f"`{f['outside_gmssvr']}`.\n")


def _log_formats_read_speed(record: dict) -> str:
    read = record["figures"]["read"]
    fast, general = read["mcap"], read["mcap, general JSON reader"]
    return (f"{fast['samples_per_s'] / 1e6:.2f} M samples/s with the compiled reader against "
            f"{general['samples_per_s'] / 1e6:.2f} M samples/s with the general one (median of 5 reads; "
            f"`{record['command']}`, {_where(record)}).\n")


def _discover_twin(record: dict) -> str:
    f = record["figures"]
    document = f["document"]
    effects = "; ".join(
        f"`{effect['name']}` (" + ", ".join(f"{name} {value:.4g}" for name, value in effect["parameters"].items())
        + f"; {_held_out(effect['evidence']['held_out'])})" for effect in document["effects"]) or "none"
    return (f"`{f['command']}` gives the verdict `{document['verdict']}` and names, in this order: {effects}. Test "
            f"RMSE on X_C {document['test_rmse_before']:.4f} -> {document['test_rmse_after']:.4f} A (RE "
            f"{document['test_re_before']:.2f} -> {document['test_re_after']:.2f} %), against a noise floor of "
            f"{f['noise_floor_A']:.4f} A (`{record['command']}`, the record `discover-twin`: "
            f"{record['seconds']:.0f} s, "
            f"{_where(record)}).\n")


def _readme_more(detection: dict, head_to_head: dict, speed: dict) -> str:
    drifts = {kind: r for kind, r in detection["figures"].items() if kind != "none"}
    seeds = len(next(iter(drifts.values()))["delays_days"])
    total = seeds * len(drifts)
    within = sum(r["within_7_days"] for r in drifts.values())
    right = sum(r["right_first"] for r in drifts.values())
    medians = ", ".join(f"{kind} {r['median_delay_days']:g}" for kind, r in drifts.items()
                        if r.get("median_delay_days") is not None)
    held_out = head_to_head["figures"]["held_out"]
    met = "; ".join(f"{name}: " + ", ".join(f"{what} {_met(ok)}" for what, ok in targets(held_out, name).items()
                                             if ok is not None)
                    for name in ("force, re-levelled", "raw, re-levelled"))
    ratio = speed["figures"]["real_time_ratio"]
    return ("| what | figure | page |\n|---|---|---|\n"
            f"| `greybox monitor` on ageing twin axes, held-out seeds (`{detection['command']}`) | drifts alarmed "
            f"within "
            f"7 days of onset: {within} of {total} ({_met(within == total)}; median days: {medians}); the right "
            f"feature first: {right} of {total} ({_met(right == total)}) ({_where(detection)}) "
            f"| [monitor](docs/monitor.md) |\n"
            f"| teach-in envelopes on twin part series through a warm-up, held-out seeds "
            f"{', '.join(held_out['series'])} and {', '.join(held_out['good'])} (`{head_to_head['command']}`) | "
            f"targets: {met} ({_where(head_to_head)}); "
            f"`greybox process check` at {ratio:.1f} times real time on one core (`{speed['command']}`, "
            f"{_where(speed)}) | [process](docs/process.md) |\n")


def _process_example(record: dict) -> str:
    f = record["figures"]
    part = f["truth_parts"][-1]
    event = f["truth_events"][0]
    warm_up = f["warm_up"]
    passed = [row for row in f["parts"] if not row["flagged"]]
    broken = [row for row in f["stretches"] if row["part"] == event["part"]]
    first = min(row["start_s"] for row in broken) if broken else None
    found = (f"the first stretch of part {event['part']} outside the band starts {first - event['time_s']:+.2f} s "
             f"from the breakage" if first is not None else f"part {event['part']} has no stretch outside the band")
    deviations = [row["deviation"] for row in passed]
    limits = sorted({row["deviation_limit"] for row in passed})
    return (_console(f["teach_lines"] + f["check_lines"])
            + f"\nThe twin's {len(f['parts'])} parts warm up from cold ({100 * warm_up['drop']:.0f} % drop, "
            f"{warm_up['time_constant_s'] / 60:.0f} min time constant): by the end of part {part['part']} the friction "
            f"has fallen by {100 * (1 - part['friction_factor_end']):.1f} % (`friction_factor_end` "
            f"{part['friction_factor_end']:.3f} in `series/X_parts.json`); the tool breaks in part {event['part']} at "
            f"{event['time_s']:g} s. {found[0].upper() + found[1:]}; "
            f"{len(passed)} parts passed with `D` between {min(deviations):.1f} and {max(deviations):.1f} N (limit "
            f"{', '.join(f'{limit:.1f}' for limit in limits)} N). (`{record['command']}`, {_where(record)}.)\n")


def _intervals_example(record: dict) -> str:
    f = record["figures"]
    widths, flagged = [], []
    for name, entry in f["parameters"].items():
        value, lower, upper = entry["value"], entry.get("lower_95"), entry.get("upper_95")
        if entry.get("flag"):
            flagged.append(f"`{name}` ({entry['flag']})")
        elif isinstance(value, (int, float)) and lower is not None and upper is not None and value > 0 and lower > 0:
            widths.append(f"`{name}` {value / lower:.2f} / {upper / value:.2f}")
    return (_console([f"{f['command']}", "...", *f["lines"]])
            + "\nEach determined parameter's interval as the factors value / lower end and upper end / value: "
            + (", ".join(widths) or "none") + ". Flagged: " + ("; ".join(flagged) or "none")
            + f". (`{record['command']}`, {_where(record)}.)\n")


def _friction_models_idim(record: dict) -> str:
    f = record["figures"]
    ours, published = f["models"]["coulomb_idim_ls"], f["published"]["coulomb_idim_ls"]
    keys = (("M_kg", "M", "kg", 2), ("Fv_N_s_per_m", "Fv", "N s/m", 1), ("Fc_N", "Fc", "N", 2),
            ("offset_N", "offset", "N", 2))
    mine = ", ".join(f"{label} = {ours['params'][key]:.{digits}f} {unit}" for key, label, unit, digits in keys)
    theirs = " / ".join(f"{published['params'][key]:.{digits}f}" for key, _, _, digits in keys)
    return (f"On the EMPS benchmark, fitted on the benchmark's decimated observation matrix (its record "
            f"`emps-benchmark`, `{record['command']}`), it gives {mine}, against the published {theirs}.\n")


# -- end of the walk-through (issue 43, h43pages3) --


# -- the pages of h43pages4 (issue 43): process, discover, arts, emps --


def _span(values, digits: int = 2, unit: str = "") -> str:
    """``low-high`` of ``values`` at ``digits`` decimals (one value when they agree there)."""
    low, high = f"{min(values):.{digits}f}", f"{max(values):.{digits}f}"
    return f"{low}{unit}" if low == high else f"{low}-{high}{unit}"


#: The twin's current noise [A] (its default AR(1) noise, which the part series keep).
_TWIN_NOISE_A = CurrentNoise().std_A
#: The per-part error the issue asks of every part's mean cut force [%], and the normal quantile of one part in
#: a hundred outside it (two-sided).
_CUT_FORCE_TARGET, _ONE_IN_A_HUNDRED = 2.0, 2.5758


def _pooling_runs(record: dict) -> list[dict]:
    return record["figures"]["runs"]


def _pooling_label(run: dict) -> str:
    return f"seed {run['seed']} ({run['parts']} {'good ' if run['good_series'] else ''}parts)"


def _process_pooling(record: dict) -> str:
    runs = _pooling_runs(record)
    pooled = sorted((name for name in runs[0] if name.startswith("pooled ")), key=lambda name: int(name.split()[1]))
    names = ["none", "per part", *pooled, "warm-up law", "true friction"]
    lines = ["| beta | " + " | ".join(f"{_pooling_label(run)}: mean / p95 / max abs, signed mean" for run in runs)
             + " |", "|---|" + "---|" * len(runs)]
    for name in names:
        lines.append(f"| {name} | " + " | ".join(f"{run[name]['mean_abs']:.2f} / {run[name]['p95_abs']:.2f} / "
                                                 f"{run[name]['max_abs']:.2f} %, {run[name]['mean']:+.2f} %"
                                                 for run in runs) + " |")
    return ("\n".join(lines) + f"\n\n`{record['command']}` (the model: `{record['figures']['model']}`), "
            f"{record['seconds'] / 60:.1f} min ({_where(record)}).\n")


def _process_pooling_says(record: dict) -> str:
    runs = _pooling_runs(record)
    first, *rest = runs
    pooled = [name for name in first if name.startswith("pooled ")]
    chosen = min(pooled, key=lambda name: first[name]["max_abs"])
    floor_sd = [run["true friction"]["sd"] for run in runs]
    factor_sd = [value for run in runs for value in run["factor_sd_part_to_part"].values()]
    needed_sd = _CUT_FORCE_TARGET / _ONE_IN_A_HUNDRED
    noise = [_TWIN_NOISE_A * needed_sd / sd for sd in floor_sd]
    cut = [(sd / needed_sd) ** 2 for sd in floor_sd]
    lower_p95 = all(run[chosen]["p95_abs"] < run["per part"]["p95_abs"] for run in runs)
    worse = [run for run in rest if run[chosen]["max_abs"] > run["per part"]["max_abs"]]
    seeds = " and ".join(f"{run['max_abs']:.2f} %" for run in (r["warm-up law"] for r in runs))
    floors = " and ".join(f"{run['true friction']['max_abs']:.2f} %" for run in runs)
    per_seed = " and ".join(f"{run['true friction']['max_abs']:.2f} % (seed {run['seed']})" for run in runs)
    reached = any(run["true friction"]["max_abs"] <= _CUT_FORCE_TARGET for run in runs)
    return (
        f"- Per part, the error's spread (sd) is {_span([run['per part']['sd'] for run in runs], unit=' %')} against a "
        f"floor of {_span(floor_sd, unit=' %')} with the true friction: the rest is the noise of the part's own air "
        f"samples in its factor (the factor varies from part to part by a standard deviation of about "
        f"{_span(factor_sd, 3)} around a smooth course).\n"
        f"- Pooling narrows the spread towards the floor: the line over the parts within {chosen.split()[1]} either "
        f"side (`{chosen}`, the smallest largest error on seed {first['seed']}) "
        f"{'brings' if lower_p95 else 'does not bring'} the 95th percentile down on every seed"
        + ("".join(f"; its largest error on seed {run['seed']} ({run[chosen]['max_abs']:.2f} %) is above the per-part "
                   f"one ({run['per part']['max_abs']:.2f} %)" for run in worse))
        + f"; the warm-up law fitted over the series brings the largest error to {seeds}, where the floor's own is "
        f"{floors}.\n"
        f"- **{'Not met, and not reachable on this twin by re-levelling' if not reached else 'Not met'}**: with the "
        f"exact friction the largest error per part is still {per_seed}, the noise of the current (AR(1), "
        f"{_TWIN_NOISE_A} A) averaged over the part's cut. For every part within {_CUT_FORCE_TARGET:.0f} % at "
        f"1-in-100 parts the floor's spread would have to fall from {_span(floor_sd, unit=' %')} to about "
        f"{needed_sd:.2f} % ({_CUT_FORCE_TARGET:.0f} % over {_ONE_IN_A_HUNDRED:.2f} standard deviations): a current "
        f"noise of at most {_span(noise, 3)} A on this program, or {_span(cut, 1)} times as much cut per part at the "
        f"same noise. The mean absolute error per part re-levelled is "
        f"{_span([run['per part']['mean_abs'] for run in runs], unit=' %')}.\n")


def _relevelled(results: dict) -> dict:
    return {name: row for name, row in results["false_alarms"].items() if name.endswith("re-levelled")}


def _process_teach_in(record: dict) -> str:
    development = record["figures"]["development"]
    counts = [series[name]["band_count"] for series in development["series"].values()
              for name in series if name.endswith("re-levelled")]
    seeds = ", ".join(development["series"])
    return (f"On the twin's re-levelled envelopes `M_95` comes out at {_span(counts, 0)} (development seed "
            f"{seeds}, the record `process-head-to-head`).\n")


def _process_head_to_head_says(record: dict) -> str:
    held_out = record["figures"]["held_out"]
    rates = _relevelled(held_out)
    parts = {row["good_parts"] for row in rates.values()}
    flagged = {name: row["false_alarms"] for name, row in rates.items()}
    fitted = [row["band_count"] for row in rates.values()]
    teach_in = [series[name]["band_count"] for series in (*held_out["series"].values(), *held_out["good"].values())
                for name in series if name.endswith("re-levelled")]
    rows = [series[name] for series in held_out["series"].values() for name in series if name.endswith("re-levelled")]
    early = [row["wear_crossing_part"] - row["wear_flagged_part"] for row in rows]
    located = [row["breakage_location_error_s"] for row in rows]
    force = [series["force, re-levelled"]["cut_force_error_pct"] for series in held_out["series"].values()]
    below = all(row["rate_ci"][1] < RATE for row in rates.values())
    safe = max(fitted) < min(teach_in)
    extrapolated = " and ".join(f"{row['rate']:.1e} ({name.split(',')[0]})" for name, row in rates.items())
    return (
        f"- At the band rule of the part maxima, {' and '.join(f'{n} ({name})' for name, n in flagged.items())} of "
        f"the {', '.join(map(str, sorted(parts)))} held-out good parts were flagged by the re-levelled envelopes; "
        f"that many parts bound the counted rate by "
        f"{max(row['counted_ci'][1] for row in rates.values()):.4f} only, and the rate extrapolated from the parts' "
        f"own maxima, {extrapolated} per part, with intervals {'below' if below else 'not all below'} {RATE:g}, is "
        f"what shows {'that' if below else 'whether'} the rule holds its {RATE:g}. The effective count fitted to the "
        f"held-out maxima ({_span(fitted, 0)}) is "
        + ("below every teach-in's upper bound `M_95` of the held-out series "
           f"({_span(teach_in, 0)}): the bound errs on the safe side, as it should." if safe else
           f"within the range of the teach-ins' upper bounds `M_95` of the held-out series ({_span(teach_in, 0)}): "
           "a teach-in's bound is not always on the safe side of the count the checked parts show.")
        + f" With that band the wear is flagged {_span(early, 0)} parts before it reaches +15 % (target: at most 5 "
        f"parts after) and the breakage's stretch starts within {max(located):.2f} s of it (target 0.2 s), by both.\n"
        f"- Each good part's mean cut force (force, re-levelled) is within {_span([f['mean_abs'] for f in force])} % "
        f"on average per seed, the largest {max(f['max_abs'] for f in force):.1f} % "
        f"(target {_CUT_FORCE_TARGET:.0f} % for every part): see the next section for why.\n")


def _process_predict_relevel(record: dict) -> str:
    series = record["figures"]["series"]["warm-up"]
    chunks = ", ".join(f"{row['max_abs_pct']:.2f} % with {chunk} s chunks" for chunk, row in
                       sorted(series["on"].items(), key=lambda item: float(item[0])))
    return (f"Its largest per-part error on the warm-up series ({series['what']}) is {chunks} (the record "
            f"`predict-relevel`, `{record['command']}`).\n")


def _arts_pooling_share(record: dict) -> str:
    files = record["figures"]["files"]
    test = {name: row for name, row in files.items() if row["role"] == "test"}
    slowest = min(row["peak_speed_mm_s"] / row["amplitude_mm"] for row in test.values())
    slow = [name for name, row in test.items() if row["peak_speed_mm_s"] / row["amplitude_mm"] < 1.5 * slowest]
    share = sum(test[name]["samples"] for name in slow) / sum(row["samples"] for row in test.values())
    names = ", ".join(sorted(slow, key=lambda name: int(name[4:-4])))
    return (f"   the {len(slow)} test files at the lowest frequency ({names}) hold "
            f"{100 * share:.0f} % of the test samples, for the same seven periods as every other file (the record "
            f"`arts-benchmark`).\n")


def _discover_emps_asymmetry(record: dict) -> str:
    ours = record["figures"]["models"]["coulomb_asym_idim_ls"]["params"]
    published = record["figures"]["published"]["coulomb_asym_idim_ls"]["params"]

    def difference(params: dict) -> str:
        up, down = params["Fv_pos_N_s_per_m"], params["Fv_neg_N_s_per_m"]
        return f"Fv+ = {up:.1f} and Fv- = {down:.1f} N s/m, a difference of {up - down:.1f} N s/m"

    return (f"   published {difference(published)}; refitted here (the record `emps-benchmark`) "
            f"{difference(ours)}.\n")


def _twin_axes_properties(record: dict) -> str:
    axes = record["figures"]["axes"]
    low, high = record["figures"]["feeds_mm_min"]

    def each(text) -> str:
        return " and ".join(f"{text(row)} ({name})" for name, row in axes.items())

    stiffness = each(lambda row: f"{row['stiffness_A_mm']:.0f} A/mm")
    slowest = each(lambda row: f"{row['sliding_min_feed_mm_min']:.0f}")
    return (f"The total initial stiffness is about {stiffness}: the "
            f"pre-sliding range is a few micrometres. In steady sliding at mid travel the friction is "
            f"{each(lambda r: _span(r['sliding_A'], unit=' A'))} between {low:.0f} and {high:.0f} mm/min: it falls "
            f"from {low:.0f} to about {slowest} mm/min "
            f"(Stribeck) and rises again above (viscous). The position factor g is "
            f"{each(lambda r: _span(r['g_window']))} inside the measurement windows (the lead ripple included); over "
            f"the travel it spans {each(lambda r: _span(r['g_travel']))}. (`{record['command']}`, the record "
            f"`twin-axes`.)\n")


def _twin_axes_ends(record: dict) -> str:
    axes = record["figures"]["axes"]
    ends = " and ".join(f"{_span(row['ends_over_middle'])} times its mid-travel level on {name}"
                        for name, row in axes.items())
    return (f"B and D reach the travel ends, where the Coulomb part of the friction is {ends} (the record "
            f"`twin-axes`).\n")


# -- end of the pages of h43pages4 --


# -- --model auto on the ARTS harmonic tests (issue 40, h40arts2) --
def _auto_arts_speed(record: dict) -> str:
    f = record["figures"]
    re = f["fastest_re"]
    se = re["coulomb_offset_se"]
    spread = f" (SE over the folds {se:.2f})" if se is not None else " (raced out: no SE)"
    return ("| development set | chosen | its RE on the fastest held-out run | `coulomb:offset` there | floor (force "
            "above 20 Hz) | no worse than `coulomb:offset` |\n|---|---|---|---|---|---|\n"
            f"| ARTS harmonic, test1 + test6 + test10 (0.25 Hz) -> {f['fastest']} ({f['fastest_speed']:.0f} mm/s) "
            f"| `{f['chosen']}` | {re['auto']:.2f} % | {re['coulomb_offset']:.2f} %{spread} | {re['floor']:.2f} % "
            f"| {_met(re['auto'] <= re['coulomb_offset'])} |\n\n"
            f"The choice took **{f['auto_seconds']:.0f} s** wall on {f['workers']} workers "
            f"(`{record['command']}`, {_where(record)}).\n")
# -- end of --model auto on the ARTS harmonic tests --


@dataclass(frozen=True)
class View:
    """One rendered stretch: the records it reads, and the function of them that gives its text.

    Attributes
    ----------
    records : tuple of str
        Names of :data:`studies.records.SPECS`, in the order ``render`` takes them.
    render : callable
        ``render(*records) -> str``: the stretch's Markdown, ending in a newline.
    """

    records: tuple
    render: Callable[..., str]


# -- the docs' last typed figures (issue 43, h43docs5) --
def _coarse_block(record: dict) -> str:
    out = ["| development set | `delta` [mm] | `v99 T` [mm per sample] | `m` |", "|---|---|---|---|"]
    for row in record["figures"]["sets"]:
        delta = "none" if row["delta_mm"] is None else f"{row['delta_mm']:.2g}"
        m = f"{row['m']} (nothing changes)" if row["m"] == 1 else f"{row['m']}"
        out.append(f"| {row['set']} | {delta} | {row['travel_per_sample_mm']:.3g} | {m} |")
    return "\n".join(out) + "\n"


def _data_files_arts(record: dict) -> str:
    out = ["| file | amplitude mm | frequency Hz | samples | peak speed mm/s |", "|---|---|---|---|---|"]
    for name, row in sorted(record["figures"]["arts"].items(), key=lambda item: int(item[0][4:])):
        out.append(f"| {name} | {row['amplitude_mm']:.1f} | {row['frequency_hz']:.3g} | {row['samples']} | "
                   f"{row['peak_speed_mm_s']:.0f} |")
    rates = sorted({f"{row['sample_rate_hz']:.0f}" for row in record["figures"]["arts"].values()})
    return "\n".join(out) + f"\n\nAll sampled at {' / '.join(rates)} Hz (the record `data-files`).\n"


def _data_files_emps(record: dict) -> str:
    files = record["figures"]["emps"]
    train, test = files["DATA_EMPS.mat"], files["DATA_EMPS_PULSES.mat"]
    return (f"   Samples (the record `data-files`): the training file keeps {train['samples_1khz']} at 1 kHz after "
            f"steps 1-2 and {train['samples_decimated']} after the decimation by {train['decimation']}; the cross-test "
            f"file {test['samples_1khz']} and {test['samples_decimated']}.\n")


#: The features of a friction fingerprint in the order the monitor page names them.
_FINGERPRINT_ORDER = ("sliding_pos", "sliding_neg", "breakaway_pos", "breakaway_neg", "viscous_pos", "viscous_neg",
                      "noise", "backlash", "periodic_amp", "local_excess")


def _monitor_thresholds(record: dict) -> str:
    variants = record["figures"]["variants"]
    spindle, found = variants["spindle"]["thresholds"], variants["plain"]["thresholds"]
    names = [name for name in _FINGERPRINT_ORDER if name in spindle] + sorted(set(spindle) - set(_FINGERPRINT_ORDER))
    listed = ", ".join(f"{name} {spindle[name]:.2f}" for name in names)
    apart = max(abs(found[name] - spindle[name]) for name in names)
    return (f"with the spindle-load column: {listed}; with `--find-cuts` instead within {apart:.2f} of these "
            f"({min(found.values()):.2f} to {max(found.values()):.2f}) (`{record['command']}`, {_where(record)}).\n")
# -- end of the docs' last typed figures (h43docs5) --


#: The views the pages render, by name.
def _auto_twin_time(record: dict) -> str:
    f = record["figures"]
    out = [label for label, entry in f["candidates"].items() if entry["error"]]
    return (f"`greybox train --model auto --train data/X_A.mcap data/X_B.mcap` took **{f['auto_seconds']:.0f} s** "
            f"wall and {f['auto_cpu_seconds']:.0f} s of CPU time (the run and its workers: "
            f"{f['auto_cpu_seconds'] / f['cores']:.0f} s on {f['cores']} idle cores at best) "
            f"on {f['workers']} workers (target 3 minutes on 2 cores: "
            f"{_met(f['auto_seconds'] <= 180.0 and f['cores'] <= 2)}) and chose `{f['chosen']}`"
            + (f"; out after the lead fold or disqualified: {', '.join(f'`{label}`' for label in out)}" if out else "")
            + f" (`{record['command']}`, {_where(record)}).\n")


def _auto_twin_speed(record: dict) -> str:
    f = record["figures"]
    re = f["fastest_re"]
    return ("| development set | chosen | its RE on the fastest held-out run | `coulomb:offset` there | noise floor | "
            "no worse than `coulomb:offset` |\n|---|---|---|---|---|---|\n"
            f"| twin, X_A + X_B -> {f['fastest']} | `{f['chosen']}` | {re['auto']:.2f} % "
            f"| {re['coulomb_offset']:.2f} % "
            f"| {re['noise_floor']:.2f} % | {_met(re['auto'] <= re['coulomb_offset'])} |\n\n"
            f"`{record['command']}` ({_where(record)}).\n")


def _operating_region(record: dict) -> str:
    f = record["figures"]
    reversals = next(row for row in f["reversal_rule"]["table"]
                     if row["window_s"] == f["reversal_rule"]["chosen"] and row["deadband"] == 1.0)
    lines = ["| trained on | held-out run | outside | by motion | by the grid alone (before the reversals) |",
             "|---|---|---|---|---|"]
    for case, runs in f["cases"].items():
        for name, shares in sorted(runs.items(), key=lambda item: [int(part) if part.isdigit() else part
                                                                   for part in re.split(r"(\d+)", item[0])]):
            lines.append(f"| {case} | {name} | {100 * shares['outside']:.1f} % | {100 * shares['motion']:.1f} % "
                         f"| {100 * shares['grid']:.1f} % |")
    lines += ["", "| reversals: window | deadband (first span edges) | same kind: " +
              " / ".join(reversals["same"]) + " | other kind: " + " / ".join(reversals["other"]) +
              " | stand-in (not used by the rule) |", "|---|---|---|---|---|"]
    for row in f["reversal_rule"]["table"]:
        lines.append(f"| {row['window_s']} s | {row['deadband']:g} | "
                     + " / ".join(f"{100 * v:.2f}" for v in row["same"].values()) + " % | "
                     + " / ".join(f"{100 * v:.1f}" for v in row["other"].values())
                     + f" % | {100 * row['stand_in']:.1f} % |")
    arts = next(runs for case, runs in f["cases"].items() if case.startswith("ARTS"))
    made_up = {name: shares["outside"] for name, shares in arts.items() if name.startswith("small oscillations")}
    caught = [name for name, share in made_up.items() if share > f["stand_in"]["limit"]]
    missed = [name for name in made_up if name not in caught]
    stand_in, held_out = f["stand_in"], f["held_out"]
    same = ", ".join(f"{name} {100 * share:.2f} %" for name, share in reversals["same"].items())
    other = ", ".join(f"{name} {100 * share:.1f} %" for name, share in reversals["other"].items())
    return ("\n".join(lines) + "\n\n"
            f"Held-out air cuts of the same kind flagged by motion (window {f['reversal_rule']['chosen']} s): {same} "
            f"(target at most {100 * held_out['limit']:.0f} % each: {_met(held_out['met'])}); of another kind: "
            f"{other}. The stand-in of issue 40 point 4 ({stand_in['name']}): {100 * stand_in['outside']:.1f} % "
            f"outside ({100 * stand_in['grid']:.1f} % by the grid alone; target more than "
            f"{100 * stand_in['limit']:.0f} %: {_met(stand_in['met'])}). Made-up oscillations more than "
            f"{100 * stand_in['limit']:.0f} % outside: {', '.join(caught) or 'none'}; "
            f"not: {', '.join(missed) or 'none'}. "
            f"`{record['command']}` ({_where(record)}).\n")


# -- issue 40's axis_dev targets (h40axisdev) --
def _axis_dev_force(record: dict) -> str:
    f = record["figures"]
    fit = f["gmssvr"]
    force = fit["cut_force"]
    lines = [f"`greybox train --model gmssvr --train aircut_A.csv aircut_B.csv aircut_C.csv` took "
             f"**{fit['seconds']:.0f} s** wall ({fit['cpu_seconds']:.0f} s of CPU time); `greybox predict` of "
             f"`cut_D.csv` with `axis.toml`: mean process force **{force['predicted_N']:.1f} N** where "
             f"`F_cut_true_N != 0` ({force['samples']} samples) against the truth's {force['truth_N']:.1f} N, "
             f"**{force['error_percent']:+.2f} %** (target within 1 %: {_met(abs(force['error_percent']) <= 1.0)}).",
             "",
             "| GMS trained on | fit time | RMSE there [A] | RMSE on the other air cuts [A] | over its own | "
             "within 3 times or refused |",
             "|---|---|---|---|---|---|"]
    for single in f["single"]:
        if single["refused"] is not None:
            lines.append(f"| `{single['trained_on']}` | {single['seconds']:.0f} s | - | - | - | refused: "
                         f"`{single['refused']}` |")
            continue
        own = single["rmse"][single["trained_on"]]
        others = ", ".join(f"{cut} {single['rmse'][cut]:.3f}" for cut in single["ratio"])
        ratios = ", ".join(f"{value:.2f}" for value in single["ratio"].values())
        lines.append(f"| `{single['trained_on']}` | {single['seconds']:.0f} s | {own:.3f} | {others} | {ratios} | "
                     f"{_met(max(single['ratio'].values()) <= 3.0)} |")
    return "\n".join(lines) + f"\n\n`{record['command']}` ({_where(record)}).\n"


def _axis_dev_speed(record: dict) -> str:
    f = record["figures"]
    re = f["fastest_re"]
    force = f["cut_force"]
    floor = ("not known: the files hold no noise-free current" if re["noise_floor"] is None
             else f"{re['noise_floor']:.2f} %")
    return ("| development set | chosen | its RE on the fastest held-out run | `coulomb:offset` there | noise floor | "
            "no worse than `coulomb:offset` |\n|---|---|---|---|---|---|\n"
            f"| `axis_dev`, {' + '.join(cut.removeprefix('aircut_') for cut in f['trained_on'])} -> "
            f"{f['fastest'].removeprefix('aircut_')} | `{f['chosen']}` | {re['auto']:.2f} % "
            f"| {re['coulomb_offset']:.2f} % "
            f"| {floor} "
            f"| {_met(re['auto'] <= re['coulomb_offset'])} |\n\n"
            f"`greybox train --model auto --train {' '.join(cut + '.csv' for cut in f['trained_on'])}` took "
            f"{f['auto_seconds']:.0f} s wall ({f['auto_cpu_seconds']:.0f} s of CPU time); the choice's mean process "
            f"force on `cut_D` is {force['predicted_N']:.1f} N against the truth's {force['truth_N']:.1f} N "
            f"({force['error_percent']:+.2f} %). `{record['command']}` ({_where(record)}).\n")
# -- end of issue 40's axis_dev targets (h40axisdev) --


# -- the example of monitor.md (issue 43, lead) --
#: Log lines of ``greybox monitor`` the page shows before the summary (one per log follows in the run).
_MONITOR_LOG_LINES = 2


def _monitor_example(record: dict) -> str:
    f = record["figures"]
    lines = f["monitor_lines"]
    summary = next(i for i, line in enumerate(lines) if " logs fingerprinted, " in line)
    shown = [f"$ {f['synth_command']}", "$ greybox monitor logs/*.mcap --history history/ --out report/",
             *lines[:_MONITOR_LOG_LINES], "...", *lines[summary:]]
    low, high = f["backlash_before_onset_um"]
    return (_console(shown) + f"\n(the drift's onset, day {f['onset_day']}, is {f['onset_date']}; over the "
            f"{f['days_before_onset']} days before it the backlash width, the pre-sliding distance to half the "
            f"level, came out {low:.2f} to {high:.2f} um; the dashboard `report/index.html` is "
            f"{f['dashboard_mb']:.1f} MB with its plotly.js inline; `{record['command']}`, {_where(record)}.)\n")


def _find_cuts_tolerance(record: dict) -> str:
    f = record["figures"]
    days = f["days"]
    late_defect = [d for d in days if d["kind"] == "local_defect" and d["after_onset"]]
    others = [d for d in days if d not in late_defect]

    def kept(group, tolerance):
        ratios = [100.0 * (d["kept"][tolerance] / d["spindle_kept"] - 1.0) for d in group]
        return f"{min(ratios):+.1f} to {max(ratios):+.1f} %"

    lines = [f"| `tolerance` | cutting samples kept ({len(days)} days) | samples kept against the spindle-load "
             f"column: {len(others)} days | the same: the defect machine's {len(late_defect)} days after its "
             f"onset |", "|---|---|---|---|"]
    for tolerance in map(str, f["tolerances"]):
        default = " (default)" if float(tolerance) == f["default"] else ""
        lines.append(f"| {tolerance}{default} | {sum(d['cutting_kept'][tolerance] for d in days)} "
                     f"| {kept(others, tolerance)} | {kept(late_defect, tolerance)} |")
    twin = f["twin_air_days"]
    share = ", ".join(f"day {d['day']} of seed {d['seed']} {d['kept_percent']:.1f} %" for d in twin)
    return ("\n".join(lines) + f"\n\nCutting: spindle load above {f['cutting_load_pct']:.0f} %; every "
            f"{f['every_days']}th day of each machine. On the twin's air-move days, the moving samples kept at the "
            f"default: {share}. `{record['command']}` ({_where(record)}).\n")


def _monitor_shapes(record: dict) -> str:
    f = record["figures"]
    shapes, tail = f["shapes"], f["tail_sd"]
    excess, backlash = shapes["local_excess"], shapes["backlash"]
    others = [stats["skewness"] for name, stats in shapes.items() if name not in ("local_excess", "backlash")]
    widest = max(abs(value) for value in others)
    return (f"Read from the shipped quantiles: the local excess (the largest rise along the travel) is skewed to "
            f"high values (skewness {excess['skewness']:+.2f}; {excess['above_percent']:.1f} % of its days beyond "
            f"+{tail} standard deviations, {excess['below_percent']:.2f} % below -{tail}; a normal day 0.6 % each), "
            f"the backlash width a little ({backlash['skewness']:+.2f}); every other feature is within "
            f"+-{widest:.2f} of a normal skewness (`{record['command']}`, {_where(record)}).\n")


def _monitor_calibrated(record: dict) -> str:
    h = record["figures"]["thresholds"]
    return (f"With 28 baseline days on the twin's shapes, h = {h['twin_28_days_0.5']:.2f} for 0.5 false alarms per "
            f"axis-year ({h['twin_28_days_1']:.2f} for 1; {h['twin_14_days_0.5']:.2f} with 14 baseline days); on "
            f"normal days, {h['normal_28_days_1']:.2f} for 1 per axis-year (`{record['command']}`, "
            f"{_where(record)}).\n")
# -- end of the example of monitor.md --

VIEWS = {
    "reproduce-run": View(("reproduce",), _reproduce_run),
    "reproduce-exp1": View(("reproduce",), _reproduce_exp(1)),
    "reproduce-exp2": View(("reproduce",), _reproduce_exp(2)),
    "reproduce-exp2-per-log": View(("reproduce",), _reproduce_per_log),
    "reproduce-pattern": View(("reproduce",), _reproduce_table(paper_pattern_table)),
    "reproduce-sole-svr": View(("reproduce",), _reproduce_table(sole_svr_table)),
    "reproduce-noise-floor": View(("reproduce",), _reproduce_table(noise_floor_table)),
    "reproduce-svr-generalisation": View(("reproduce",), _reproduce_table(svr_generalisation_table)),
    "reproduce-hyperparameters": View(("reproduce",), _reproduce_table(hyperparameter_table, "hyperparameters")),
    "reproduce-summary": View(("reproduce",), _reproduce_summary),
    "default-tests-run": View(("default-tests",), _tests_run),
    "monitor-independent": View(("monitor-independent",), _monitor_independent),
    "predict-hour": View(("predict-hour",), _predict_hour),
    "live-speed": View(("live-speed",), _live_speed),
    "readme-measured": View(("reproduce", "default-tests", "monitor-independent"), _readme_table),
    "live-cut-force": View(("live-low-latency",), _live_cut_force),
    "live-low-latency": View(("live-low-latency",), _live_low_latency),
    "process-head-to-head": View(("process-head-to-head",), _process_head_to_head("held_out")),
    "process-head-to-head-development": View(("process-head-to-head",), _process_head_to_head("development")),
    # -- the real-data benchmarks and speed (issue 43) --
    "emps-benchmark": View(("emps-benchmark",), _emps_benchmark),
    "emps-targets": View(("emps-benchmark",), _emps_targets),
    "arts-benchmark": View(("arts-benchmark",), _arts_benchmark),
    "arts-targets": View(("arts-benchmark",), _arts_targets),
    "arts-band-budget": View(("arts-benchmark",), _arts_band_budget),
    "emps-summary": View(("emps-benchmark",), _emps_summary),
    "arts-summary": View(("arts-benchmark",), _arts_summary),
    "readme-real-data": View(("emps-benchmark",), _readme_real_data),
    "gms-kernel": View(("gms-speed",), _gms_kernel),
    "speed-table": View(("gms-speed", "svr-predict", "read-hour"), _speed_table),
    # -- end of the real-data benchmarks and speed (issue 43) --
    "auto-twin-time": View(("auto-twin",), _auto_twin_time),
    "auto-twin-speed": View(("auto-twin",), _auto_twin_speed),
    # -- the pages of h43pages1 (issue 43): compensate, validation, discover --
    "compensate-twin": View(("compensate-twin",), _compensate_tables),
    "compensate-summary": View(("compensate-twin",), _compensate_summary),
    "intervals-cost": View(("intervals-cost",), _intervals_cost),
    "discover-emps": View(("discover-emps",), _discover_emps),
    "discover-emps-summary": View(("discover-emps",), _discover_emps_summary),
    # -- end of the pages of h43pages1 --
    "process-speed": View(("process-speed",), _process_speed),
    # -- the predict and monitor pages (issue 43) --
    "cutting-validation-detail": View(("cutting-validation",), _cutting_detail),
    "cutting-validation-sweep": View(("cutting-validation",), _cutting_sweep),
    "monitor-detection": View(("monitor-detection",), _monitor_detection),
    "monitor-fleet": View(("monitor-fleet",), _monitor_fleet),
    "monitor-query": View(("monitor-query",), _monitor_query),
    "predict-relevel": View(("predict-relevel",), _predict_relevel),
    # -- end of the predict and monitor pages (issue 43) --
    # -- the walk-through of usage.md and predict.md, the log formats' reading speed (issue 43, h43pages3) --
    "walkthrough-predict": View(("walkthrough",), _walkthrough_predict),
    "walkthrough-table": View(("walkthrough",), _walkthrough_table),
    "walkthrough-row": View(("walkthrough",), _walkthrough_row),
    "walkthrough-cut": View(("walkthrough",), _walkthrough_cut),
    "walkthrough-interval": View(("walkthrough",), _walkthrough_interval),
    "walkthrough-outside": View(("walkthrough",), _walkthrough_outside),
    "walkthrough-stribeck": View(("walkthrough",), _walkthrough_stribeck),
    "log-formats-read-speed": View(("predict-hour",), _log_formats_read_speed),
    "discover-twin": View(("discover-twin",), _discover_twin),
    "process-example": View(("process-example",), _process_example),
    "intervals-example": View(("intervals-example",), _intervals_example),
    "friction-models-idim": View(("emps-benchmark",), _friction_models_idim),
    "readme-more": View(("monitor-detection", "process-head-to-head", "process-speed"), _readme_more),
    # -- end of the walk-through (issue 43, h43pages3) --
    # -- the pages of h43pages4 (issue 43): process, discover, arts, emps --
    "process-pooling": View(("process-pooling",), _process_pooling),
    "process-pooling-says": View(("process-pooling",), _process_pooling_says),
    "process-teach-in": View(("process-head-to-head",), _process_teach_in),
    "process-head-to-head-says": View(("process-head-to-head",), _process_head_to_head_says),
    "process-predict-relevel": View(("predict-relevel",), _process_predict_relevel),
    "arts-pooling-share": View(("arts-benchmark",), _arts_pooling_share),
    "discover-emps-asymmetry": View(("emps-benchmark",), _discover_emps_asymmetry),
    "twin-axes-properties": View(("twin-axes",), _twin_axes_properties),
    "twin-axes-ends": View(("twin-axes",), _twin_axes_ends),
    # -- end of the pages of h43pages4 --
    # -- the training region (issue 40, h40region) --
    "operating-region": View(("operating-region",), _operating_region),
    # -- end of the training region (issue 40, h40region) --
    # -- issue 40's axis_dev targets (h40axisdev) --
    "axis-dev-force": View(("axis-dev",), _axis_dev_force),
    "axis-dev-speed": View(("axis-dev-speed",), _axis_dev_speed),
    # -- end of issue 40's axis_dev targets (h40axisdev) --
    # -- --model auto on the ARTS harmonic tests (issue 40, h40arts2) --
    "auto-arts-speed": View(("auto-arts",), _auto_arts_speed),
    # -- end of --model auto on the ARTS harmonic tests --
    # -- the docs' last typed figures (issue 43, h43docs5) --
    "coarse-block": View(("coarse-block",), _coarse_block),
    "data-files-arts": View(("data-files",), _data_files_arts),
    "data-files-emps": View(("data-files",), _data_files_emps),
    "monitor-thresholds": View(("monitor-independent",), _monitor_thresholds),
    # -- end of the docs' last typed figures (h43docs5) --
    # -- the example of monitor.md (issue 43, lead) --
    "monitor-example": View(("monitor-example",), _monitor_example),
    "find-cuts-tolerance": View(("find-cuts-tolerance",), _find_cuts_tolerance),
    "monitor-shapes": View(("monitor-calibration",), _monitor_shapes),
    "monitor-calibrated": View(("monitor-calibration",), _monitor_calibrated),
    # -- end of the example of monitor.md --
}


def render_text(text: str, *, read: Callable[[str], dict] = read_record, where: str = "page",
                keep: tuple = ()) -> str:
    """``text`` with every marked stretch rendered anew from its record.

    Parameters
    ----------
    text : str
        A page.
    read : callable, default :func:`studies.records.read_record`
        Record name -> record.
    where : str, default "page"
        The page's name, for the error message.
    keep : tuple of str, default ()
        Records being re-made: the stretches that read them are left as they stand.

    Returns
    -------
    str

    Raises
    ------
    GreyboxError
        Naming the page, for a view that does not exist or a record that has not been made.
    """
    records = {}

    def render(match: re.Match) -> str:
        view = VIEWS.get(match["view"])
        if view is None:
            raise GreyboxError(f"{where}: no view {match['view']!r}; views: {', '.join(VIEWS)}")
        if set(view.records) & set(keep):
            return match[0]
        for name in view.records:
            if name not in records:
                records[name] = read(name)
        return match["open"] + view.render(*(records[name] for name in view.records)) + match["close"]

    return BLOCK.sub(render, text)


def cited_records(text: str) -> set[str]:
    """The names of the records a page renders.

    Parameters
    ----------
    text : str
        A page.

    Returns
    -------
    set of str
    """
    return {name for match in BLOCK.finditer(text) if match["view"] in VIEWS for name in VIEWS[match["view"]].records}


def render_pages(pages=PAGES, *, check: bool = False, keep: tuple = ()) -> list[Path]:
    """Render every page's marked stretches from the records, writing the pages that change.

    Parameters
    ----------
    pages : sequence of path-like, default :data:`PAGES`
        The pages.
    check : bool, default False
        Only report the pages that would change; write nothing.
    keep : tuple of str, default ()
        Records whose stretches are left as they stand (not made yet).

    Returns
    -------
    list of pathlib.Path
        The pages that changed (or would change).
    """
    changed = []
    for page in map(Path, pages):
        text = page.read_text(encoding="utf-8")
        rendered = render_text(text, where=str(page.relative_to(ROOT)), keep=keep)
        if rendered != text:
            changed.append(page)
            if not check:
                write_text_atomic(page, rendered)
    return changed
