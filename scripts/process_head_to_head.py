"""Head to head of teach-in envelopes on the twin's part series through a warm-up: raw current against force.

Runs :mod:`studies.process_head_to_head` on development and held-out seeds, prints one table per set and the
false-alarm rate of every variant on its good parts. The model is trained once on the cold machine's shipped
air cuts (``greybox train --model gms --train data/X_A.mcap data/X_C.mcap``; without ``--model`` the script
trains it into a temporary directory):

    python scripts/process_head_to_head.py --json -
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.process_head_to_head import (  # noqa: E402
    GOOD_PARTS,
    RATE,
    false_alarm_table,
    head_to_head,
    head_to_head_table,
)

ROOT = Path(__file__).resolve().parents[1]
#: Seeds the settings were looked at on, and the held-out seeds the figures are reported on.
DEVELOPMENT, HELD_OUT = (101,), (201, 202, 203)
#: Development and held-out seeds of the series of good parts that measure the false-alarm rate.
DEVELOPMENT_GOOD, HELD_OUT_GOOD = (111,), (211, 212, 213, 214)
#: How the model is trained.
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "data/X_C.mcap")


def _train(out: Path) -> str:
    model = out / "gms_x.gbm"
    subprocess.run([str(Path(sys.executable).with_name("greybox")), *TRAIN, "--out", str(model)], cwd=ROOT,
                   check=True, stdout=subprocess.DEVNULL)
    return str(model)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", help="GMS model file trained on data/X_A.mcap data/X_C.mcap (default: train it)")
    parser.add_argument("--axis-config", default=str(ROOT / "examples" / "axis_x.toml"))
    parser.add_argument("--seeds", type=int, nargs="+", help="run only these seeds (default development and "
                        "held-out)")
    parser.add_argument("--only", choices=("development", "held_out"), help="run only this set of seeds")
    parser.add_argument("--json", help="write the figures per seed and variant to this file, '-': print them last")
    args = parser.parse_args(argv)
    sets = ({"given": (tuple(args.seeds), ())} if args.seeds else
            {"development": (DEVELOPMENT, DEVELOPMENT_GOOD), "held_out": (HELD_OUT, HELD_OUT_GOOD)})
    if args.only:
        sets = {args.only: sets[args.only]}
    everything = {"model": "greybox " + " ".join(TRAIN), "rate": RATE, "good_parts_per_series": GOOD_PARTS}
    with tempfile.TemporaryDirectory() as scratch:
        model = args.model or _train(Path(scratch))
        for label, (seeds, good) in sets.items():
            results = head_to_head(seeds, model, args.axis_config, good_seeds=good,
                                   progress=lambda line: print(line, flush=True))
            everything[label] = results
            print(f"\n{label} seeds {', '.join(map(str, seeds))}, false-alarm rate {RATE:g} per part for every "
                  f"variant\n")
            print(head_to_head_table(results["series"]))
            print(f"false alarms of the good parts ({label}, series {', '.join(map(str, (*seeds, *good)))}):\n")
            print(false_alarm_table(results["false_alarms"]))
    text = json.dumps(everything, indent=1)
    if args.json == "-":
        print(text)
    elif args.json:
        Path(args.json).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
