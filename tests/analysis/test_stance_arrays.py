"""The stance's arrays that analyze() hands to the compiled posture: the contacts' faces (kept for
the last contacts' specs) are cwc_faces of each contact whatever stance came before, and an
analysis does not depend on the analyses before it."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.analysis import analyze as pipeline
from impact_balance.contacts.cwc import cwc_faces
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.scenario import load_scenario

SCENARIO = load_scenario("talos_three_contacts")
ROBOT = SCENARIO.load_robot()
Q = SCENARIO.configuration_vector(ROBOT)
SPECS = SCENARIO.contact_specs(ROBOT, Q)

contact = st.tuples(
    st.sampled_from([0.1, 0.24, 0.5, 0.7, 1.0]),
    st.sampled_from([(0.2, 0.1), (0.1, 0.1), (0.0, 0.0), (0.05, 0.3)]),
)


def _stance(choices) -> Stance:
    """The scenario's contacts (frames and offsets) with the chosen frictions and sizes."""
    specs = [
        ContactSpec(spec.frame, mu, size, spec.offset)
        for spec, (mu, size) in zip(SPECS, choices, strict=False)
    ]
    return Stance(ROBOT, Q, specs)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.lists(contact, min_size=1, max_size=3), min_size=1, max_size=6), st.data())
def test_the_faces_are_each_contacts_own_in_any_order(sequence, data):
    stances = [_stance(choices) for choices in sequence]
    order = data.draw(st.lists(st.sampled_from(range(len(stances))), min_size=1, max_size=12))
    for k in order:
        stance = stances[k]
        faces = pipeline._stance_arrays(stance, SCENARIO.torque_limits, SCENARIO.gravity)[0]
        want = [cwc_faces(c.spec.friction, c.half_length, c.half_width) for c in stance.contacts]
        assert faces.shape == (len(want), 16, 6)
        np.testing.assert_array_equal(faces, np.array(want))


def _document(name_or_scenario) -> str:
    out = ib.analyze(name_or_scenario).to_dict()
    out.pop("timings_ms")
    return json.dumps(out, sort_keys=True)


def test_an_analysis_does_not_depend_on_the_ones_before():
    names = ("palm_push_mu010", "palm_push_two_feet", "talos_three_contacts", "g1_two_feet")
    contacts = SCENARIO.model_dump(exclude_unset=True)["contacts"]
    for c, mu in zip(contacts, (0.3, 0.4, 0.5), strict=True):
        c["friction"] = mu
    narrower = SCENARIO.replace(contacts=contacts)
    first = {name: _document(name) for name in names}
    first["narrower"] = _document(narrower)
    for name in reversed(names):
        assert _document(name) == first[name], name
        assert _document(narrower) == first["narrower"]
