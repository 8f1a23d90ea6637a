"""Does the holding hand's contact survive the impact? After the fact, on spent sets, no trial.

Usage (from the repository root, with impact-balance installed)::

    nice -n 5 python studies/hold_through_impact.py 8 9 10 11

For every stance of ``studies/held_out_N/`` with a hand among its sustained ``contacts`` and a
rigid-impact record in ``studies/held_out_results_N/impacts.csv``, it takes the held-stance
impact model's impulses (``contact_impact`` at 1 m/s, the restitution bounds lo and hi, cold
start: the QP's multipliers, least norm, per corner) and adds the hand's pre-impact load over
the impact window: the static wrench distribution of least norm (the weight carried by every
contact's corners inside their friction pyramids at ``SCALE`` mu, one QP) times the scenario's
``impact.duration`` T. The hand's resultant over the window at approach speed v is then
``T f_static + v iota`` (N s, both linear), and the script reports:

- ``slip``: the smallest v at which that resultant leaves the friction cone ``SCALE`` mu
  (circular, the contact's normal), a root of a quadratic; inf if never; the same at the
  contact's full mu (the static load kept as at ``SCALE`` mu, as the controller holds it);
- ``lift``: the largest normal velocity a hand corner takes per m/s after the impact (m/s per
  m/s; > 0: that corner leaves the surface, the hand tilts or lifts) and the speed ``g T / u``
  at which that exceeds what gravity takes back over the window;
- the CoP of the hand's resultant is inside its rectangle by construction (every corner impulse
  has a normal part >= 0), so it is not a criterion here: printed as a check.

Both speeds scale with T (the pre-load is T f_static). It prints one Markdown table with the
record's strict failure and first contact break beside them.
"""

from __future__ import annotations

import csv
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent
SCALE = 0.65  # the id controller's friction share
G = 9.81
HAND_WORDS = ("hand", "wrist", "gripper")


def is_hand(frame: str) -> bool:
    """Whether a contact frame is a hand (not a foot)."""
    return any(word in frame for word in HAND_WORDS)


def slip_speed(static: np.ndarray, per_speed: np.ndarray, normal: np.ndarray, mu: float) -> float:
    """Smallest v >= 0 where ``static + v per_speed`` leaves the cone ``|f_t| <= mu f_n``.

    Args:
        static: Impulse (or force) at v = 0, world, (3,).
        per_speed: Its growth per unit v, world, (3,).
        normal: Unit contact normal, world.
        mu: Friction coefficient of the cone.

    Returns:
        The speed (inf when the resultant stays inside for every v >= 0; 0 when it starts out).
    """
    a_n, b_n = float(normal @ static), float(normal @ per_speed)
    a_t, b_t = static - a_n * normal, per_speed - b_n * normal

    def outside(v: float) -> bool:
        f_n = a_n + v * b_n
        return f_n <= 0.0 or float(np.linalg.norm(a_t + v * b_t)) > mu * f_n * (1 + 1e-12)

    if outside(0.0):
        return 0.0
    # |a_t + v b_t|^2 - mu^2 (a_n + v b_n)^2 = 0, and f_n = 0
    qa = float(b_t @ b_t) - mu**2 * b_n**2
    qb = 2 * (float(a_t @ b_t) - mu**2 * a_n * b_n)
    qc = float(a_t @ a_t) - mu**2 * a_n**2
    roots = [-a_n / b_n] if b_n < 0 else []
    disc = qb * qb - 4 * qa * qc
    if abs(qa) > 1e-14 and disc >= 0:
        # The stable form (no cancellation when qa is small against qb: mu near the cone's
        # growth ratio): q = -(qb + sign(qb) sqrt(disc)) / 2, the roots q / qa and qc / q.
        q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))
        roots += [q / qa] + ([qc / q] if q != 0.0 else [])
    elif abs(qa) <= 1e-14 and abs(qb) > 1e-14:
        roots.append(-qc / qb)
    for v in sorted(r for r in roots if r > 0):
        if outside(v * (1 + 1e-9) + 1e-12):
            return v
    return math.inf


