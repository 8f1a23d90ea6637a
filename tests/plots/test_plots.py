"""Figures: each plotting function returns a readable Figure; save_figures writes PNGs."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

pytest.importorskip("matplotlib", reason="needs the plots extra (matplotlib)")

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import impact_balance as ib
from impact_balance.plots import (
    __all__ as plots_all,
)
from impact_balance.plots import (
    analysis_phase_portrait,
    plot_areas,
    plot_friction_comparison,
    plot_impulse_set,
    plot_phase_portrait,
    plot_stance,
    save_figures,
)
from impact_balance.scenario import scenario_from_dict, scenario_path

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def analysis() -> ib.Analysis:
    return ib.analyze("palm_push_two_feet")


@pytest.fixture(scope="module")
def no_impact() -> ib.Analysis:
    raw = yaml.safe_load(scenario_path("palm_push_two_feet").read_text())
    raw.pop("impact")
    raw["name"] = "no_impact"
    return ib.analyze(scenario_from_dict(raw))


def _check_axes(fig: Figure, n_axes: int) -> None:
    assert isinstance(fig, Figure)
    assert isinstance(fig.canvas, FigureCanvasAgg)
    # Not the frameless column of legends and notes (3D axes keep axison False: their own axes).
    panels = [ax for ax in fig.axes if ax.axison or ax.name == "3d"]
    assert len(panels) == n_axes
    assert fig.get_suptitle() or all(ax.get_title() for ax in panels)
    for ax in panels:
        assert ax.get_title(), "every panel has a title"
        assert ax.get_xlabel() and ax.get_ylabel(), "every panel has labelled axes"
        assert "(" in ax.get_xlabel() and "(" in ax.get_ylabel(), "axis labels carry units"


def _legend_texts(ax) -> list[str]:
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend is not None else []


def _velocity_legend(fig: Figure) -> list[str]:
    """The entries of the areas figure's CoM velocity legend (under both panels)."""
    return [t.get_text() for leg in fig.legends for t in leg.get_texts()]


def _note(fig: Figure) -> str:
    """The note inside the CoM velocity panel (the maxima, the impact's parameters)."""
    return " ".join(t.get_text() for t in fig.axes[1].texts)


def _line(ax, label: str):
    found = [line for line in ax.get_lines() if line.get_label() == label]
    assert found, f"no line labelled {label!r}"
    return found[0]


def test_exports() -> None:
    for name in (
        "plot_areas",
        "plot_impulse_set",
        "plot_friction_comparison",
        "plot_phase_portrait",
        "plot_stance",
        "save_figures",
    ):
        assert name in plots_all


def test_plot_areas(analysis: ib.Analysis) -> None:
    fig = plot_areas(analysis)
    _check_axes(fig, 2)
    zmp_ax, vel_ax = fig.axes[:2]
    assert "(m)" in zmp_ax.get_xlabel() and "(m/s)" in vel_ax.get_xlabel()
    assert zmp_ax.get_aspect() == 1.0 and vel_ax.get_aspect() == 1.0
    labels = _velocity_legend(fig)
    vmax = analysis.impact.max_contact_velocity
    assert any(f"v_max = {vmax:.3g} m/s" in t for t in labels)
    # The five sets: the one at v_max, and one entry for the lighter four.
    assert sum("post-impact set" in t for t in labels) == 2
    assert any("0.2, 0.4, 0.6, 0.8 x v_max" in t for t in labels)
    assert len(vel_ax.patches) >= 2 * 5  # each set: a fill and an outline
    assert any("falls" in t for t in labels), "the reference speed 0.8 m/s exceeds v_max"
    # The limiting vertex is marked where the model puts it, on the area's boundary.
    star = next(
        line for line in vel_ax.get_lines() if line.get_label().startswith("limiting vertex")
    )
    point = np.array([star.get_xdata()[0], star.get_ydata()[0]])
    lim = analysis.impact.com
    expected = analysis.impact.model.post_impact_com_velocities(analysis.com_velocity, vmax)[
        lim.limiting_vertex
    ]
    np.testing.assert_allclose(point, expected)
    assert abs(analysis.areas.com_velocity_area.margins(point)[0]) < 1e-8
    text = _note(fig)
    assert f"CoM criterion: {vmax:.3g} m/s" in text and "ZMP criterion" in text
    # The legend of the ZMP panel and the note are inside their panels.
    fig.canvas.draw()
    for ax, box in ((zmp_ax, zmp_ax.get_legend()), (vel_ax, vel_ax.texts[0])):
        assert ax.get_window_extent().contains(*box.get_window_extent().p0)
        assert ax.get_window_extent().contains(*box.get_window_extent().p1)


