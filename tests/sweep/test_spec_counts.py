"""Sweep files: the point count from the file alone, the sampling's points, a range's bounds."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("pyarrow", reason="needs the sweep extra (pyarrow)")

from impact_balance.sweep.spec import (
    QMC_METHODS,
    SAMPLING_METHODS,
    Dim,
    Sampling,
    sweep_spec_from_dict,
)


def spec_with(axes, **extra):
    return sweep_spec_from_dict({"base": "palm_push_two_feet", "axes": axes, **extra})


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=30), min_size=1, max_size=4))
def test_grid_point_count_is_the_product_of_the_counts(counts):
    axes = [
        {"path": f"impact.restitution[{k % 2}]", "range": [0.0, 1.0], "count": n}
        for k, n in enumerate(counts)
    ]
    spec = spec_with(axes)
    assert spec.dimension_sizes() == counts
    assert spec.point_count() == math.prod(counts)


def test_a_range_without_count_has_no_point_count():
    spec = spec_with([{"path": "impact.friction", "range": [0.0, 1.0]}])
    assert spec.dimension_sizes() == [None]
    assert spec.point_count() is None


def test_quasi_random_point_count_is_the_samples():
    spec = spec_with(
        [{"path": "impact.friction", "range": [0.0, 1.0]}],
        sampling={"method": "halton", "samples": 17, "seed": 2},
    )
    assert spec.sampling.points == 17
    assert spec.point_count() == 17


def test_a_grid_has_no_sample_count():
    with pytest.raises(ValueError, match="grid"):
        _ = Sampling().points


def test_bounds_of_a_range_and_of_values():
    assert Dim(range=(0.25, 0.5), count=3).bounds == (0.25, 0.5)
    with pytest.raises(ValueError, match="values"):
        _ = Dim(values=[1.0, 2.0]).bounds


def test_sampling_methods_are_the_grid_and_the_quasi_random_ones():
    assert SAMPLING_METHODS == ("grid", *QMC_METHODS)
    assert QMC_METHODS == ("sobol", "halton", "lhs")
    for method in QMC_METHODS:
        assert Sampling(method=method, samples=4).points == 4
