"""Draw the pages' pictures that are drawn from a measured record, not from a new run.

``docs/figures/cut-correlation-vs-force.png`` (docs/predict.md) is the correlation of recovered and true
process current against the mean cut force, drawn from the record ``cutting-validation``
(``docs/results/cutting-validation.json``): each model's correlations at the swept strengths come from the
record; the perfect model's curve and the mean cut forces are recomputed from the twin's cutting logs of the
record's seed (deterministic, a few seconds).

Usage::

    python scripts/record_figures.py [--out docs/figures]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.errors import GreyboxError
from studies.cutting import TEST_DATASETS, CuttingCase, plot_correlation_vs_force
from studies.records import ROOT, read_record


def cut_correlation_figure(out: Path) -> Path:
    """Draw ``out / cut-correlation-vs-force.png`` from the record ``cutting-validation``; its path."""
    figures = read_record("cutting-validation")["figures"]
    cases = {case.name: case for case in (CuttingCase(dataset, figures["seed"], figures["strengths_A"], ROOT / "data")
                                          for dataset in TEST_DATASETS)}
    recorded = {case["name"] for case in figures["cases"]}
    if recorded != set(cases):
        raise GreyboxError(f"record cutting-validation holds the logs {sorted(recorded)}, not {sorted(cases)}")
    return plot_correlation_vs_force(figures["rows"], cases, figures["force_constant_N_per_A"], figures["target"],
                                     out / "cut-correlation-vs-force.png")


#: The pictures drawn from a record, by the record's name: ``scripts/record.py`` redraws them after measuring it.
DRAWN_FROM = {"cutting-validation": cut_correlation_figure}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures", help="folder of the pictures")
    args = parser.parse_args(argv)
    try:
        print(f"wrote {cut_correlation_figure(args.out)}")
    except GreyboxError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
