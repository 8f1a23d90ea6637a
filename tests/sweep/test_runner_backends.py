"""run_sweep's backends: inline for one worker, none for a finished folder, and an error in
the parent keeps what was written (the next run resumes)."""

from __future__ import annotations

import pytest

pytest.importorskip("pyarrow", reason="needs the sweep extra (pyarrow)")

from impact_balance.sweep import make_plan, read_results, run_sweep, sweep_spec_from_dict


@pytest.fixture(scope="module")
def plan():
    spec = sweep_spec_from_dict(
        {
            "base": "palm_push_two_feet",
            "axes": [{"path": "impact.friction", "range": [0.1, 0.4], "count": 4}],
            "chunk_size": 2,
        }
    )
    return make_plan(spec)


def test_inline_then_nothing_left(plan, tmp_path):
    out = tmp_path / "out"
    first = run_sweep(plan, out, workers=1, progress=False)
    assert (first.backend, first.workers) == ("inline", 1)
    assert first.complete and first.chunks_computed == plan.n_chunks == 2
    assert first.points_computed == plan.n_points == 4
    again = run_sweep(plan, out, workers=1, progress=False)
    assert (again.backend, again.workers) == ("none", 0)
    assert again.complete and again.chunks_before == 2 and again.chunks_computed == 0
    assert read_results(out).num_rows == 4


def test_an_error_in_the_parent_keeps_the_written_chunks(plan, tmp_path):
    out = tmp_path / "out"

    def fail(chunk):
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        run_sweep(plan, out, workers=1, progress=False, on_chunk=fail)
    resumed = run_sweep(plan, out, workers=1, progress=False)
    assert resumed.chunks_before == 1 and resumed.chunks_computed == 1 and resumed.complete
    assert sorted(read_results(out).column("point").to_pylist()) == [0, 1, 2, 3]
