"""Does a reproduction show the pattern of the paper's Tables 3 and 4?

The synthetic axes cannot give the paper's numbers (another machine), but
they should behave like it. :func:`paper_pattern` checks, on the metric
records of ``greybox reproduce``, the relations the paper's real axes show:

* Table 3 (train A, test C): Stribeck, the sole SVR and GMS within 30 % of each
  other in test RE on each axis, their test RMSE in the paper's range
  (0.08-0.16 A);
* Table 4 (train A + B, test C + D): the sole SVR's test RE at least three
  times its training RE (the paper's overfitting), GMS+SVR the lowest test RE
  of the paper's four models (Stribeck, SVR, GMS, GMS+SVR; variants such as
  ``gmssvr_eq8`` are not compared) on each axis, and the position effect larger on Y than on X (test RE of
  Stribeck and of GMS on Y at least 1.8 times that on X).

Each check is computed the same way on the paper's figures
(:mod:`greybox.evaluate.paper`) and on ours.
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

from .paper import PAPER_RE, PAPER_TEST_RMSE, PAPER_TRAIN_RE
from .table import Table

__all__ = ["PATTERN_LIMITS", "paper_pattern", "paper_pattern_table"]

#: The limits of the checks: RE spread of the static, SVR and GMS models on C, the RMSE range [A],
#: the SVR's test over training RE, the Y over X ratio of the position-blind models.
PATTERN_LIMITS = {"spread": 1.3, "rmse_range_A": (0.08, 0.16), "svr_overfit": 3.0, "position_y_over_x": 1.8}

_TABLE3_MODELS = ("stribeck", "svr", "gms")
_TABLE4_MODELS = ("stribeck", "svr", "gms", "gmssvr")


def _lookup(records: Iterable[Mapping]) -> dict[str, dict]:
    """``{"re" | "train_re" | "rmse": {(experiment, axis, model): value}}`` of the records."""
    values: dict[str, dict] = {"re": {}, "train_re": {}, "rmse": {}}
    for record in records:
        key = (record.get("experiment"), record.get("axis"), record.get("model"))
        if record.get("dataset") == "test":
            values["re"][key], values["rmse"][key] = record["re"], record["rmse"]
        elif record.get("dataset") == "train":
            values["train_re"][key] = record["re"]
    return values


def _checks(values: Mapping[str, Mapping], axes: Sequence[str]) -> list[dict]:
    """Every check that ``values`` (see :func:`_lookup`) hold the figures for: name, axis, value, met."""
    re, train, rmse = values["re"], values["train_re"], values["rmse"]
    low, high = PATTERN_LIMITS["rmse_range_A"]
    out = []
    for axis in axes:
        table3 = [(1, axis, m) for m in _TABLE3_MODELS]
        if all(k in re for k in table3):
            spread = max(re[k] for k in table3) / min(re[k] for k in table3)
            out.append({"check": "Table 3: test RE of Stribeck, SVR, GMS, largest / smallest", "axis": axis,
                        "value": f"{spread:.2f}", "target": f"<= {PATTERN_LIMITS['spread']:g}",
                        "met": spread <= PATTERN_LIMITS["spread"]})
        if all(k in rmse for k in table3):
            errors = [rmse[k] for k in table3]
            out.append({"check": "Table 3: test RMSE of Stribeck, SVR, GMS [A]", "axis": axis,
                        "value": f"{min(errors):.3f}-{max(errors):.3f}", "target": f"{low:g}-{high:g}",
                        "met": low <= min(errors) and max(errors) <= high})
        key = (2, axis, "svr")
        if key in re and train.get(key):
            ratio = re[key] / train[key]
            out.append({"check": "Table 4: SVR test RE / training RE", "axis": axis, "value": f"{ratio:.2f}",
                        "target": f">= {PATTERN_LIMITS['svr_overfit']:g}",
                        "met": ratio >= PATTERN_LIMITS["svr_overfit"]})
        table4 = [(2, axis, m) for m in _TABLE4_MODELS]
        if all(k in re for k in table4):
            best = min(table4, key=lambda k: re[k])[2]
            out.append({"check": "Table 4: lowest test RE", "axis": axis, "value": best, "target": "gmssvr",
                        "met": best == "gmssvr"})
    if "X" in axes and "Y" in axes:
        for model in ("stribeck", "gms"):
            x, y = (2, "X", model), (2, "Y", model)
            if x in re and y in re and re[x] > 0:
                ratio = re[y] / re[x]
                out.append({"check": f"Table 4: {model} test RE, Y / X (position effect)", "axis": "X, Y",
                            "value": f"{ratio:.2f}", "target": f">= {PATTERN_LIMITS['position_y_over_x']:g}",
                            "met": ratio >= PATTERN_LIMITS["position_y_over_x"]})
    return out


def paper_pattern(records: Sequence[Mapping]) -> list[dict]:
    """The pattern checks on ``records`` beside the same checks on the paper's figures.

    Parameters
    ----------
    records : sequence of dict
        Metric records of experiments 1 and 2 (see :mod:`greybox.evaluate.report`).

    Returns
    -------
    list of dict
        ``check``, ``axis``, ``paper`` (the paper's value), ``ours``,
        ``target`` and ``met`` (bool, ours), for every check the records hold
        the figures for.
    """
    axes = sorted({r.get("axis") for r in records if r.get("axis") in ("X", "Y")})
    paper = {"re": PAPER_RE, "train_re": PAPER_TRAIN_RE, "rmse": PAPER_TEST_RMSE}
    published = {(c["check"], c["axis"]): c["value"] for c in _checks(paper, axes)}
    return [{"check": c["check"], "axis": c["axis"], "paper": published.get((c["check"], c["axis"]), "–"),
             "ours": c["value"], "target": c["target"], "met": c["met"]} for c in _checks(_lookup(records), axes)]


def paper_pattern_table(records: Sequence[Mapping]) -> Table:
    """:func:`paper_pattern` as a table.

    Parameters
    ----------
    records : sequence of dict
        Metric records of experiments 1 and 2, as for :func:`paper_pattern`.
    """
    rows = [[c["check"], c["axis"], c["paper"], c["ours"], c["target"], "yes" if c["met"] else "no"]
            for c in paper_pattern(records)]
    notes = ["The synthetic axes are calibrated to behave like the paper's machine, not to give its numbers; "
             "each check is computed in the same way on the paper's Tables 3 and 4 and on our records."]
    return Table("The paper's pattern on the synthetic axes", ["check", "axis", "paper", "greybox", "target",
                                                                "met"], rows, notes)
