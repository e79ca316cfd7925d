"""Head to head of teach-in envelopes on the twin's part series through a warm-up: raw current against force.

Runs :mod:`studies.process_head_to_head` on development and held-out seeds and prints one table per set.
The model is trained once on the cold machine's shipped air cuts:

    greybox train --model gms --train data/X_A.mcap data/X_C.mcap --out gms_x.gbm
    python scripts/process_head_to_head.py --model gms_x.gbm --json head_to_head.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.process_head_to_head import RATE, VARIANTS, head_to_head  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: Seeds the settings were looked at on, and the held-out seeds the figures are reported on.
DEVELOPMENT, HELD_OUT = (101,), (201, 202, 203)


def _table(results: dict) -> str:
    lines = ["| variant | false alarms / good parts | missing blank | oversized blank | wear flagged at part "
             "(+15 % at) | breakage flagged, located within | mean cut force error (mean / max abs) |",
             "|---|---|---|---|---|---|---|"]
    for name in VARIANTS:
        rows = [results[seed][name] for seed in results]
        alarms = sum(r["false_alarms"] for r in rows)
        total = sum(r["good_parts"] for r in rows)
        wear = ", ".join(f"{r['wear_flagged_part']} ({r['wear_crossing_part']})" for r in rows)
        located = ", ".join("miss" if not r["breakage_flagged"] else
                            (f"{r['breakage_location_error_s']:.2f} s" if r["breakage_location_error_s"] is not None
                             else "flagged, no stretch") for r in rows)
        force = ", ".join(f"{r['cut_force_error_pct']['mean_abs']:.2f} / {r['cut_force_error_pct']['max_abs']:.2f} %"
                          for r in rows if "cut_force_error_pct" in r) or "-"
        lines.append(f"| {name} | {alarms} / {total} | {sum(r['missing_blank'] for r in rows)} / {len(rows)} | "
                     f"{sum(r['oversized_blank'] for r in rows)} / {len(rows)} | {wear} | {located} | {force} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", required=True, help="GMS model file trained on data/X_A.mcap data/X_C.mcap")
    parser.add_argument("--axis-config", default=str(ROOT / "examples" / "axis_x.toml"))
    parser.add_argument("--seeds", type=int, nargs="+", help="run only these seeds (default development and "
                        "held-out)")
    parser.add_argument("--json", type=Path, help="write the figures per seed and variant")
    args = parser.parse_args(argv)
    sets = {"given": tuple(args.seeds)} if args.seeds else {"development": DEVELOPMENT, "held-out": HELD_OUT}
    everything = {}
    for label, seeds in sets.items():
        results = head_to_head(seeds, args.model, args.axis_config, progress=lambda line: print(line, flush=True))
        everything[label] = results
        print(f"\n{label} seeds {', '.join(map(str, seeds))}, false-alarm rate {RATE:g} per part for every variant\n")
        print(_table(results))
    if args.json:
        args.json.write_text(json.dumps(everything, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
