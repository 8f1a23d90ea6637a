"""The narrower contact model: friction scaled, rectangles inset, the rest of the stance kept."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.contacts.contact_model import (
    check_friction_scale,
    inset_half_size,
    scaled_contact,
    scaled_stance,
)
from impact_balance.contacts.stance import ContactSpec
from impact_balance.exceptions import ScenarioError
from impact_balance.scenario import load_scenario

STANCE = load_scenario("talos_three_contacts").build_stance()


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.0000001, 1.5, math.nan, math.inf, "x"])
def test_a_bad_friction_scale_is_named_with_its_value(bad):
    with pytest.raises(ScenarioError) as info:
        check_friction_scale(bad)
    assert info.value.field == "friction_scale"
    assert str(bad) in str(info.value) or repr(bad) in str(info.value)


def test_a_bad_cop_margin_is_named():
    spec = ContactSpec("left_sole_link", 0.7, (0.2, 0.1))
    with pytest.raises(ScenarioError) as info:
        scaled_contact(spec, 0.5, -0.01)
    assert info.value.field == "cop_margin"


def test_scale_one_without_margin_is_the_same_stance():
    assert scaled_stance(STANCE, 1.0) is STANCE


@settings(max_examples=30, deadline=None)
@given(
    scale=st.floats(0.01, 1.0),
    margin=st.floats(0.0, 0.2),
)
def test_only_the_specs_change(scale, margin):
    narrower = scaled_stance(STANCE, scale, margin)
    assert narrower.com.tolist() == STANCE.com.tolist()
    assert narrower.mass == STANCE.mass
    for new, old in zip(narrower.contacts, STANCE.contacts, strict=True):
        assert new.spec.frame == old.spec.frame
        assert new.spec.friction == pytest.approx(old.spec.friction * scale, rel=1e-15)
        for half_new, half_old in zip(
            (new.half_length, new.half_width), (old.half_length, old.half_width), strict=True
        ):
            # the controller's rule, written out: shrunk by the margin, never below half
            assert half_new == pytest.approx(max(half_old - margin, 0.5 * half_old), abs=1e-15)
            assert half_new == pytest.approx(inset_half_size(half_old, margin), abs=1e-15)
        np.testing.assert_array_equal(new.position, old.position)
        np.testing.assert_array_equal(new.rotation, old.rotation)
        np.testing.assert_array_equal(new.jacobian, old.jacobian)
    # the stance itself is left as it was
    assert [c.spec.friction for c in STANCE.contacts] == [
        c.spec.friction for c in load_scenario("talos_three_contacts").build_stance().contacts
    ]


def test_scale_one_with_a_bad_margin_is_still_refused():
    with pytest.raises(ScenarioError) as info:
        scaled_stance(STANCE, 1.0, -0.01)
    assert info.value.field == "cop_margin"
    assert scaled_stance(STANCE, 1.0, 0.01) is not STANCE  # a margin alone narrows the contacts
