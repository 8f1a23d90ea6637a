"""``studies/torso_pushes.py``: the turn while the capture stands on one sole.

``turn_on_one_sole``'s closed form is checked against an independent integration of the LIPM
with the ZMP held at the edge, and ``_sole_alone``'s geometry against a brute-force walk along
the ray on two synthetic soles.
"""

from __future__ import annotations

import math
from types import ModuleType, SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.helpers.scripts import load_study

pytest.importorskip("mujoco")  # the script imports the simulation's push prediction
pd = pytest.importorskip("pandas", reason="needs the study extra (pandas)")


@pytest.fixture(scope="module")
def script() -> ModuleType:
    return load_study("torso_pushes")


def _time_on_one_sole(omega: float, e: float, e_in: float, xi0: float) -> float:
    """RK4 on c'' = omega^2 (c - e) from c = 0, c' = omega xi0, until c + c'/omega <= e_in."""
    dt, x, v, t = 1e-4, 0.0, omega * xi0, 0.0
    f = lambda x: omega**2 * (x - e)  # noqa: E731
    while x + v / omega > e_in:
        k1x, k1v = v, f(x)
        k2x, k2v = v + 0.5 * dt * k1v, f(x + 0.5 * dt * k1x)
        k3x, k3v = v + 0.5 * dt * k2v, f(x + 0.5 * dt * k2x)
        k4x, k4v = v + dt * k3v, f(x + dt * k3x)
        x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        t += dt
    return t


@settings(max_examples=25, deadline=None)
@given(
    omega=st.floats(2.5, 5.0),
    e=st.floats(0.05, 0.3),
    entry=st.floats(0.0, 0.95),
    ratio=st.floats(0.05, 0.97),
    momentum=st.floats(0.5, 15.0),
    inertia=st.floats(1.0, 20.0),
)
def test_turn_on_one_sole_matches_the_lipm(
    script: ModuleType,
    omega: float,
    e: float,
    entry: float,
    ratio: float,
    momentum: float,
    inertia: float,
) -> None:
    e_in = entry * e
    table = pd.DataFrame(
        {
            "kappa": [1.1],
            "relative": [ratio / 1.1],
            "rho": [1.0],
            "zmp_extent": [e],
            "sole_entry": [e_in],
            "omega": [omega],
            "angular_momentum": [momentum],
            "inertia": [inertia],
        }
    )
    turn = float(script.turn_on_one_sole(table).iloc[0])
    expected = momentum / inertia * _time_on_one_sole(omega, e, e_in, ratio * e)
    assert turn == pytest.approx(expected, abs=momentum / inertia * 2e-4)


def test_turn_on_one_sole_edges(script: ModuleType) -> None:
    base = {"kappa": 1.0, "rho": 1.0, "zmp_extent": 0.1, "omega": 3.0}
    base |= {"angular_momentum": 4.0, "inertia": 2.0}
    table = pd.DataFrame(
        [
            {**base, "relative": 0.8, "sole_entry": math.nan},  # no sole alone: no turn
            {**base, "relative": 1.2, "sole_entry": 0.05},  # not captured
            {**base, "relative": 0.3, "sole_entry": 0.05},  # the DCM never beyond the entry
        ]
    )
    turn = script.turn_on_one_sole(table).tolist()
    assert turn[0] == 0.0 and math.isinf(turn[1]) and turn[2] == 0.0


def _rectangle(cx: float, cy: float, hx: float, hy: float) -> SimpleNamespace:
    corners = np.array(
        [[cx + sx * hx, cy + sy * hy, 0.0] for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    )
    return SimpleNamespace(spec=SimpleNamespace(frame="left_sole"), corners=lambda: corners)


@pytest.mark.parametrize("degrees", [0.0, 30.0, 60.0, 90.0, 120.0, 200.0, 270.0, 300.0])
def test_sole_alone_against_a_walk_along_the_ray(script: ModuleType, degrees: float) -> None:
    from impact_balance.geometry.polygon import Polygon

    soles = [_rectangle(0.02, 0.1, 0.1, 0.04), _rectangle(-0.03, -0.1, 0.1, 0.04)]
    points = np.vstack([s.corners()[:, :2] for s in soles])
    area = Polygon.from_points(points)
    analysis = SimpleNamespace(
        stance=SimpleNamespace(com=np.zeros(3), contacts=soles),
        areas=SimpleNamespace(zmp_area=area),
    )
    u = np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])
    e, e_in = script._sole_alone(analysis, u, 0.0)
    # brute force: the last point of the ray inside the hull, and the first inside each sole
    s = np.linspace(0.0, 0.5, 500_001)
    ray = s[:, None] * u
    inside = area.contains(ray, tol=1e-12)
    assert e == pytest.approx(s[inside].max(), abs=2e-6)
    rects = [Polygon.from_points(r.corners()[:, :2]) for r in soles]
    holding = [r for r in rects if bool(np.all(r.contains((e * u)[None, :], tol=1e-6)))]
    if len(holding) != 1:
        assert math.isnan(e_in)
    else:
        entered = holding[0].contains(ray, tol=1e-12)
        assert e_in == pytest.approx(s[entered].min(), abs=2e-6)
