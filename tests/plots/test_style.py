"""The figures' shared style: an Agg figure with the wider layout margin, limits that fit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("matplotlib", reason="needs the plots extra (matplotlib)")

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.layout_engine import ConstrainedLayoutEngine

from impact_balance.plots.style import fmt_speed, new_figure, set_limits


def test_new_figure_is_constrained_on_agg_with_the_wider_margin():
    fig = new_figure(4.0, 3.0)
    engine = fig.get_layout_engine()
    assert isinstance(engine, ConstrainedLayoutEngine)
    assert engine.get()["w_pad"] == 0.06 and engine.get()["h_pad"] == 0.06
    assert isinstance(fig.canvas, FigureCanvasAgg)
    assert tuple(fig.get_size_inches()) == (4.0, 3.0)


def test_speeds_as_text():
    assert fmt_speed(0.123456) == "0.123 m/s"
    assert fmt_speed(math.inf) == fmt_speed(None) == fmt_speed(math.nan) == "unbounded"


coords = st.floats(min_value=-100, max_value=100, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(coords, coords), min_size=1, max_size=12))
def test_limits_contain_every_point(points):
    fig = new_figure(4.0, 3.0)
    ax = fig.add_subplot()
    pts = np.array(points, dtype=float)
    set_limits(ax, [pts, np.array([[np.nan, 0.0]])], margin=0.1, min_span=0.05, min_ratio=0.3)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert np.all((pts[:, 0] >= x0) & (pts[:, 0] <= x1))
    assert np.all((pts[:, 1] >= y0) & (pts[:, 1] <= y1))
    # Each span is at least min_span and at least min_ratio of the other.
    w, h = x1 - x0, y1 - y0
    assert w >= 0.05 and h >= 0.05
    assert w >= 0.3 * h - 1e-9 and h >= 0.3 * w - 1e-9
