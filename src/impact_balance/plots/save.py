"""Write all the figures of one analysis as PNG files."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from impact_balance.analysis.analyze import Analysis
from impact_balance.analysis.result import Diagnostic
from impact_balance.plots.areas import plot_areas
from impact_balance.plots.impulse import plot_impulse_set
from impact_balance.plots.phase import analysis_phase_portrait, plot_phase_portrait
from impact_balance.plots.stance import plot_stance
from impact_balance.plots.style import DPI

__all__ = ["figure_prefix", "save_figures"]


def figure_prefix(analysis: Analysis) -> str:
    """File-name prefix of an analysis' figures: its scenario name, made file-system safe."""
    name = analysis.scenario.name or "scenario"
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "scenario"


def _sagittal_velocities(analysis: Analysis) -> tuple[float, tuple[float, float] | None]:
    """The CoM velocities along world x drawn on the sagittal phase portrait, m/s.

    Returns:
        The pre-impact one, and the range of the post-impact ones at the maximum contact
        velocity (None without a finite maximum).
    """
    c0 = np.asarray(analysis.com_velocity[:2], dtype=float)
    im = analysis.impact
    if im is None or not im.com.is_finite:
        return float(c0[0]), None
    post = im.model.post_impact_com_velocities(c0, im.max_contact_velocity)[:, 0]
    return float(c0[0]), (float(post.min()), float(post.max()))


def save_figures(
    analysis: Analysis, out_dir: str | Path, dpi: int = DPI, skipped: list[Diagnostic] | None = None
) -> list[Path]:
    """Write the figures of an analysis as PNG files.

    The files are ``<scenario>_areas.png``, ``_stance.png``, ``_phase_portrait.png`` and, with
    an impact, ``_impulse_set.png``. The phase portrait is the sagittal one of the stance
    (:func:`analysis_phase_portrait`) with the stance's pre-impact CoM velocity and the range of
    its post-impact CoM velocities at the maximum contact velocity along x; it is skipped when
    the ZMP support area has no chord through the CoM along x.

    Args:
        analysis: The analysis.
        out_dir: The folder (created if needed).
        dpi: The resolution, dots per inch.
        skipped: If given, receives a ``figure_skipped`` :class:`Diagnostic` per figure
            skipped, saying why.

    Returns:
        The paths written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    prefix = figure_prefix(analysis)
    figures: list[tuple[str, Figure]] = [
        ("areas", plot_areas(analysis)),
        ("stance", plot_stance(analysis)),
    ]
    if analysis.impact is not None:
        figures.append(("impulse_set", plot_impulse_set(analysis)))
    try:
        portrait = analysis_phase_portrait(analysis, axis=0)
    except ValueError as exc:
        portrait = None
        if skipped is not None:
            skipped.append(
                Diagnostic("figure_skipped", "plots", f"no {prefix}_phase_portrait.png: {exc}")
            )
    if portrait is not None:
        com = analysis.areas.com
        title = (
            f"{prefix}: sagittal LIPM phase portrait, CoM height {portrait.com_height:.3g} m, "
            f"g = {analysis.areas.gravity:.4g} m/s², ω = {portrait.omega:.4f} 1/s\n"
            f"ZMP in [{portrait.zmp_range[0]:+.3g}, {portrait.zmp_range[1]:+.3g}] m about the CoM: "
            f"the chord of the ZMP support area along x\nthrough the CoM (at y = {com[1]:.3f} m); "
            f"other slices of the area give other bounds"
        )
        pre, post = _sagittal_velocities(analysis)
        figures.append(
            (
                "phase_portrait",
                plot_phase_portrait(
                    portrait,
                    title=title,
                    pre_impact=pre,
                    post_impact=post,
                    post_label="post-impact CoM velocities at v_max",
                ),
            )
        )
    written = []
    for name, fig in figures:
        path = out / f"{prefix}_{name}.png"
        try:
            fig.savefig(path, dpi=dpi)
        except OSError as exc:  # the image writer names no file: say which one failed
            if exc.filename is None:
                exc.filename = str(path)
            raise
        written.append(path)
    return written
