"""The figure pass: legends and notes inside their panels and clear of the data, no panel
mostly blank, a log scale where two criteria differ by orders of magnitude, the two phase
portraits of different stances telling them apart, velocity arrows with their scale."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("matplotlib", reason="needs the plots extra (matplotlib)")

from matplotlib.patches import FancyArrow

import impact_balance as ib
from impact_balance.plots import plot_areas, plot_friction_comparison, plot_impulse_set, plot_stance
from impact_balance.plots.save import save_figures
from impact_balance.plots.style import LOG_RATIO, needs_log_scale
from tests.helpers.figure_layout import assert_layout, data_fill, inside_axes


@pytest.fixture(scope="module")
def analyses():
    names = ["kick_one_foot", "palm_push_ramp", "talos_three_contacts", "palm_push_two_feet"]
    return {name: ib.analyze(name) for name in names}


@pytest.mark.parametrize("name", ["kick_one_foot", "palm_push_ramp", "talos_three_contacts"])
def test_areas_legend_and_note_inside_their_panels(analyses, name):
    fig = plot_areas(analyses[name])
    assert_layout(fig)  # nothing over data or a filled area, every text >= 8 pt
    zmp_ax, vel_ax = fig.axes
    assert inside_axes(fig, zmp_ax, zmp_ax.get_legend())
    (note,) = [t for t in vel_ax.texts if "maximum approach speed" in t.get_text()]
    assert inside_axes(fig, vel_ax, note)
    # No column beside the panels: the two panels are the figure's only axes, and they
    # span most of its width.
    fig.canvas.draw()
    width = sum(ax.get_window_extent().width for ax in fig.axes)
    assert width > 0.6 * fig.bbox.width


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(min_value=1e-6, max_value=1e3), min_size=2, max_size=8))
def test_log_scale_exactly_when_the_values_span_more_than_the_ratio(values):
    assert needs_log_scale(values) == (max(values) > LOG_RATIO * min(values))
    assert not needs_log_scale([*values[:1], math.nan, math.inf, 0.0][:2])  # one value left


def test_friction_bars_on_a_log_scale_where_the_zmp_maxima_are_a_hundredth():
    runs = [ib.analyze(n) for n in ("palm_push_mu010", "palm_push_mu040")]
    values = [r.impact.max_contact_velocity for r in runs]
    values += [r.impact.zmp_max_contact_velocity for r in runs]
    assert max(values) > LOG_RATIO * min(values)  # the case the scale is for
    fig = plot_friction_comparison(runs)
    assert_layout(fig)
    bar = fig.axes[1]
    assert bar.get_yscale() == "log"
    # Every bar visible: at least a tenth of the axis' height (in decades) above its bottom.
    lo, hi = bar.get_ylim()
    for rect in bar.patches:
        top = rect.get_y() + rect.get_height()
        assert (math.log10(top) - math.log10(lo)) > 0.1 * (math.log10(hi) - math.log10(lo))
    heights = sorted(r.get_y() + r.get_height() for r in bar.patches)
    np.testing.assert_allclose(heights, sorted(values), rtol=1e-12)
    assert inside_axes(fig, bar, bar.get_legend())


def test_impulse_set_jump_panel_uses_its_room(analyses):
    for name in ("palm_push_ramp", "kick_one_foot"):
        fig = plot_impulse_set(analyses[name])
        assert_layout(fig)
        jump = fig.axes[1]
        assert data_fill(fig, jump) > 0.5, name  # the set and the origin: most of the panel
        assert inside_axes(fig, jump, jump.get_legend())


def test_stance_velocity_arrows_keep_the_reference_visible_with_their_scale(analyses):
    analysis = analyses["palm_push_ramp"]  # capped: v_max 0.788 < reference 0.8 m/s
    im = analysis.impact
    fig = plot_stance(analysis)
    assert_layout(fig)
    labels = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert any("m per m/s" in t for t in labels)
    top = fig.axes[0]
    arrows = {str(a.get_label()): a for a in top.patches if isinstance(a, FancyArrow)}
    (ref,) = [a for label, a in arrows.items() if label.startswith("reference velocity")]
    (cap,) = [a for label, a in arrows.items() if label.startswith("capped at v_max")]
    assert ref.get_facecolor()[3] == 0  # hollow: the capped arrow inside it shows through
    assert cap.get_facecolor()[3] > 0 and cap.get_zorder() > ref.get_zorder()
    # Their lengths are the velocities at the stated scale (top view: x and y).
    from impact_balance.plots.stance import VELOCITY_SCALE

    for arrow, v in ((ref, im.model.spec.reference_velocity), (cap, im.contact_velocity)):
        xy = arrow.get_xy()
        reach = np.max(np.linalg.norm(xy - im.model.point[:2], axis=1))
        assert reach == pytest.approx(VELOCITY_SCALE * np.linalg.norm(np.asarray(v)[:2]), rel=1e-6)


def test_phase_portraits_of_two_stances_differ_by_more_than_their_titles(analyses, tmp_path):
    """palm_push_two_feet and kick_one_foot have the same ZMP chord (+-0.1 m): their saved
    portraits now show each stance's post-impact CoM velocities at v_max."""
    ranges = {}
    for name in ("palm_push_two_feet", "kick_one_foot"):
        analysis = analyses[name]
        paths = save_figures(analysis, tmp_path / name)
        assert any(p.name.endswith("_phase_portrait.png") for p in paths)
        im = analysis.impact
        post = im.model.post_impact_com_velocities(
            analysis.com_velocity[:2], im.max_contact_velocity
        )
        ranges[name] = (post[:, 0].min(), post[:, 0].max())
    a, b = ranges.values()
    assert abs(a[1] - b[1]) > 0.02  # the highest post-impact velocity along x differs
    from impact_balance.plots import analysis_phase_portrait, plot_phase_portrait

    analysis = analyses["kick_one_foot"]
    fig = plot_phase_portrait(
        analysis_phase_portrait(analysis), pre_impact=0.0, post_impact=ranges["kick_one_foot"]
    )
    assert_layout(fig)
    (segment,) = [
        line for line in fig.axes[0].get_lines() if line.get_label().startswith("post-impact")
    ]
    np.testing.assert_allclose(sorted(segment.get_ydata()), sorted(ranges["kick_one_foot"]))