def static_corner_forces(stance, scale: float) -> list[np.ndarray]:  # type: ignore[no-untyped-def]
    """Least-norm corner forces (k, 4, 3) carrying the weight, each in its pyramid at scale mu.

    Force balance m g z and moment balance about the CoM; one QP (daqp) over the pyramids'
    generator weights. Raises RuntimeError when the weight cannot be carried.
    """
    import qpsolvers

    from impact_balance.impact.contact_aware import corner_contacts

    corners = corner_contacts(stance)
    cols, owners = [], []
    for i, contact in enumerate(corners):
        for k, p in enumerate(contact):
            D = p.normal[:, None] + scale * (p.generators - p.normal[:, None])
            for j in range(D.shape[1]):
                cols.append(np.concatenate([D[:, j], np.cross(p.arm, D[:, j])]))
                owners.append((i, k, D[:, j]))
    A = np.array(cols).T
    b = np.array([0.0, 0.0, stance.mass * G, 0.0, 0.0, 0.0])
    n = A.shape[1]
    lam = qpsolvers.solve_qp(
        np.eye(n), np.zeros(n), A=A, b=b, lb=np.zeros(n), ub=np.full(n, np.inf), solver="daqp"
    )
    if lam is None or np.abs(A @ lam - b).max() > 1e-6 * stance.mass * G:
        raise RuntimeError("the weight cannot be carried at this friction")
    out = [np.zeros((4, 3)) for _ in corners]
    for weight, (i, k, d) in zip(lam, owners, strict=True):
        out[i][k] += max(weight, 0.0) * d
    return out


@dataclass(frozen=True)
class HandAnswer:
    """The hand's answer at one restitution bound (units in the module docstring)."""

    restitution: float
    converged: bool
    impulse: np.ndarray  # the hand's impulse per m/s, world, N s per (m/s)
    static_force: np.ndarray  # the hand's pre-impact force, world, N
    slip: float  # m/s, at SCALE mu
    slip_full: float  # m/s, at mu
    lift_rate: float  # m/s per m/s
    lift: float  # m/s
    cop_inside: bool


def hand_answers(path: Path) -> tuple[str, list[HandAnswer]]:
    """The held-stance model's hand answers of the stance file ``path`` at lo and hi."""
    from impact_balance.analysis.analyze import analyze
    from impact_balance.impact.contact_aware import contact_impact, corner_contacts

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analysis = analyze(str(path), solve_qp=False)
    stance = analysis.stance
    assert analysis.impact is not None
    spec = analysis.impact.model.spec
    T = float(spec.duration)
    index = [i for i, c in enumerate(stance.contacts) if is_hand(c.spec.frame)]
    if len(index) != 1:
        raise ValueError(f"{path.name}: {len(index)} hand contacts")
    h = index[0]
    contact = stance.contacts[h]
    static = static_corner_forces(stance, SCALE)[h]
    corners = corner_contacts(stance)[h]
    out = []
    for c in spec.restitution:
        answer = contact_impact(stance, spec, 1.0, restitution=float(c))
        dxi = np.concatenate([answer.com_velocity_jump_3d, answer.angular_velocity_jump])
        rates = [
            float(p.normal @ (dxi[:3] + np.cross(dxi[3:], p.arm))) for p in corners
        ]  # each hand corner's normal velocity after the impact, per m/s
        iota = answer.contact_impulses[h]
        lift_rate = max(rates)
        total = T * static + answer.corner_impulses[h]  # at v = 1 m/s, per corner
        normals = total @ contact.normal
        out.append(
            HandAnswer(
                float(c),
                bool(answer.converged),
                iota,
                static.sum(axis=0),
                slip_speed(
                    T * static.sum(axis=0), iota, contact.normal, SCALE * contact.spec.friction
                ),
                slip_speed(T * static.sum(axis=0), iota, contact.normal, contact.spec.friction),
                lift_rate,
                G * T / lift_rate if lift_rate > 1e-9 else math.inf,
                bool((normals >= -1e-9).all()),
            )
        )
    return contact.spec.frame, out


