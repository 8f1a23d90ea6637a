"""Joint groups' labels: the common prefix of joint names (checked by brute force)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from impact_balance.gui.limbs import _common_prefix, _label

_names = st.lists(st.text(alphabet="ab_01xyz", max_size=8), max_size=6)


@given(_names)
def test_common_prefix_is_the_character_prefix_of_every_name(names):
    prefix = _common_prefix(names)
    first = names[0] if names else ""
    candidates = [first[:k] for k in range(len(first) + 1)]  # "" first: always shared
    longest = max((p for p in candidates if all(n.startswith(p) for n in names)), key=len)
    assert prefix == longest


def test_label_of_unknown_joints_is_their_common_prefix():
    assert _label(["servo_a1_joint", "servo_a2_joint"]) == "servo_a"
    assert _label(["ab1", "cd2"]) == "ab1"  # no prefix of 3 characters: the first name
    assert _label(["left_knee", "left_ankle"]) == "left leg"
