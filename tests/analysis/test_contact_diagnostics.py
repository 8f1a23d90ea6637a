"""contact_diagnostics skips the tilt of a clearly flat normal: the same warnings as the rule.

The rule, computed here from the angle itself: a normal with a negative world z points down;
one between FLOOR_TILT and WALL_TILT degrees from the vertical is tilted.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pinocchio as pin
from hypothesis import given
from hypothesis import strategies as st

from impact_balance.analysis.diagnostics import FLOOR_TILT, WALL_TILT, contact_diagnostics
from impact_balance.contacts.stance import Contact, ContactSpec

SPEC = ContactSpec("sole", 0.7, (0.2, 0.1))


def _contact(tilt_degrees: float, azimuth: float) -> Contact:
    """A contact whose normal is ``tilt_degrees`` from the vertical, towards ``azimuth``."""
    rotation = pin.rpy.rpyToMatrix(0.0, math.radians(tilt_degrees), 0.0)
    rotation = pin.rpy.rpyToMatrix(0.0, 0.0, azimuth) @ rotation
    return Contact(SPEC, rotation, np.zeros(3), np.zeros((6, 1)), np.zeros(3))


def _expected(contact: Contact) -> list[str]:
    z = float(contact.normal[2])
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, z))))
    if z < 0.0:
        return ["contact_normal_down"]
    return ["contact_normal_tilted"] if FLOOR_TILT < tilt < WALL_TILT else []


ANGLES = st.one_of(
    st.floats(0.0, 180.0),
    st.floats(FLOOR_TILT - 1e-6, FLOOR_TILT + 1e-6),  # at the floor's edge
    st.sampled_from([0.0, FLOOR_TILT, math.nextafter(FLOOR_TILT, 0.0), WALL_TILT, 90.0, 180.0]),
)


@given(st.lists(st.tuples(ANGLES, st.floats(-math.pi, math.pi)), min_size=1, max_size=4))
def test_the_warnings_are_the_rules_at_any_tilt(normals):
    contacts = [_contact(tilt, azimuth) for tilt, azimuth in normals]
    got = contact_diagnostics(SimpleNamespace(contacts=contacts))
    want = [(f"contacts[{i}]", code) for i, c in enumerate(contacts) for code in _expected(c)]
    assert [(d.field, d.code) for d in got] == want
