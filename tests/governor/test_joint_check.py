"""The tick's joint check: the first joint outside its bounds, as numpy's comparison finds it."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.governor.governor import _first_outside


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(0, 40),
    spread=st.sampled_from([0.5, 1.0, 1.0 + 1e-12, 2.0]),
)
def test_first_outside_is_numpys_first_out_of_bounds_entry(seed, n, spread):
    rng = np.random.default_rng(seed)
    lower = rng.uniform(-2.0, 0.0, size=n)
    upper = lower + rng.uniform(0.1, 2.0, size=n)
    idx = rng.permutation(n + 7)[:n].astype(np.int64)
    q = rng.uniform(-3.0, 3.0, size=n + 7)
    middle, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    q[idx] = middle + spread * half * rng.uniform(-1.0, 1.0, size=n)
    if n:  # an entry exactly on a bound is inside
        q[idx[0]] = lower[0] if seed % 2 else upper[0]
    values = q[idx]
    outside = np.flatnonzero((values < lower) | (values > upper))
    want = int(outside[0]) if outside.size else -1
    assert _first_outside(q, idx, lower, upper) == want
