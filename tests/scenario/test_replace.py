"""``Scenario.replace``: the one validated override, refusing what the schema refuses."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.constants import MAX_SIZE, MAX_VELOCITY_MARGIN
from impact_balance.exceptions import ScenarioError, UnknownKeyError
from impact_balance.scenario import load_scenario

BASE = load_scenario("palm_push_two_feet")

#: The margins and their ranges, as the schema documents them.
RANGES = {"zmp_margin": (0.0, MAX_SIZE), "velocity_margin": (0.0, MAX_VELOCITY_MARGIN)}

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-1.0, 12.0),
    st.sampled_from([0.0, MAX_SIZE, MAX_VELOCITY_MARGIN, -0.0, 1e-300, -1e-300]),
)


@settings(max_examples=150, deadline=None)
@given(key=st.sampled_from(sorted(RANGES)), value=numbers)
def test_replace_refuses_exactly_what_the_range_refuses(key, value):
    lo, hi = RANGES[key]
    if math.isfinite(value) and lo <= value <= hi:
        changed = BASE.replace(**{key: value})
        assert getattr(changed, key) == value
        assert key in changed.set_keys
        # Everything else is the scenario's own.
        assert changed.model_dump(exclude={key}) == BASE.model_dump(exclude={key})
        assert changed.source == BASE.source
    else:
        with pytest.raises(ScenarioError) as info:
            BASE.replace(**{key: value})
        assert info.value.field == key


@pytest.mark.parametrize("value", ["0.01", True, None, [0.01]])
@pytest.mark.parametrize("key", sorted(RANGES))
def test_replace_refuses_what_is_not_a_number(key, value):
    with pytest.raises(ScenarioError) as info:
        BASE.replace(**{key: value})
    assert info.value.field == key


def test_replace_refuses_what_a_file_refuses(tmp_path: Path):
    """The same value, written in a file and given to ``replace``: the same refusal."""
    for key, value in (("zmp_margin", 10.5), ("velocity_margin", -0.01), ("gravity", 0.0)):
        path = tmp_path / f"{key}.yaml"
        path.write_text(f"extends: palm_push_two_feet\n{key}: {value}\n")
        with pytest.raises(ScenarioError) as from_file:
            load_scenario(str(path))
        with pytest.raises(ScenarioError) as from_replace:
            BASE.replace(**{key: value})
        assert from_replace.value.field == from_file.value.field == key
        assert from_replace.value.reason == from_file.value.reason


def test_replace_refuses_an_unknown_key():
    with pytest.raises(UnknownKeyError) as info:
        BASE.replace(zmp_margn=0.01)
    assert info.value.field == "zmp_margn" and "zmp_margin" in str(info.value)


def test_a_file_key_and_an_override_give_the_same_scenario(tmp_path: Path):
    path = tmp_path / "margins.yaml"
    path.write_text("extends: palm_push_two_feet\nzmp_margin: 0.01\nvelocity_margin: 0.02\n")
    from_file = load_scenario(str(path))
    assert {"zmp_margin", "velocity_margin"} <= from_file.set_keys
    replaced = BASE.replace(zmp_margin=0.01, velocity_margin=0.02)
    assert replaced.model_dump(exclude={"name"}) == from_file.model_dump(exclude={"name"})
    assert "velocity_margin" not in BASE.set_keys and BASE.velocity_margin == 0.0


def test_replace_without_changes_is_the_scenario():
    assert BASE.replace() is BASE