def records(numbers: list[int]) -> list[tuple[int, dict[str, str]]]:
    """The rigid rows of the hand-hold stances' impact records of the sets ``numbers``."""
    import yaml

    rows = []
    for number in numbers:
        with open(ROOT / f"held_out_results_{number}" / "impacts.csv") as f:
            for row in csv.DictReader(f):
                if row["impact_model"] != "rigid":
                    continue
                stance = yaml.safe_load(
                    (ROOT / f"held_out_{number}" / f"{row['stance']}.yaml").read_text()
                )
                if any(is_hand(c["frame"]) for c in stance["contacts"]):
                    rows.append((number, row))
    return rows


def fmt(x: float | str | None) -> str:
    """A speed to 3 decimals (inf, '-' for a missing one)."""
    if x is None or x == "":
        return "–"
    x = float(x)
    return "inf" if math.isinf(x) else f"{x:.3f}"


def main(argv: list[str]) -> int:
    """Print the table of the sets named in ``argv`` (default 8 9 10 11)."""
    from impact_balance.exceptions import SolverError

    numbers = [int(a) for a in argv] or [8, 9, 10, 11]
    print(
        "| set | stance | hand | c | converged | hand impulse per m/s (n, |t|) |"
        " |t|/n of the impulse / 0.65 mu | static force (n, |t|) | slip at 0.65 mu (m/s) |"
        " slip at mu (m/s) | corner lift rate | lift speed (m/s) | CoP inside |"
        " first break (m/s, contact) | strict failure | fell |"
    )
    print("|" + "---|" * 16)
    for number, row in records(numbers):
        path = ROOT / f"held_out_{number}" / f"{row['stance']}.yaml"
        try:
            frame, answers = hand_answers(path)
        except SolverError as exc:  # the model's QP not solved: no answer on this stance
            print(f"| {number} | {row['stance']} | – | – | not solved ({exc}) |" + " – |" * 11)
            continue
        for a in answers:
            print(
                f"| {number} | {row['stance']} | {frame} | {a.restitution:.2f} | {a.converged} |"
                f" {_nt(a.impulse, path)} | {_ratio(a.impulse, path)} |"
                f" {_nt(a.static_force, path)} | {fmt(a.slip)} | {fmt(a.slip_full)} |"
                f" {a.lift_rate:.3f} | {fmt(a.lift)} | {a.cop_inside} |"
                f" {fmt(row['first_contact_break_mps'])} {row['first_contact_break'] or ''} |"
                f" {fmt(row['strict_failed_mps'])} | {fmt(row['fell_mps'])} |"
            )
            sys.stdout.flush()
    return 0


_NORMALS: dict[Path, tuple[np.ndarray, float]] = {}


def _hand_normal(path: Path) -> tuple[np.ndarray, float]:
    if path not in _NORMALS:
        from impact_balance.analysis.analyze import analyze

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            stance = analyze(str(path), solve_qp=False).stance
        c = next(c for c in stance.contacts if is_hand(c.spec.frame))
        _NORMALS[path] = (c.normal.copy(), float(c.spec.friction))
    return _NORMALS[path]


def _nt(f: np.ndarray, path: Path) -> str:
    n, _ = _hand_normal(path)
    f_n = float(n @ f)
    return f"({f_n:.1f}, {float(np.linalg.norm(f - f_n * n)):.1f})"


def _ratio(f: np.ndarray, path: Path) -> str:
    n, mu = _hand_normal(path)
    f_n = float(n @ f)
    if f_n <= 1e-9:
        return "no normal"
    return f"{float(np.linalg.norm(f - f_n * n)) / f_n / (SCALE * mu):.2f}"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
