"""Figure layout of the areas figure: legends and notes never cover the areas, no quarter
of a figure left blank. Checked on the rendered figures' bounding boxes."""

from __future__ import annotations

import pytest

pytest.importorskip("matplotlib", reason="needs the plots extra (matplotlib)")

import impact_balance as ib
from impact_balance.plots import plot_areas


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 - 1 and b.x0 < a.x1 - 1 and a.y0 < b.y1 - 1 and b.y0 < a.y1 - 1


@pytest.mark.parametrize("name", ["kick_one_foot", "palm_push_ramp", "talos_three_contacts"])
def test_areas_figure_keeps_the_areas_clear(name):
    fig = plot_areas(ib.analyze(name))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.axison]  # not the legends' column
    boxes = [ax.get_window_extent(renderer) for ax in axes]
    notes = [ax.get_legend().get_window_extent(renderer) for ax in fig.axes if ax.get_legend()]
    notes += [t.get_window_extent(renderer) for ax in fig.axes for t in ax.texts]
    assert len(notes) >= 3  # two legends and the info box
    for note in notes:
        for box in boxes:
            assert not _overlap(note, box), (name, note, box)
    # Everything is on the figure, and the axes fill most of its height (no blank bands).
    W, H = fig.bbox.width, fig.bbox.height
    for note in notes:
        assert note.x0 >= -1 and note.y0 >= -1 and note.x1 <= W + 1 and note.y1 <= H + 1
    assert max(b.height for b in boxes) >= 0.5 * H
