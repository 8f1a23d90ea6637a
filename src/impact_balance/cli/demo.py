"""``impact-balance demo``: the paper's studies on the bundled default robot (Talos)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = [
    "DEMO_SCENARIOS",
    "FIGURE_SUFFIXES",
    "FRICTION_SWEEP",
    "USES_KERNEL",
    "add_parser",
    "describe_figure",
    "run",
    "write_index",
]

USES_KERNEL = True

#: The bundled studies the demo runs (paper sec. VI).
DEMO_SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot")
#: The impact-friction sweep (paper Fig. miu-compare).
FRICTION_SWEEP = ("palm_push_mu010", "palm_push_mu024", "palm_push_mu040")


#: What each figure of an analysis shows, by the end of its file name (``<scenario><suffix>``).
FIGURE_SUFFIXES = {
    "_areas.png": "ZMP support area (left); CoM velocity area with the post-impact CoM velocity "
    "sets up to the maximum contact velocity and the limiting vertex (right)",
    "_stance.png": "top and side views of the stance: contacts and normals, CoM, ZMP support "
    "area, impact point, reference velocity and its cap at v_max",
    "_impulse_set.png": "impulse set in its friction cone (3D) and the CoM velocity jump set at "
    "the maximum contact velocity",
    "_phase_portrait.png": "sagittal LIPM phase portrait of the stance, its pre-impact CoM "
    "velocity and its post-impact CoM velocities at v_max",
}
#: What the demo's other figures show, by file name.
_DEMO_FIGURES = {
    "friction_comparison.png": "post-impact CoM velocity sets and maximum contact velocities "
    "(CoM and ZMP criteria) for impact frictions 0.1, 0.24 and 0.4 (paper Fig. miu-compare)",
    "phase_portrait.png": "the paper's LIPM phase portrait: CoM height 0.78 m, ZMP in "
    "[-0.13, 0.13] m, the stable standing region (paper Fig. lipm-pplane)",
}


def describe_figure(name: str) -> str:
    """One line on what the demo's figure file ``name`` shows (its scenario first)."""
    if name in _DEMO_FIGURES:
        return _DEMO_FIGURES[name]
    for suffix, text in FIGURE_SUFFIXES.items():
        if name.endswith(suffix):
            return f"{name.removesuffix(suffix)}: {text}"
    return "figure"


def write_index(out: Path, figures: list[Path]) -> Path:
    """Write ``out/index.md``: each figure as a link with one line on what it shows.

    Args:
        out: The figures' folder.
        figures: The figures written, in the order listed.

    Returns:
        The index's path.
    """
    lines = [
        "# impact-balance demo: figures",
        "",
        "The paper's studies on Talos (bundled scenarios), written by `impact-balance demo`.",
        "",
    ]
    lines += [f"- [{p.name}]({p.name}): {describe_figure(p.name)}" for p in figures]
    path = out / "index.md"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``demo`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    d = sub.add_parser(
        "demo", help="run the bundled studies on the default robot, print a report, write figures"
    )
    d.add_argument(
        "--out", default="impact-balance-demo", help="folder for the figures (default: %(default)s)"
    )
    d.add_argument("--no-plots", action="store_true", help="skip the figures")
    return ["demo"]


def run(args: argparse.Namespace) -> int:
    """Run ``demo`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.analysis.analyze import analyze
    from impact_balance.analysis.report import format_analysis, format_speed

    out = Path(args.out)
    if not args.no_plots:
        from impact_balance.cli.output_paths import check_output_folder

        check_output_folder(out, "--out")  # before the studies run, not after
    from impact_balance.cli.output_paths import writing

    print("impact-balance demo: the paper's studies on Talos (bundled scenarios)\n")
    written: list[Path] = []
    for name in DEMO_SCENARIOS:
        analysis = analyze(name, solve_qp=True)
        print(format_analysis(analysis) + "\n")
        if not args.no_plots:
            from impact_balance.plots import save_figures

            with writing("--out", out):
                written += save_figures(analysis, out)
    sweep = [analyze(name) for name in FRICTION_SWEEP]
    print("impact-friction sweep (palm push, two coplanar feet):")
    print(f"  {'mu':>5}  {'CoM criterion':>14}  {'ZMP criterion':>14}")
    for a in sweep:
        im = a.impact
        assert im is not None  # the friction sweep's scenarios have an impact
        print(
            f"  {im.model.spec.friction:>5.2f}  {format_speed(im.max_contact_velocity):>14}  "
            f"{format_speed(im.zmp_max_contact_velocity):>14}"
        )
    if not args.no_plots:
        from impact_balance.balance.lipm import phase_portrait
        from impact_balance.plots import plot_friction_comparison, plot_phase_portrait

        with writing("--out", out):
            out.mkdir(parents=True, exist_ok=True)
            for fig, fname in (
                (plot_friction_comparison(sweep), "friction_comparison.png"),
                (plot_phase_portrait(phase_portrait(0.78, (-0.13, 0.13))), "phase_portrait.png"),
            ):
                fig.savefig(out / fname, dpi=120)
                written.append(out / fname)
            index = write_index(out, written)
        print(f"\n{len(written)} figures written to {out}/ (what each shows: {index})")
    from impact_balance.balance.lipm import com_velocity_bounds

    bounds = [round(float(b), 4) for b in com_velocity_bounds(0.78, (-0.13, 0.13))]
    print(
        "LIPM check (paper sec. III-B): c_z 0.78 m, ZMP in [-0.13, 0.13] m -> CoM velocity in "
        f"[{bounds[0]}, {bounds[1]}] m/s"
    )
    return 0
