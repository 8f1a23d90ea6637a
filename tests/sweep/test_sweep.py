"""Sweeps: spec validation, axis paths, sampling, evaluation against analyze(), resume,
the same rows on 1 and 2 workers and a Dask LocalCluster, invalid points as rows, summary."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

pytest.importorskip("dask", reason="needs the sweep extra (Dask)")
pytest.importorskip("distributed", reason="needs the sweep extra (Dask distributed)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")
pytest.importorskip("pyarrow.parquet", reason="needs the logs or sweep extra (pyarrow)")

import pyarrow as pa
import pyarrow.parquet as pq
import yaml
from scipy.stats import qmc

from impact_balance import analyze, cli
from impact_balance.exceptions import ImpactBalanceError, SweepError, UnknownPathError
from impact_balance.scenario import read_mapping, scenario_from_dict, scenario_path
from impact_balance.sweep import (
    Evaluator,
    bundled_sweeps,
    load_sweep_spec,
    make_plan,
    plan_sweep,
    read_results,
    run_sweep,
    sweep_spec_from_dict,
)
from impact_balance.sweep.paths import parse_path, set_path
from impact_balance.sweep.summary import summarize
from tests.helpers.cli import strict_json

BASE = "palm_push_two_feet"


def plan_of(axes, **extra):
    return make_plan(sweep_spec_from_dict({"base": BASE, "axes": axes, **extra}))


def rows(plan, chunk=None):
    ev = Evaluator(plan)
    chunks = range(plan.n_chunks) if chunk is None else [chunk]

    return pa.concat_tables([ev.evaluate_chunk(c) for c in chunks]).to_pandas()


def base_raw():
    raw = read_mapping(scenario_path(BASE))
    raw["name"] = BASE
    return raw


# -- spec validation -----------------------------------------------------------------------
@pytest.mark.parametrize(
    "axes, field, needle",
    [
        ([{"path": "impact.frictio", "values": [0.1]}], "axes[0].path", "impact.friction"),
        ([{"path": "impct.friction", "values": [0.1]}], "axes[0].path", "contacts"),
        ([{"path": "contacts[5].friction", "values": [0.1]}], "axes[0].path", "has 2 items"),
        (
            [{"path": "joints.arm_right_44_joint", "values": [0.1]}],
            "axes[0].path",
            "joints.arm_right_4_joint",
        ),
        ([{"path": "impact.frame", "range": [0, 1], "count": 3}], "axes[0].path", "not a number"),
        ([{"path": "impact..friction", "values": [0.1]}], "axes[0].path", "not a key path"),
        ([{"path": "impact.friction"}], "axes[0]", "either values"),
        ([{"path": "impact.friction", "range": [1.0, 0.0], "count": 3}], "axes[0]", "lo <= hi"),
        ([{"path": "impact.friction", "range": [0, 1]}], "axes[0]", "needs count"),
        (
            [{"direction": "impact.friction", "azimuth": {"values": [0]}}],
            "axes[0].direction",
            "not a 3-vector",
        ),
        (
            [{"posture": {"frame": "no_such_frame", "z": {"values": [1.0]}}}],
            "axes[0].posture.frame",
            "valid frames",
        ),
        ([{"posture": {"w": {"values": [1.0]}}}], "axes[0].posture.w", "unknown key"),
        (
            [{"path": "impact.friction", "values": [0.1], "colour": 1}],
            "axes[0].colour",
            "unknown key",
        ),
        ([], "axes", "non-empty"),
    ],
)
def test_bad_spec_names_the_field(axes, field, needle):
    with pytest.raises(ImpactBalanceError) as info:
        plan_of(axes)
    assert info.value.field == field
    assert needle in str(info.value)


def test_unknown_path_lists_valid_keys():
    with pytest.raises(UnknownPathError) as info:
        plan_of([{"path": "impact.restitutoin[1]", "values": [0.1]}])
    assert "impact.restitution" in info.value.valid and "impact.friction" in info.value.valid
    assert "did you mean impact.restitution" in str(info.value)


def test_sampling_and_top_level_errors():
    with pytest.raises(SweepError, match="needs samples"):
        sweep_spec_from_dict(
            {
                "base": BASE,
                "axes": [{"path": "impact.friction", "range": [0, 1]}],
                "sampling": "sobol",
            }
        )
    with pytest.raises(SweepError) as info:
        sweep_spec_from_dict(
            {"base": BASE, "axes": [{"path": "impact.friction", "values": [0.1]}], "chunksize": 3}
        )
    assert info.value.field == "chunksize"
    with pytest.raises(ImpactBalanceError) as info:
        plan_of([{"path": "impact.friction", "values": [0.1]}], base="no_such_scenario")
    assert "palm_push_two_feet" in info.value.valid  # the valid names are carried
    assert "valid scenarios" in str(info.value)


# -- paths and points -----------------------------------------------------------------------
def test_hostile_sweep_file_is_refused_quickly(tmp_path):
    """A sweep file is read like a scenario file: an alias bomb ("billion laughs") is refused
    in milliseconds with one message naming the file, not expanded."""
    import time

    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefgh", "bcdefghi", strict=True)
    )
    path = tmp_path / "bomb.yaml"
    path.write_text(bomb + "base: palm_push_two_feet\naxes: []\n")
    t = time.perf_counter()
    with pytest.raises(SweepError) as info:
        load_sweep_spec(path)
    assert time.perf_counter() - t < 5.0
    assert (
        info.value.field == "sweep" and "100000" in str(info.value) and len(str(info.value)) < 400
    )


def test_set_path_copies_only_the_path():
    base = {
        "impact": {"restitution": (0.0, 0.2), "friction": 0.24},
        "contacts": [{"friction": 0.7}, {"friction": 0.7}],
    }
    out = set_path(base, parse_path("impact.restitution[1]"), 0.5)
    out = set_path(out, parse_path("contacts[1].friction"), 0.3)
    assert out["impact"]["restitution"] == [0.0, 0.5] and out["contacts"][1]["friction"] == 0.3
    assert base["impact"]["restitution"] == (0.0, 0.2) and base["contacts"][1]["friction"] == 0.7
    assert out["contacts"][0] is base["contacts"][0]  # untouched branches are shared


def test_grid_order_and_values():
    plan = plan_of(
        [
            {"path": "impact.friction", "range": [0.1, 0.3], "count": 3},
            {"path": "joints.arm_right_4_joint", "values": [-1.4, -1.3]},
        ],
        chunk_size=4,
    )
    # The stance dimension (a joint) varies slowest, then the impact one.
    assert [d.name for d in plan.dims] == ["joints.arm_right_4_joint", "impact.friction"]
    assert plan.n_points == 6 and plan.n_chunks == 2
    pts = plan.points(0, 6)
    assert pts["joints.arm_right_4_joint"] == [-1.4, -1.4, -1.4, -1.3, -1.3, -1.3]
    assert np.allclose(pts["impact.friction"], [0.1, 0.2, 0.3] * 2)


def test_qmc_points_are_scipy_sobol_scaled():
    plan = plan_of(
        [
            {"path": "impact.friction", "range": [0.1, 0.5]},
            {"path": "com_velocity[0]", "range": [-0.2, 0.2]},
        ],
        sampling={"method": "sobol", "samples": 64, "seed": 3},
    )
    u = qmc.Sobol(2, rng=3).random(64)
    pts = plan.points(0, 64)
    assert np.allclose(pts["impact.friction"], 0.1 + 0.4 * u[:, 0])
    assert np.allclose(pts["com_velocity[0]"], -0.2 + 0.4 * u[:, 1])
    assert (
        plan.digest
        == plan_of(
            [
                {"path": "impact.friction", "range": [0.1, 0.5]},
                {"path": "com_velocity[0]", "range": [-0.2, 0.2]},
            ],
            sampling={"method": "sobol", "samples": 64, "seed": 3},
        ).digest
    )


# -- evaluation against the pipeline --------------------------------------------------------
def _analyze_with(**changes):
    raw = base_raw()
    for path, value in changes.items():
        raw = set_path(raw, parse_path(path), value)
    return analyze(scenario_from_dict(raw))


def test_rows_match_analyze():
    plan = plan_of(
        [
            {"path": "joints.arm_right_4_joint", "values": [-1.384306, -1.2]},
            {"path": "impact.friction", "values": [0.1, 0.24]},
            {"path": "impact.restitution[1]", "values": [0.2, 0.6]},
            {"path": "contacts[0].friction", "values": [0.5]},
        ]
    )
    df = rows(plan)
    assert len(df) == 8 and (df["status"] == "ok").all()
    for _, r in df.iterrows():
        a = _analyze_with(
            **{
                "joints.arm_right_4_joint": r["joints.arm_right_4_joint"],
                "impact.friction": r["impact.friction"],
                "impact.restitution[1]": r["impact.restitution[1]"],
                "contacts[0].friction": 0.5,
            }
        )
        assert r["max_contact_velocity"] == pytest.approx(a.impact.max_contact_velocity, rel=1e-12)
        assert r["zmp_max_contact_velocity"] == pytest.approx(
            a.impact.zmp_max_contact_velocity, rel=1e-12
        )
        assert r["limiting_edge"] == a.impact.com.limiting_edge
        assert r["com_velocity_area"] == pytest.approx(a.areas.com_velocity_area.area, rel=1e-12)
        assert r["verdict"] == "balanced"


def test_direction_axis_matches_the_normal():
    plan = plan_of(
        [
            {
                "direction": "impact.normal",
                "azimuth": {"values": [180.0, 160.0]},
                "elevation": {"values": [0.0, 20.0]},
            }
        ]
    )
    df = rows(plan)
    for _, r in df.iterrows():
        az, el = (
            math.radians(r["impact.normal.azimuth"]),
            math.radians(r["impact.normal.elevation"]),
        )
        n = [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]
        a = _analyze_with(**{"impact.normal": n})
        assert r["max_contact_velocity"] == pytest.approx(a.impact.max_contact_velocity, rel=1e-9)
    # azimuth 180, elevation 0 is the bundled normal [-1, 0, 0]: the reference maximum.
    first = df[
        (df["impact.normal.azimuth"] == 180.0) & (df["impact.normal.elevation"] == 0.0)
    ].iloc[0]
    assert first["max_contact_velocity"] == pytest.approx(
        analyze(BASE).impact.max_contact_velocity, rel=1e-9
    )


def test_posture_axis_moves_the_point_and_keeps_the_feet():
    plan = plan_of(
        [{"posture": {"y": {"values": [-0.25, -0.15]}, "z": {"values": [1.0]}}}], chunk_size=2
    )
    df = rows(plan)
    assert (df["status"] == "ok").all()
    assert np.allclose(df["impact_y"], [-0.25, -0.15], atol=2e-4) and np.allclose(
        df["impact_z"], 1.0, atol=2e-4
    )
    assert (df["ik_residual"] < 2e-4).all()
    # Independent check of the IK answer: the feet did not move, the palm is where asked.
    ev = Evaluator(plan)
    base = ev.base_scenario.build_stance(ev.robot)
    entry = ev._stance_entry(ev.base_scenario, {"posture.y": -0.15, "posture.z": 1.0}, {})
    for name in ("left_sole_link", "right_sole_link"):
        assert np.allclose(
            entry.stance.frame_pose(name).translation, base.frame_pose(name).translation, atol=2e-4
        )
    palm = entry.stance.frame_pose("gripper_right_base_link") * ev._posture_offset
    assert np.allclose(palm.translation[1:], [-0.15, 1.0], atol=2e-4)


# -- invalid points are rows -----------------------------------------------------------------
def test_invalid_points_become_rows():
    plan = plan_of(
        [
            {"path": "impact.friction", "values": [-0.1, 0.24]},
            {"path": "com_velocity[0]", "values": [0.0, 5.0]},
        ]
    )
    df = rows(plan).set_index(["impact.friction", "com_velocity[0]"])
    bad = df.loc[(-0.1, 0.0)]
    assert (
        bad["status"] == "invalid"
        and "impact.friction" in bad["message"]
        and math.isnan(bad["max_contact_velocity"])
    )
    assert (
        df.loc[(0.24, 5.0), "status"] == "already_falling"
        and df.loc[(0.24, 5.0), "verdict"] == "falling"
    )
    assert df.loc[(0.24, 5.0), "max_contact_velocity"] == 0.0
    assert df.loc[(0.24, 0.0), "status"] == "ok"


def test_unreachable_and_bad_stance_become_rows():
    plan = plan_of([{"posture": {"z": {"values": [1.0, 3.0]}, "max_iterations": 30}}], chunk_size=2)
    df = rows(plan)
    assert list(df["status"]) == ["ok", "unreachable"]
    assert "inverse kinematics" in df["message"][1]
    plan = plan_of([{"path": "plane_height", "values": [0.0, 2.0]}])
    df = rows(plan)
    assert list(df["status"]) == ["ok", "invalid"] and "plane_height" in df["message"][1]


# -- execution: resume, workers, Dask ---------------------------------------------------------
SMALL = [
    {"path": "impact.friction", "range": [0.0, 0.6], "count": 9},
    {"path": "impact.restitution[1]", "values": [0.0, 0.5, 1.0]},
    {"path": "joints.torso_1_joint", "values": [0.0, 0.1]},
]


def test_resume_computes_only_missing_chunks(tmp_path):
    plan = plan_of(SMALL, chunk_size=7)
    assert plan.n_chunks == 8
    first: list[int] = []
    r1 = run_sweep(
        plan, tmp_path / "out", workers=1, progress=False, stop_after=3, on_chunk=first.append
    )
    assert r1.interrupted and first == [0, 1, 2]
    assert len(read_results(tmp_path / "out")) == 21
    second: list[int] = []
    r2 = run_sweep(plan, tmp_path / "out", workers=1, progress=False, on_chunk=second.append)
    assert r2.complete and r2.chunks_before == 3 and second == [3, 4, 5, 6, 7]
    resumed = read_results(tmp_path / "out")
    whole = run_sweep(plan, tmp_path / "whole", workers=1, progress=False)
    assert whole.complete
    assert resumed.equals(read_results(tmp_path / "whole"))
    assert list(resumed.column("point").to_pylist()) == list(range(plan.n_points))
    # A different sweep is refused in the same folder.
    with pytest.raises(SweepError, match="different sweep"):
        run_sweep(plan_of(SMALL, chunk_size=5), tmp_path / "out", workers=1, progress=False)


@pytest.mark.slow
def test_same_rows_on_one_two_workers_and_dask(tmp_path):
    from distributed import Client, LocalCluster

    plan = plan_of(SMALL, chunk_size=10)
    run_sweep(plan, tmp_path / "one", workers=1, progress=False)
    two = run_sweep(plan, tmp_path / "two", workers=2, progress=False)
    assert two.backend == "processes" and two.workers == 2
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        dask = run_sweep(plan, tmp_path / "dask", scheduler=client, progress=False)
    assert dask.backend == "dask"
    one = read_results(tmp_path / "one").drop_columns([]).replace_schema_metadata(None)
    for other in ("two", "dask"):
        assert read_results(tmp_path / other).replace_schema_metadata(None).equals(one)
    assert (
        pq.read_schema(next((tmp_path / "one" / "parts").glob("*.parquet"))).metadata[
            b"impact_balance.sweep"
        ]
        == plan.digest.encode()
    )


# -- summary and command line ------------------------------------------------------------------
def test_summary_ranks_and_is_strict_json(tmp_path):
    plan = plan_of(
        [
            {"path": "impact.friction", "values": [0.0, 0.24, -1.0]},
            {
                "direction": "impact.normal",
                "azimuth": {"values": [180.0]},
                "elevation": {"values": [0.0, 90.0]},
            },
        ]
    )
    run_sweep(plan, tmp_path / "s", workers=1, progress=False)
    s = summarize(tmp_path / "s", top=2)
    df = read_results(tmp_path / "s").to_pandas()
    # A vertical impact without friction moves the CoM vertically only: unbounded, ranked best, null
    # in JSON.
    assert s["status_counts"]["unbounded"] == 1 and s["status_counts"]["invalid"] == 2
    assert (
        s["best"][0]["max_contact_velocity"] is None
        and s["best"][0]["impact.normal.elevation"] == 90.0
    )
    ok = df[df["status"] == "ok"]
    assert s["worst"][0]["max_contact_velocity"] == pytest.approx(ok["max_contact_velocity"].min())
    strict_json(json.dumps(s, allow_nan=False))


def test_cli_sweep_and_summary(tmp_path, capsys):
    spec = tmp_path / "s.yaml"
    spec.write_text(
        yaml.safe_dump(
            {
                "description": "friction curve",
                "base": BASE,
                "chunk_size": 4,
                "axes": [{"path": "impact.friction", "range": [0.1, 0.4], "count": 7}],
            }
        )
    )
    out = tmp_path / "out"
    rc = cli.main(
        ["sweep", str(spec), "--out", str(out), "--workers", "1", "--no-progress", "--json"]
    )
    captured = capsys.readouterr()
    assert rc == 0
    doc = strict_json(captured.out)
    assert doc["rows"] == 7 and doc["complete"] and doc["figures"] and (out / "figures").is_dir()
    # The maximum falls with the impact friction (as in the paper): worst at the highest friction.
    assert doc["worst"][0]["impact.friction"] == pytest.approx(0.4)
    rc = cli.main(["sweep", "--summary", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "best:" in text and "worst:" in text and "7 of 7 points" in text
    spec.write_text(
        yaml.safe_dump({"base": BASE, "axes": [{"path": "impact.frictoin", "values": [0.1]}]})
    )
    rc = cli.main(["sweep", str(spec), "--out", str(tmp_path / "o2")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "axes[0].path" in err and "impact.friction" in err


def test_bundled_sweeps_plan():
    names = bundled_sweeps()
    assert {"wall_palm_push", "impact_friction_restitution"} <= set(names)
    for name in names:
        plan = plan_sweep(name)
        assert plan.n_points > 100


def test_list_values_and_unexpected_errors_are_rows(monkeypatch):
    plan = plan_of([{"path": "contacts[0].size", "values": [[0.2, 0.1], [0.3, 0.1], [0.2]]}])
    df = rows(plan)
    assert (
        list(df["status"]) == ["ok", "ok", "invalid"] and df["contacts[0].size"][1] == "[0.3, 0.1]"
    )
    ref = _analyze_with(**{"contacts[0].size": [0.3, 0.1]})
    assert df["max_contact_velocity"][1] == pytest.approx(
        ref.impact.max_contact_velocity, rel=1e-12
    )
    # A bug deep in one point (here a simulated one) is that point's row, not the end of the chunk.
    import impact_balance.sweep.evaluate as evaluate

    calls = {"n": 0}
    real = evaluate.impact_answer

    def flaky(*args):
        calls["n"] += 1
        if calls["n"] == 2:
            raise FloatingPointError("simulated")
        return real(*args)

    monkeypatch.setattr(evaluate, "impact_answer", flaky)
    df = rows(plan_of([{"path": "impact.friction", "values": [0.1, 0.2, 0.3]}]))
    assert (
        list(df["status"]) == ["ok", "error", "ok"]
        and df["message"][1] == "FloatingPointError: simulated"
    )


def test_posture_at_the_base_point_gives_the_base_answer():
    ref = analyze(BASE)
    x, y, z = ref.impact.model.point
    plan = plan_of(
        [
            {
                "posture": {
                    "x": {"values": [float(x)]},
                    "y": {"values": [float(y)]},
                    "z": {"values": [float(z)]},
                }
            }
        ]
    )
    r = rows(plan).iloc[0]
    assert r["status"] == "ok" and r["ik_residual"] < 1e-6
    assert r["max_contact_velocity"] == pytest.approx(ref.impact.max_contact_velocity, rel=1e-6)


def test_base_file_relative_to_the_sweep_file(tmp_path):
    from impact_balance.sweep import load_sweep_spec

    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mine.yaml").write_text(
        "extends: palm_push_two_feet\ncom_velocity: [0.05, 0.0]\n"
    )
    (tmp_path / "sub" / "s.yaml").write_text(
        "base: mine.yaml\naxes:\n  - {path: 'com_velocity[1]', values: [0.0]}\n"
    )
    plan = make_plan(load_sweep_spec(tmp_path / "sub" / "s.yaml"))
    r = rows(plan).iloc[0]
    ref = _analyze_with(com_velocity=[0.05, 0.0])
    assert r["max_contact_velocity"] == pytest.approx(ref.impact.max_contact_velocity, rel=1e-12)
    assert ref.impact.max_contact_velocity != pytest.approx(
        analyze(BASE).impact.max_contact_velocity, rel=1e-6
    )


def test_impact_offset_axis_moves_the_impact_point():
    plan = plan_of([{"path": "impact.offset.position[1]", "values": [0.0, 0.05]}])
    df = rows(plan)
    for _, r in df.iterrows():
        a = _analyze_with(**{"impact.offset.position[1]": r["impact.offset.position[1]"]})
        assert np.allclose(
            [r["impact_x"], r["impact_y"], r["impact_z"]], a.impact.model.point, atol=1e-12
        )
        assert r["max_contact_velocity"] == pytest.approx(a.impact.max_contact_velocity, rel=1e-12)
    assert abs(df["impact_y"][1] - df["impact_y"][0]) > 0.04  # the point moved


def test_rows_honour_the_velocity_margin_as_analyze_does():
    """A sweep of velocity_margin gives analyze()'s maximum at each margin (and it decreases)."""
    margins = [0.0, 0.01, 0.03]
    df = rows(plan_of([{"path": "velocity_margin", "values": margins}]))
    assert list(df["status"]) == ["ok"] * len(margins)
    expected = [_analyze_with(velocity_margin=d).impact.max_contact_velocity for d in margins]
    assert list(df["max_contact_velocity"]) == pytest.approx(expected, rel=1e-12)
    assert expected[0] > expected[1] > expected[2]
