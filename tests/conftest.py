"""Shared fixtures for the CWC, projection and area tests, and the folder markers.

Plain helper functions are handed out through session-scoped fixtures so that hypothesis
tests can use them without the function-scoped-fixture health check. Every test under
``tests/sim``, ``tests/gui`` and ``tests/sweep`` gets that folder's marker (``-m "not sim"``
leaves the folder out); helpers shared by test files live in :mod:`tests.helpers`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

#: Folders whose every test needs an extra, and the marker each gets.
FOLDER_MARKERS = {"sim": "sim", "gui": "gui", "sweep": "sweep"}
HERE = Path(__file__).parent

GRAVITY = 9.81  # CONVENTIONS.md: g = 9.81 m/s^2 along -z


def _make_contact(position, rotation=None, friction=0.7, size=(0.2, 0.1)):
    """A synthetic contact (no robot): only spec, rotation and position matter."""
    from impact_balance.contacts.stance import Contact, ContactSpec

    rotation = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    return Contact(
        ContactSpec("synthetic", float(friction), (float(size[0]), float(size[1]))),
        rotation,
        np.asarray(position, dtype=float),
        jacobian=np.zeros((6, 1)),
    )


def _ccw_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (monotone chain), collinear points dropped.

    Independent of scipy and of the library: used as the reference for expected polygons.
    Degenerate inputs give 0, 1 or 2 points.
    """
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, dtype=float).reshape(-1, 2)})
    if len(pts) <= 2:
        return np.array(pts).reshape(-1, 2)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    scale = max(1.0, max(abs(c) for p in pts for c in p))
    eps = 1e-12 * scale * scale
    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= eps:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= eps:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1]).reshape(-1, 2)


def _shoelace(vertices: np.ndarray) -> float:
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    if len(v) < 3:
        return 0.0
    x, y = v.T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _point_distance(p: np.ndarray, hull: np.ndarray) -> float:
    """Euclidean distance from point p to the convex hull given by CCW vertices (0 inside)."""
    p = np.asarray(p, dtype=float)
    k = len(hull)
    if k == 0:
        return np.inf
    if k == 1:
        return float(np.linalg.norm(p - hull[0]))
    inside = k >= 3
    best = np.inf
    for i in range(k if k >= 3 else 1):
        a, b = hull[i], hull[(i + 1) % k]
        e = b - a
        if inside and e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0]) < 0:
            inside = False
        t = np.clip(np.dot(p - a, e) / np.dot(e, e), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(p - (a + t * e))))
    return 0.0 if inside else best


def _hausdorff(P: np.ndarray, Q: np.ndarray) -> float:
    """Hausdorff distance between the convex hulls of two point sets.

    For convex sets the farthest point of one from the other is a vertex, so checking the
    vertices of each against the hull of the other is exact. Two empty sets are at distance
    0; an empty and a non-empty set at the diameter-like extent of the non-empty one.
    """
    P = np.asarray(P, dtype=float).reshape(-1, 2)
    Q = np.asarray(Q, dtype=float).reshape(-1, 2)
    if len(P) == 0 and len(Q) == 0:
        return 0.0
    if len(P) == 0 or len(Q) == 0:
        R = P if len(P) else Q
        return float(np.max(np.linalg.norm(R - R.mean(axis=0), axis=1)))
    hp, hq = _ccw_hull(P), _ccw_hull(Q)
    return max(max(_point_distance(p, hq) for p in hp), max(_point_distance(q, hp) for q in hq))


class Geometry:
    """Namespace of the independent geometric reference helpers."""

    hull = staticmethod(_ccw_hull)
    area = staticmethod(_shoelace)
    distance = staticmethod(_point_distance)
    hausdorff = staticmethod(_hausdorff)


@pytest.fixture(scope="session")
def geo() -> type[Geometry]:
    return Geometry


@pytest.fixture(scope="session")
def make_contact():
    return _make_contact


@pytest.fixture(scope="session")
def talos_stance():
    """Talos half_sitting on both soles (mu 0.7, 0.2 x 0.1 m), the README's standard stance."""
    from impact_balance.contacts.stance import ContactSpec, Stance
    from impact_balance.robot.robot import load_robot

    robot = load_robot("talos")
    return Stance(
        robot,
        robot.configuration(),
        [
            ContactSpec("left_sole_link", 0.7, (0.2, 0.1)),
            ContactSpec("right_sole_link", 0.7, (0.2, 0.1)),
        ],
    )


@pytest.fixture(autouse=True)
def _trial_journals_in_tmp(tmp_path, monkeypatch):
    """The simulation commands' default journals (``impact-balance-trials/`` in the current
    directory) go to the test's own folder, not into the source tree."""
    try:
        from impact_balance.sim.studies import journal
    except ImportError:  # no sim extra: nothing writes journals
        return
    monkeypatch.setattr(journal, "JOURNAL_FOLDER", str(tmp_path / "impact-balance-trials"))


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Add the folder's marker to every test under ``tests/sim``, ``tests/gui``, ``tests/sweep``."""
    for item in items:
        try:
            folder = item.path.relative_to(HERE).parts[0]
        except ValueError:  # a test outside tests/
            continue
        marker = FOLDER_MARKERS.get(folder)
        if marker is not None:
            item.add_marker(getattr(pytest.mark, marker))
