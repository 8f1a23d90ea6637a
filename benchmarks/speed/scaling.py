"""Scaling studies: with the number of contacts (Talos, 1 to 4, with and without torque limits)
and with the number of friction-cone edges of the impact model (8 to 64)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

import impact_balance as ib
from benchmarks.speed.projection import bench_projection
from benchmarks.speed.timing import Case, measure, progress, stats
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.contacts.wrench_polytope import wrench_polytope

__all__ = ["bench_cone_edges", "bench_contacts", "talos_contact_sets"]


def talos_contact_sets() -> tuple[ib.Robot, np.ndarray, list[tuple[str, list[ContactSpec]]]]:
    import pinocchio as pin

    sc = ib.load_scenario("talos_three_contacts")
    robot = sc.load_robot()
    q = sc.configuration_vector(robot)
    left, right, left_hand = (c.spec() for c in sc.contacts)
    # Right palm (flat +x face of the gripper, as the palm_push impact point) on a wall in
    # front: contact z = gripper -x, i.e. world -x here (checked below).
    right_hand = ContactSpec(
        "gripper_right_base_link",
        0.7,
        (0.1, 0.08),
        pin.SE3(pin.rpy.rpyToMatrix(0.0, -math.pi / 2, 0.0), np.array([0.051, 0.0, -0.045])),
    )
    sets = [
        ("right foot", [right]),
        ("two feet", [left, right]),
        ("two feet + left hand (wall)", [left, right, left_hand]),
        ("two feet + both hands (walls)", [left, right, left_hand, right_hand]),
    ]
    return robot, q, sets


def bench_contacts(args) -> list[dict[str, Any]]:
    robot, q, sets = talos_contact_sets()
    rows = []
    for label, specs in sets:
        stance = Stance(robot, q, specs)
        t_stance, _ = measure(
            {"stance": Case(lambda specs=specs: Stance(robot, q, specs))}, args.repeat, args.warmup
        )
        for tl in (True, False):
            poly = wrench_polytope(stance, tl)
            t_poly, _ = measure(
                {"constraints": Case(lambda stance=stance, tl=tl: wrench_polytope(stance, tl))},
                args.repeat,
                args.warmup,
            )
            entry = {
                "contacts": label,
                "n_contacts": len(specs),
                "torque_limits": tl,
                "normals": [np.round(c.normal, 3).tolist() for c in stance.contacts],
                "stance_us": stats(t_stance["stance"]),
                "constraints_us": stats(t_poly["constraints"]),
            }
            entry.update(bench_projection(poly, args))
            rows.append(entry)
            progress(
                f"  scaling {label}, torque limits {tl}: {entry['project_us']['median']:.0f} us, "
                f"{entry['pivots']} pivots"
            )
    return rows


def _cone_edge_cases(sc, stance: Stance, areas, spec, model) -> dict[str, Case]:
    """The timed calls of the impact part at one impact ``spec`` (its friction-cone edges)."""
    return {
        "impact_model": Case(lambda: ib.impact_model(stance, spec)),
        "max_velocity": Case(
            lambda: ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity)
        ),
        "zmp_max_velocity": Case(
            lambda: ib.zmp_max_contact_velocity(
                areas.zmp_area,
                model,
                stance.com,
                sc.plane_height,
                sc.gravity,
                spec.duration,
            )
        ),
    }


def bench_cone_edges(
    args, names=("palm_push_two_feet", "talos_three_contacts")
) -> list[dict[str, Any]]:
    rows = []
    for name in names:
        sc = ib.load_scenario(name)
        stance = sc.build_stance()
        areas = ib.balance_areas(stance, sc.plane_height, sc.torque_limits, sc.gravity)
        for n in (8, 16, 32, 64):
            spec = dataclasses.replace(sc.impact.spec(), cone_edges=n)
            model = ib.impact_model(stance, spec)
            cases = _cone_edge_cases(sc, stance, areas, spec, model)
            times, _ = measure(cases, args.repeat_cheap, max(args.warmup, 10))
            v = ib.max_contact_velocity(
                areas.com_velocity_area, model, sc.com_velocity
            ).max_contact_velocity
            rows.append(
                {
                    "scenario": name,
                    "cone_edges": n,
                    "max_contact_velocity_m_s": None if math.isinf(v) else v,
                }
                | {f"{k}_us": stats(t) for k, t in times.items()}
            )
    return rows
