"""A log check's results as JSON values: a violation without an area has a null margin."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

import pandas as pd

from impact_balance.logs.check import Violation, json_records


def strict(value):
    def refuse(name):
        raise ValueError(name)

    return json.loads(json.dumps(value), parse_constant=refuse)


def test_a_violation_without_area_has_a_null_margin():
    v = Violation("com_velocity", 0.0, 0.5, -math.inf, 0.1, 6)
    assert strict(v.to_dict()) == {
        "kind": "com_velocity",
        "start": 0.0,
        "end": 0.5,
        "worst_margin": None,
        "worst_time": 0.1,
        "samples": 6,
    }
    assert Violation("zmp", 0.0, 0.1, -0.02, 0.05, 2).to_dict()["worst_margin"] == -0.02


def test_records_turn_nan_and_infinities_into_null():
    frame = pd.DataFrame({"a": [1.0, np.nan, np.inf], "b": [0.5, -np.inf, 2.0]})
    assert strict(json_records(frame)) == [
        {"a": 1.0, "b": 0.5},
        {"a": None, "b": None},
        {"a": None, "b": 2.0},
    ]
