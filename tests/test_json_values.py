"""Numbers as JSON values: finite -> float, anything else -> null."""

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from impact_balance.json_values import json_number, json_numbers


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_a_float_is_itself_when_finite_else_null(x):
    out = json_number(x)
    if math.isfinite(x):
        assert out == x and type(out) is float
    else:
        assert out is None
    json.dumps(out, allow_nan=False)  # strict JSON never sees NaN or Infinity


@pytest.mark.parametrize(
    ("value", "expected"),
    [(np.float64(0.25), 0.25), (np.int64(3), 3.0), (True, 1.0), (None, None), (np.inf, None)],
)
def test_numpy_and_none(value, expected):
    out = json_number(value)
    assert out == expected and (out is None or type(out) is float)


def test_many():
    assert json_numbers([1, float("nan"), None, -np.inf, 2.5]) == [1.0, None, None, None, 2.5]
