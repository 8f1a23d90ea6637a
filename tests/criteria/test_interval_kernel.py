"""speed_interval (compiled: interval_kernel) gives the numbers of the array expression it
replaced, to the last digit, on random margins and rates (zero rates, negative margins, ties)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from impact_balance.criteria.linear_exit import BOUNDARY_TOLERANCE, speed_interval


def reference(margins: np.ndarray, rates: np.ndarray, tol: float = BOUNDARY_TOLERANCE):
    """The numpy expression speed_interval was, kept here as the independent computation."""
    scale = tol * max(1.0, float(np.abs(rates).max(initial=0.0)))
    positive, negative = rates > scale, rates < -scale
    flat = ~(positive | negative)
    m = np.broadcast_to(margins, rates.shape)
    if (m[flat] < -tol).any():
        return None
    inside = bool((margins >= -tol).all())
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = m / rates
    hi = float(
        np.min(np.maximum(ratio[positive], 0.0) if inside else ratio[positive], initial=np.inf)
    )
    lo = 0.0 if inside else max(0.0, float(np.max(ratio[negative], initial=0.0)))
    if lo > hi * (1.0 + 1e-12) + tol:
        return None
    return lo, max(lo, hi)


values = st.one_of(
    st.floats(-2.0, 2.0, allow_nan=False),
    st.sampled_from([0.0, 1e-12, -1e-12, 1e-11, -1e-11, 0.5, -0.5]),
)


@settings(max_examples=400, deadline=None)
@given(
    data=st.data(),
    n_v=st.integers(1, 8),
    n_c=st.integers(1, 8),
)
def test_interval_is_the_array_expression(data, n_v, n_c):
    margins = data.draw(arrays(np.float64, n_c, elements=values))
    rates = data.draw(arrays(np.float64, (n_v, n_c), elements=values))
    got, want = speed_interval(margins, rates), reference(margins, rates)
    assert (got is None) == (want is None)
    if got is not None:
        assert got == want  # exact, floats compared bit for bit (no tolerance)
