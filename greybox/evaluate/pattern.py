"""Does a reproduction show the pattern of the paper's Tables 3 and 4?

The synthetic axes cannot give the paper's numbers (another machine), but
they should behave like it. :func:`paper_pattern` checks, on the metric
records of ``greybox reproduce``, the relations the paper's real axes show
in Table 4 (train A + B, test C + D):

* GMS+SVR has the lowest test RE of the paper's four models (Stribeck, SVR,
  GMS, GMS+SVR; variants such as ``gmssvr_eq8`` are not compared) on each axis;
* the position effect is larger on Y than on X: the test RE of Stribeck and of
  GMS on Y is at least 1.8 times that on X.

The sole SVR is shown beside the paper's figures without a target
(:func:`sole_svr_beside_paper`): its test RE and RMSE in Table 3 and its test
over training RE in Table 4 (the paper's overfitting). They depend on how the
paper trained its SVR, which it does not describe in enough detail to copy, so
they are not a check of greybox.

Each figure is computed the same way on the paper's figures
(:mod:`greybox.evaluate.paper`) and on ours.
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

from .paper import PAPER_RE, PAPER_TEST_RMSE, PAPER_TRAIN_RE
from .table import Table

__all__ = ["PATTERN_LIMITS", "paper_pattern", "paper_pattern_table", "sole_svr_beside_paper", "sole_svr_table"]

#: The limit of the checks: the Y over X ratio of the test RE of the position-blind models.
PATTERN_LIMITS = {"position_y_over_x": 1.8}

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
    re = values["re"]
    out = []
    for axis in axes:
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


def _sole_svr(values: Mapping[str, Mapping], axes: Sequence[str]) -> list[dict]:
    """The sole SVR's figures that ``values`` (see :func:`_lookup`) hold: name, axis, value."""
    re, train, rmse = values["re"], values["train_re"], values["rmse"]
    out = []
    for axis in axes:
        key = (1, axis, "svr")
        if key in re:
            out.append({"figure": "Table 3: sole SVR test RE [%]", "axis": axis, "value": f"{re[key]:.2f}"})
        if key in rmse:
            out.append({"figure": "Table 3: sole SVR test RMSE [A]", "axis": axis, "value": f"{rmse[key]:.3f}"})
        key = (2, axis, "svr")
        if key in re and train.get(key):
            out.append({"figure": "Table 4: sole SVR test RE / training RE", "axis": axis,
                        "value": f"{re[key] / train[key]:.2f}"})
    return out


def _paper_values() -> dict[str, dict]:
    """The paper's Tables 3 and 4 in the layout of :func:`_lookup`."""
    return {"re": PAPER_RE, "train_re": PAPER_TRAIN_RE, "rmse": PAPER_TEST_RMSE}


def _axes(records: Sequence[Mapping]) -> list[str]:
    """The paper's axes (X, Y) that ``records`` hold."""
    return sorted({r.get("axis") for r in records if r.get("axis") in ("X", "Y")})


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
    axes = _axes(records)
    published = {(c["check"], c["axis"]): c["value"] for c in _checks(_paper_values(), axes)}
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


def sole_svr_beside_paper(records: Sequence[Mapping]) -> list[dict]:
    """The sole SVR's figures beside the paper's, without a target: the paper's SVR training is not disclosed.

    Parameters
    ----------
    records : sequence of dict
        Metric records of experiments 1 and 2, as for :func:`paper_pattern`.

    Returns
    -------
    list of dict
        ``figure``, ``axis``, ``paper`` (the paper's value) and ``ours``, for
        every figure the records hold: the test RE [%] and RMSE [A] of
        experiment 1, the test over training RE of experiment 2.
    """
    axes = _axes(records)
    published = {(f["figure"], f["axis"]): f["value"] for f in _sole_svr(_paper_values(), axes)}
    return [{"figure": f["figure"], "axis": f["axis"], "paper": published.get((f["figure"], f["axis"]), "–"),
             "ours": f["value"]} for f in _sole_svr(_lookup(records), axes)]


def sole_svr_table(records: Sequence[Mapping]) -> Table:
    """:func:`sole_svr_beside_paper` as a table.

    Parameters
    ----------
    records : sequence of dict
        Metric records of experiments 1 and 2, as for :func:`paper_pattern`.
    """
    rows = [[f["figure"], f["axis"], f["paper"], f["ours"]] for f in sole_svr_beside_paper(records)]
    notes = ["Shown, not checked: these figures depend on how the paper trained its sole SVR (the paper's Table 4 "
             "overfitting among them), which the paper does not describe in enough detail to copy."]
    return Table("The sole SVR beside the paper", ["figure", "axis", "paper", "greybox"], rows, notes)
