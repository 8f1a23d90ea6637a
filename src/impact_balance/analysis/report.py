"""Plain-text reports of analyses (what ``impact-balance demo`` and ``analyze`` print)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from impact_balance.analysis.result import Analysis

__all__ = ["format_analysis", "format_safe_interval", "format_speed", "format_timings"]


def format_speed(value: float) -> str:
    """m/s with 3 decimals, "unbounded" for inf."""
    return f"{value:.3f} m/s" if np.isfinite(value) else "unbounded"


def format_timings(timings: dict[str, float]) -> str:
    """What each measured time is: the analysis, then what it did not include.

    ``kernel_compiling`` (s) is said beside the analysis (``analysis 3.1 ms (+ 14.2 s
    compiling the kernels once)``); the rest of ``kernel_loading`` (s, numba loading its
    cached kernels), the scenario's and the robot model's loading are listed as not included.
    """
    text = f"analysis {1e3 * timings.get('total', float('nan')):.1f} ms"
    compiling = timings.get("kernel_compiling", 0.0)
    if compiling > 0.0:
        text += f" (+ {compiling:.1f} s compiling the kernels once)"
    extra = []
    if "scenario_loading" in timings:
        extra.append(f"scenario loading {1e3 * timings['scenario_loading']:.1f} ms")
    robot = timings.get("robot_loading", 0.0)
    if robot > 1e-3:  # a cached model takes microseconds: only the first use is worth a word
        extra.append(f"robot model loading {1e3 * robot:.0f} ms (first use)")
    loading = timings.get("kernel_loading", 0.0) - compiling
    if loading > 1e-3:  # microseconds: a dispatch, not a load
        extra.append(f"compiled kernel loading {1e3 * loading:.0f} ms (first call)")
    return text + (f"; not included: {', '.join(extra)}" if extra else "")


def format_safe_interval(interval: tuple[float, float] | None, inside: bool) -> str:
    """One line on the approach speeds that keep every post-impact CoM velocity in the area."""
    if interval is None:
        return "safe approach speeds: none (no impact speed brings the CoM velocity into the area)"
    lo, hi = interval
    text = (
        f"safe approach speeds: [{lo:.3f}, {f'{hi:.3f}' if np.isfinite(hi) else 'unbounded'}] m/s"
    )
    if not inside:
        text += (
            " (the CoM velocity is outside the area: "
            "an impact in this range would bring it back inside)"
        )
    return text


def _vec(v: Iterable[float], digits: int = 3) -> str:
    """``(x, y, z)`` with ``digits`` decimals."""
    return "(" + ", ".join(f"{x:.{digits}f}" for x in v) + ")"


def format_analysis(analysis: Analysis) -> str:
    """Multi-line human-readable summary of one analysis."""
    a, st, sc = analysis.areas, analysis.stance, analysis.scenario
    lines = [f"{sc.name or 'scenario'}: {sc.description or ''}".rstrip(": ")]
    lines.append(
        f"  robot {st.robot.name}, mass {st.mass:.2f} kg, CoM {_vec(st.com)} m, "
        f"omega {a.omega:.4f} 1/s, "
        f"{len(st.contacts)} contact(s), torque limits {'on' if sc.torque_limits else 'off'}"
    )
    warnings = [f"  warning: {w}" for w in analysis.warnings]
    if not a.can_balance:
        lines.append("  CANNOT BALANCE: these contacts cannot hold the robot at rest (empty areas)")
        if a.reason is not None:
            lines.append(f"  reason: {a.reason}")
        lines.append(f"  {format_timings(analysis.timings)}")
        return "\n".join(lines + warnings)
    v = a.com_velocity_area
    lo, hi = v.vertices.min(axis=0), v.vertices.max(axis=0)
    lines.append(
        f"  CoM velocity area: {len(v.vertices)} vertices, {v.area:.4f} m^2/s^2, "
        f"x in [{lo[0]:.3f}, {hi[0]:.3f}] m/s, y in [{lo[1]:.3f}, {hi[1]:.3f}] m/s"
        + ("" if v.bounded else " (unbounded, clipped)")
    )
    z = a.zmp_area
    margin = f", shrunk by the ZMP margin {a.zmp_margin:g} m" if a.zmp_margin > 0 else ""
    lines.append(f"  ZMP support area: {len(z.vertices)} vertices, {z.area:.4f} m^2{margin}")
    lines.append(f"  pre-impact CoM velocity {_vec(analysis.com_velocity)} m/s: {analysis.verdict}")
    im = analysis.impact
    if im is not None:
        spec = im.model.spec
        lines.append(
            f"  impact at {spec.frame}, point {_vec(im.model.point)} m, "
            f"normal {_vec(im.model.normal, 2)}, mu {spec.friction:g}, "
            f"restitution [{spec.restitution[0]:g}, {spec.restitution[1]:g}], "
            f"N = {spec.cone_edges}"
        )
        com_v, zmp_v = im.max_contact_velocity, im.zmp_max_contact_velocity
        if im.com.status == "already_falling":
            # The ZMP criterion ignores the CoM velocity: its number is not comparable here.
            lines.append(
                f"  max contact velocity: none, the robot is already falling (CoM criterion 0); "
                f"ZMP criterion {format_speed(zmp_v)} (it ignores the CoM velocity)"
            )
        else:
            ratio = (
                f" (x{com_v / zmp_v:.1f})" if np.isfinite(com_v) and com_v > 0 and zmp_v > 0 else ""
            )
            lines.append(
                f"  max contact velocity: CoM criterion {format_speed(com_v)}, "
                f"ZMP criterion {format_speed(zmp_v)}{ratio}"
            )
        lines.append("  " + format_safe_interval(im.safe_interval, analysis.com_velocity_inside))
        if spec.reference_velocity is not None:
            target = (
                f"contact velocity {_vec(im.contact_velocity)} m/s (approach speed "
                f"{im.model.approach_speed(im.contact_velocity):.3f}, in the safe interval)"
                if im.contact_velocity is not None
                else "no safe contact velocity (no approach speed is safe)"
            )
            lines.append(f"  reference velocity {_vec(spec.reference_velocity)} m/s -> {target}")
        if im.qp is not None:
            lines.append(
                f"  paper's QP ({im.qp.status}): "
                f"approach speed {format_speed(im.qp.approach_speed)}"
            )
    lines.append(f"  {format_timings(analysis.timings)}")
    return "\n".join(lines + warnings)