def test_plot_areas_without_impact(no_impact: ib.Analysis) -> None:
    fig = plot_areas(no_impact)
    _check_axes(fig, 2)
    assert not any("post-impact" in t for t in _velocity_legend(fig))
    assert "no impact" in _note(fig)


def test_plot_impulse_set(analysis: ib.Analysis) -> None:
    fig = plot_impulse_set(analysis)
    _check_axes(fig, 2)
    ax3, ax2 = fig.axes
    assert ax3.name == "3d" and "N s" in ax3.get_zlabel() and "N s" in ax3.get_xlabel()
    assert "m/s" in ax2.get_xlabel()
    n = analysis.impact.model.cone.shape[1]
    dots = [line for line in ax2.get_lines() if line.get_label().startswith("vertices")]
    assert sum(len(line.get_xdata()) for line in dots) == 2 * n
    assert ax3.collections, "the polytope faces are drawn"


def test_plot_impulse_set_without_impact(no_impact: ib.Analysis) -> None:
    fig = plot_impulse_set(no_impact)
    assert len(fig.axes) == 2
    assert all(ax.get_title() for ax in fig.axes)


def test_plot_friction_comparison(analysis: ib.Analysis, no_impact: ib.Analysis) -> None:
    low = ib.analyze("palm_push_mu010")
    fig = plot_friction_comparison([analysis, low, no_impact])
    _check_axes(fig, 2)
    labels = _legend_texts(fig.axes[0])
    assert f"μ = 0.1: v_max = {low.impact.max_contact_velocity:.3g} m/s" in labels
    assert f"μ = 0.24: v_max = {analysis.impact.max_contact_velocity:.3g} m/s" in labels
    assert len(fig.axes[1].patches) == 4  # two criteria x two frictions
    with pytest.raises(ValueError):
        plot_friction_comparison([no_impact])


def test_plot_phase_portrait_marks_paper_bounds() -> None:
    portrait = ib.phase_portrait(0.78, (-0.13, 0.13))
    fig = plot_phase_portrait(portrait)
    _check_axes(fig, 1)
    ax = fig.axes[0]
    marks = _line(ax, "CoM velocity bounds at c = 0: -0.4610 and +0.4610 m/s")
    np.testing.assert_allclose(marks.get_xdata(), [0.0, 0.0])
    np.testing.assert_allclose(sorted(marks.get_ydata()), [-0.461, 0.461], atol=5e-4)
    assert ax.collections, "the stable standing region is shaded"


def test_analysis_phase_portrait(analysis: ib.Analysis) -> None:
    portrait = analysis_phase_portrait(analysis)
    area = analysis.areas.com_velocity_area.vertices
    # Along x through the CoM, the bounds are the CoM velocity area's chord (rectangular here).
    np.testing.assert_allclose(
        portrait.com_velocity_bounds, [area[:, 0].min(), area[:, 0].max()], atol=1e-6
    )


@pytest.mark.parametrize("fixture", ["analysis", "no_impact"])
def test_plot_stance(fixture: str, request: pytest.FixtureRequest) -> None:
    a = request.getfixturevalue(fixture)
    fig = plot_stance(a)
    _check_axes(fig, 2)
    top, side = fig.axes
    assert (top.get_xlabel(), top.get_ylabel(), side.get_ylabel()) == ("x (m)", "y (m)", "z (m)")
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert "CoM" in labels and "robot (joint origins)" in labels
    assert ("impact point" in labels) == (a.impact is not None)


def test_save_figures(analysis: ib.Analysis, no_impact: ib.Analysis, tmp_path) -> None:
    written = save_figures(analysis, tmp_path / "out")
    names = sorted(p.name for p in written)
    assert names == sorted(
        f"palm_push_two_feet_{k}.png" for k in ("areas", "stance", "impulse_set", "phase_portrait")
    )
    for path in written:
        data = path.read_bytes()
        assert path.parent == tmp_path / "out" and data.startswith(PNG) and len(data) > 10_000
    written = save_figures(no_impact, tmp_path / "out")
    assert sorted(p.name for p in written) == sorted(
        f"no_impact_{k}.png" for k in ("areas", "stance", "phase_portrait")
    )
    assert all(p.stat().st_size > 10_000 for p in written)
