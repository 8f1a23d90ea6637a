"""The safe interval of approach speeds: analytic cases.

The post-impact CoM velocities are ``c0 + s d_j``; in the square ``[-1, 1]^2`` the safe
speeds are found by hand below, independently of the half-plane code.
"""

from __future__ import annotations

import numpy as np
import pytest

import impact_balance as ib
from impact_balance.criteria.com import max_contact_velocity, safe_interval
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel, ImpactSpec

SQUARE = Polygon(np.array([[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]]))
MASS = 2.0


def _model(jumps) -> ImpactModel:
    """An impact model whose CoM velocity jumps per unit approach speed are ``jumps``."""
    jumps = np.atleast_2d(np.asarray(jumps, dtype=float))
    rates = np.column_stack([MASS * jumps, np.zeros(len(jumps))])
    spec = ImpactSpec("synthetic", normal=(0.0, 0.0, 1.0))
    return ImpactModel(
        spec,
        np.zeros(3),
        np.array([0.0, 0.0, 1.0]),
        np.zeros((3, 1)),
        np.eye(3),
        MASS,
        np.zeros((3, 1)),
        rates,
    )


@pytest.mark.parametrize(
    "c0, jumps, expected",
    [
        # Inside: from 0 until x = -0.5 + s reaches 1.
        ((-0.5, 0.0), [(1.0, 0.0)], (0.0, 1.5)),
        # Outside on the left, moving right: enters at x = -1 (s = 1), leaves at x = 1 (s = 3).
        ((-2.0, 0.0), [(1.0, 0.0)], (1.0, 3.0)),
        # Same with a second vertex that drifts up: y = 0.5 s <= 1 caps at s = 2.
        ((-2.0, 0.0), [(1.0, 0.0), (1.0, 0.5)], (1.0, 2.0)),
        # Outside, but the jump is along the boundary's direction: never inside.
        ((-2.0, 0.0), [(0.0, 1.0)], None),
        # Outside and moving away: never inside.
        ((-2.0, 0.0), [(-1.0, 0.0)], None),
        # Two vertices, one too slow to enter before the other leaves: x1 = -3 + s in [-1, 1]
        # needs s in [2, 4]; x2 = -3 + 4 s needs s in [0.5, 1]: empty.
        ((-3.0, 0.0), [(1.0, 0.0), (4.0, 0.0)], None),
        # Inside, no horizontal effect: any speed.
        ((0.2, 0.3), [(0.0, 0.0)], (0.0, np.inf)),
    ],
)
def test_square(c0, jumps, expected):
    model = _model(jumps)
    got = safe_interval(SQUARE, model, c0)
    if expected is None:
        assert got is None
        return
    assert got == pytest.approx(expected, abs=1e-12)
    limit = max_contact_velocity(SQUARE, model, c0)
    if expected[0] == 0.0:  # c0 inside: the interval's top is the maximum contact velocity
        assert limit.max_contact_velocity == pytest.approx(expected[1])
    else:
        assert limit.status == "already_falling"
    # Spot check by brute force: the vertices are inside exactly at the speeds in between.
    for s in np.linspace(0.0, 5.0, 101):
        points = np.asarray(c0) + s * np.asarray(jumps, dtype=float)
        inside = bool((np.abs(points) <= 1 + 1e-12).all())
        within = expected[0] - 1e-9 <= s <= expected[1] + 1e-9
        assert inside == within, s


def test_empty_area():
    assert safe_interval(Polygon.empty(), _model([(1.0, 0.0)]), (0.0, 0.0)) is None


def test_a_push_that_catches_a_fall():
    """Talos falling forwards (CoM velocity beyond the area's front): the palm push on the wall
    in front pushes the CoM backwards, so a range of approach speeds catches the fall."""
    scenario = ib.load_scenario("palm_push_two_feet")
    area = ib.analyze(scenario).areas.com_velocity_area
    x_max = area.vertices[:, 0].max()
    falling = scenario.model_copy(update={"com_velocity": (x_max + 0.2, 0.0)})
    analysis = ib.analyze(falling)
    assert not analysis.com_velocity_inside
    lo, hi = analysis.impact.safe_interval
    assert 0.0 < lo < hi
    model = analysis.impact.model
    for s, ok in ((0.5 * lo, False), (0.5 * (lo + hi), True), (1.5 * hi, False)):
        post = model.post_impact_com_velocities(falling.com_velocity, s)
        assert bool(area.contains(post, tol=1e-9).all()) == ok
    d = analysis.to_dict()["impact"]
    assert d["safe_interval"] == pytest.approx([lo, hi])
    assert d["max_contact_velocity"] == 0.0 and d["status"] == "already_falling"
