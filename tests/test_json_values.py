"""The one sanitiser of values written as JSON."""

from __future__ import annotations

import json

import numpy as np

from greybox.json_values import jsonable


def test_nested_numpy_values_become_strict_json():
    value = {"a": np.float32(0.25), 3: [np.int64(7), (np.bool_(True), float("nan"))],
             "b": np.array([[1.0, -np.inf], [np.nan, 2.5]]), "c": None, "d": "text"}
    out = jsonable(value)
    assert out == {"a": 0.25, "3": [7, [True, None]], "b": [[1.0, None], [None, 2.5]], "c": None, "d": "text"}
    assert type(out["a"]) is float and type(out["3"][0]) is int and type(out["3"][1][0]) is bool
    json.dumps(out, allow_nan=False)  # strict JSON: would raise on a NaN left behind


def test_other_objects_pass_unchanged_or_through_the_given_function():
    class Thing:
        def __repr__(self):
            return "Thing()"

    thing = Thing()
    assert jsonable([thing])[0] is thing
    assert jsonable({"model": thing, "n": np.int32(2), "bounds": (1, np.float64(np.inf))}, other=repr) == {
        "model": "Thing()", "n": 2, "bounds": [1, None]}
