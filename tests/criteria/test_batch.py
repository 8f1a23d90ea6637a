"""criteria.batch.posture_exits: the first exit of many postures in one compiled call, the same
numbers as ComCriterion.limit; repeated postures reuse the area; it releases the GIL."""

from __future__ import annotations

import math

import numpy as np
import pytest

from impact_balance._jit import HAVE_NUMBA
from impact_balance.balance.areas import FORCE_BOX, MERGE_TOLERANCE, posture_areas
from impact_balance.contacts.wrench_polytope import face_blocks
from impact_balance.criteria.batch import FALLBACK, posture_exits
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.linear_exit import BOUNDARY_TOLERANCE, EXIT_STATUSES
from impact_balance.geometry.polygon import MERGE_AREA_TOLERANCE
from impact_balance.governor import Governor
from impact_balance.projection.walk import MAX_PIVOTS


def _rows(name: str, n: int, seed: int):
    """The evaluator's arrays for ``n`` postures near the scenario's, and their criteria."""
    g = Governor(name)
    e = g._evaluator
    s = e.settings
    rng = np.random.default_rng(seed)
    cols: dict[str, list] = {
        k: [] for k in "blocks pos arms jac gt w depth com omega jumps cv".split()
    }
    criteria = []
    for _ in range(n):
        q = g.configuration.copy()
        q[7:] += rng.uniform(-0.02, 0.02, q.size - 7)
        k = e.kinematics(q)
        impact = e.impact_at(q, k)
        areas = posture_areas(
            e._faces, k.rotations, k.local + k.origin, k.local - k.com_local, k.mass, k.com,
            s.gravity, k.jacobians, e._idx, e._limit, k.gravity_torques, e._frictions,
            s.plane_height, s.zmp_margin,
        )  # fmt: skip
        criteria.append(ComCriterion(areas.com_velocity_area, impact, s.velocity_margin))
        cols["blocks"].append(face_blocks(e._faces, k.rotations))
        cols["pos"].append(k.local + k.origin)
        cols["arms"].append(k.local - k.com_local)
        cols["jac"].append(k.jacobians if e._torques else np.zeros((0, 0)))
        cols["gt"].append(k.gravity_torques)
        cols["w"].append(k.mass * s.gravity)
        cols["depth"].append(s.plane_height - float(k.com[2]))
        cols["com"].append(k.com)
        cols["omega"].append(areas.w if hasattr(areas, "w") else areas.omega)
        cols["jumps"].append(impact.com_jump_rates)
        cols["cv"].append(rng.normal(0.0, 0.2, 2))
    arrays = {k: np.ascontiguousarray(np.array(v)) for k, v in cols.items()}
    settings = np.array(
        [FORCE_BOX, MAX_PIVOTS, MERGE_TOLERANCE, MERGE_AREA_TOLERANCE, s.zmp_margin,
         s.velocity_margin, BOUNDARY_TOLERANCE]
    )  # fmt: skip
    return e, arrays, settings, criteria


def _exits(e, a, settings, same):
    out = np.empty((len(same), 4))
    posture_exits(
        a["blocks"], a["pos"], a["arms"], a["jac"], e._idx, e._limit, a["gt"], a["w"],
        a["depth"], a["com"], a["omega"], a["jumps"], a["cv"], settings,
        np.full(2 + 6 * len(e._frames), -1, dtype=np.int64), out, same,
    )  # fmt: skip
    return out


@pytest.mark.parametrize("name", ["kick_one_foot", "g1_two_feet"])
def test_exits_equal_the_criterion(name):
    e, a, settings, criteria = _rows(name, 8, 2)
    out = _exits(e, a, settings, np.zeros(8, dtype=np.bool_))
    for i, criterion in enumerate(criteria):
        want = criterion.limit(np.append(a["cv"][i], 0.0))
        assert out[i, 0] != FALLBACK
        assert EXIT_STATUSES[int(out[i, 0])] == want.status
        if want.status == "ok":
            assert out[i, 1] == pytest.approx(want.max_contact_velocity, abs=1e-12)
            assert (int(out[i, 2]), int(out[i, 3])) == (want.limiting_vertex, want.limiting_edge)


def test_a_repeated_posture_reuses_the_previous_area():
    e, a, settings, criteria = _rows("kick_one_foot", 4, 5)
    for key in ("blocks", "pos", "arms", "jac", "gt", "w", "depth", "com", "omega", "jumps"):
        a[key][1:] = a[key][0]  # postures 1..3 are posture 0; only the velocity differs
        a[key][3] = 0.0  # and the arrays of a repeated row are not read
    same = np.array([False, True, True, True])
    out = _exits(e, a, settings, same)
    for i in range(4):
        want = criteria[0].limit(np.append(a["cv"][i], 0.0))
        assert EXIT_STATUSES[int(out[i, 0])] == want.status
        if math.isfinite(want.max_contact_velocity) and want.status == "ok":
            assert out[i, 1] == pytest.approx(want.max_contact_velocity, abs=1e-12)


@pytest.mark.skipif(not HAVE_NUMBA, reason="needs numba (compiled code)")
def test_the_compiled_call_releases_the_gil():
    assert posture_exits.targetoptions.get("nogil") is True
