"""Key paths into nested data: get_path reads what set_path wrote, which copies the path only."""

from __future__ import annotations

import copy

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("pyarrow", reason="needs the sweep extra (pyarrow)")

from impact_balance.sweep.paths import format_path, get_path, parse_path, set_path

BASE = {
    "impact": {"friction": 0.3, "restitution": [0.0, 0.5], "offset": {"position": [0, 0, 0]}},
    "contacts": [{"frame": "a", "size": [0.2, 0.1]}, {"frame": "b", "size": [0.2, 0.1]}],
}
PATHS = [
    "impact.friction",
    "impact.restitution[1]",
    "impact.offset.position[2]",
    "contacts[1].size[0]",
    "contacts[0].frame",
]


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(PATHS), st.floats(allow_nan=False, allow_infinity=False))
def test_set_then_get_gives_the_value_and_leaves_the_base(path, value):
    before = copy.deepcopy(BASE)
    tokens = parse_path(path, "axes[0].path")
    assert format_path(tokens) == path
    out = set_path(BASE, tokens, value)
    assert get_path(out, tokens) == value
    assert BASE == before
    # Containers off the path are shared, not copied.
    if tokens[0] == "impact":
        assert out["contacts"] is BASE["contacts"]


def test_a_key_into_a_list_is_a_type_error():
    with pytest.raises(TypeError, match="integers"):
        set_path(BASE, ("contacts", "frame"), "c")
