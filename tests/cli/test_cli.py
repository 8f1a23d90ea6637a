"""The command line: ``impact-balance {demo, analyze, phase-portrait, scenarios, robots}``.

Most tests call ``cli.main`` in-process (fast); a few run real processes for exit statuses,
``python -m impact_balance`` and the installed entry point.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import impact_balance
from impact_balance import cli
from tests.helpers.cli import assert_one_line_error, run_process, strict_json
from tests.helpers.cli import run_cli as run
from tests.helpers.extras import needs_extra

PNG = b"\x89PNG\r\n\x1a\n"
BUNDLED_DIR = Path(impact_balance.__file__).parent / "scenarios"
BUNDLED_NAMES = sorted(p.stem for p in BUNDLED_DIR.glob("*.yaml"))


def assert_png(path: Path) -> None:
    assert path.is_file(), path
    assert path.stat().st_size > 1000, path
    assert path.read_bytes()[:8] == PNG, path


# -- listings ---------------------------------------------------------------------------------
def test_bundled_scenarios_exist():
    assert "palm_push_two_feet" in BUNDLED_NAMES
    assert len(BUNDLED_NAMES) >= 5


def test_scenarios_lists_every_bundled_name(capsys):
    rc, out, err = run(capsys, "scenarios")
    assert rc == 0 and err == ""
    listed = [line.split()[0] for line in out.splitlines() if line.strip()]
    assert listed == BUNDLED_NAMES
    # each with its one-line description
    assert all(len(line.split(None, 1)) == 2 for line in out.splitlines() if line.strip())


def test_robots_lists_talos_and_g1(capsys):
    rc, out, err = run(capsys, "robots")
    assert rc == 0 and err == ""
    names = [line.split()[0] for line in out.splitlines() if line.strip()]
    assert {"talos", "g1"} <= set(names)


def test_python_dash_m_scenarios():
    proc = run_process("scenarios")
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    for name in BUNDLED_NAMES:
        assert re.search(rf"^{name}\s", proc.stdout, re.M), name


def test_entry_point_robots():
    exe = shutil.which("impact-balance") or str(Path(sys.executable).with_name("impact-balance"))
    if not Path(exe).is_file():
        pytest.skip("impact-balance entry point not installed")
    proc = run_process("robots", exe=[exe])
    assert proc.returncode == 0, proc.stderr
    assert "talos" in proc.stdout and "g1" in proc.stdout


# -- argparse errors --------------------------------------------------------------------------
def test_unknown_command_is_argparse_error(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["bogus"])
    assert info.value.code == 2
    _, err = capsys.readouterr()
    assert "invalid choice" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["bogus"], "invalid choice: 'bogus'"),
        (["analyze"], "required: scenario"),
        (["validate", "kick_one_foot", "--joints", "foo"], "--joints: invalid choice"),
        (
            ["push-test", "palm_push_ramp", "--directions", "many"],
            "--directions: invalid int value",
        ),
    ],
)
def test_usage_errors_are_one_line(capsys, argv, needle):
    """A usage error follows the project's rule too: one line naming the option, exit 2."""
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and needle in err and "--help" in err


def test_no_command_is_argparse_error(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main([])
    assert info.value.code == 2


def test_unknown_command_subprocess():
    proc = run_process("bogus")
    assert proc.returncode == 2
    assert "invalid choice" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_phase_portrait_missing_required_argument(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["phase-portrait", "--com-height", "0.78"])
    assert info.value.code == 2
    assert "--zmp-range" in capsys.readouterr().err


# -- analyze ----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def palm_json() -> tuple[str, dict]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = cli.main(["analyze", "palm_push_two_feet", "--json"])
    assert rc == 0
    return buf.getvalue(), strict_json(buf.getvalue())


def test_analyze_json_is_one_object(palm_json):
    text, d = palm_json
    assert len([line for line in text.splitlines() if line.strip()]) == 1
    assert isinstance(d, dict)


def test_analyze_json_keys_and_shapes(palm_json):
    _, d = palm_json
    for key in (
        "omega",
        "mass",
        "com",
        "com_velocity_area",
        "zmp_area",
        "impact",
        "verdict",
        "can_balance",
    ):
        assert key in d, key
    assert d["verdict"] == "balanced" and d["can_balance"] is True
    assert 80 < d["mass"] < 100  # Talos, ~90 kg
    assert len(d["com"]) == 3
    assert d["omega"] == pytest.approx(
        math.sqrt(d["gravity"] / (d["com"][2] - d["plane_height"])), rel=1e-9
    )

    area = d["com_velocity_area"]
    V = np.asarray(area["vertices"])
    assert V.ndim == 2 and V.shape[1] == 2 and len(V) >= 3
    G, h = np.asarray(area["halfplanes"]["G"]), np.asarray(area["halfplanes"]["h"])
    assert G.ndim == 2 and G.shape[1] == 2 and h.shape == (len(G),)
    Z = np.asarray(d["zmp_area"]["vertices"])
    assert Z.ndim == 2 and Z.shape[1] == 2 and len(Z) >= 3

    im = d["impact"]
    n_edges = im["cone_edges"]
    assert n_edges == 16
    for key in (
        "max_contact_velocity",
        "contact_velocity",
        "impulse_vertices",
        "post_impact_com_velocities",
        "zmp_max_contact_velocity",
    ):
        assert key in im, key
    assert len(im["contact_velocity"]) == 3
    assert np.asarray(im["impulse_vertices"]).shape == (2 * n_edges, 3)
    assert np.asarray(im["post_impact_com_velocities"]).shape == (2 * n_edges, 2)


def test_analyze_json_consistency(palm_json):
    _, d = palm_json
    G = np.asarray(d["com_velocity_area"]["halfplanes"]["G"])
    h = np.asarray(d["com_velocity_area"]["halfplanes"]["h"])
    V = np.asarray(d["com_velocity_area"]["vertices"])
    im = d["impact"]
    vmax, zmax = im["max_contact_velocity"], im["zmp_max_contact_velocity"]
    assert im["status"] == "ok"

    # the area's own vertices satisfy its half-planes
    assert np.all(V @ G.T <= h + 1e-9)
    # at the maximum speed every post-impact CoM velocity is inside the area ...
    post = np.asarray(im["post_impact_com_velocities"])
    assert im["evaluated_at_approach_speed"] == pytest.approx(vmax)
    slack = post @ G.T - h
    assert slack.max() <= 1e-9
    # ... and one of them is on the boundary (the maximum is tight)
    assert slack.max() >= -1e-9

    # the CoM criterion allows more than the ZMP one, both positive
    assert vmax > zmax > 0

    # the commanded contact velocity respects the maximum approach speed -n.v
    n = np.asarray(im["normal"])
    v = np.asarray(im["contact_velocity"])
    assert -(n @ v) <= vmax + 1e-12
    # reference 0.8 m/s along +x exceeds the maximum: capped exactly at it
    assert np.asarray(im["reference_velocity"]) @ -n > vmax
    assert -(n @ v) == pytest.approx(vmax, abs=1e-12)

    # impulses push along the normal (inside the cone: positive normal component)
    iota = np.asarray(im["impulse_vertices"])
    assert np.all(iota @ n > 0)


def test_analyze_text_report(capsys):
    rc, out, err = run(capsys, "analyze", "palm_push_two_feet")
    assert rc == 0 and err == ""
    assert "max contact velocity" in out
    assert "balanced" in out


def test_analyze_file_path(capsys):
    rc, out, _ = run(capsys, "analyze", str(BUNDLED_DIR / "palm_push_two_feet.yaml"), "--json")
    assert rc == 0
    assert strict_json(out)["scenario"] == "palm_push_two_feet"


@needs_extra("plots")
def test_analyze_writes_plots(tmp_path, capsys):
    out_dir = tmp_path / "figs" / "nested"
    rc, out, err = run(capsys, "analyze", "palm_push_two_feet", "--plots", str(out_dir))
    assert rc == 0 and err == ""
    pngs = sorted(out_dir.glob("*.png"))
    assert len(pngs) >= 3
    for p in pngs:
        assert_png(p)
        assert f"figure: {p}" in out


@needs_extra("plots")
@pytest.mark.slow
def test_analyze_json_with_plots_keeps_stdout_json(tmp_path, capsys):
    rc, out, _ = run(capsys, "analyze", "palm_push_two_feet", "--json", "--plots", str(tmp_path))
    assert rc == 0
    strict_json(out)
    assert list(tmp_path.glob("*.png"))


def test_analyze_qp_json(capsys):
    rc, out, _ = run(capsys, "analyze", "palm_push_two_feet", "--json", "--qp")
    assert rc == 0
    im = strict_json(out)["impact"]
    assert "qp" in im
    assert im["qp"]["approach_speed"] == pytest.approx(im["max_contact_velocity"], rel=1e-4)


def test_analyze_unknown_scenario_exit_2(capsys):
    rc, out, err = run(capsys, "analyze", "no_such_scenario")
    assert out == ""
    assert_one_line_error(rc, err, "impact-balance: error:", "no_such_scenario")


# -- phase-portrait ---------------------------------------------------------------------------
def test_phase_portrait_json_bounds(capsys):
    rc, out, err = run(
        capsys, "phase-portrait", "--com-height", "0.78", "--zmp-range", "-0.13", "0.13", "--json"
    )
    assert rc == 0 and err == ""
    d = strict_json(out)
    assert d["omega"] == pytest.approx(math.sqrt(9.81 / 0.78), rel=1e-12)
    lo, hi = d["com_velocity_bounds"]
    assert lo == pytest.approx(-0.4610, abs=1e-4)
    assert hi == pytest.approx(0.4610, abs=1e-4)
    assert d["zmp_range"] == [-0.13, 0.13]


def test_phase_portrait_paper_gravity(capsys):
    """The paper's +-0.4608 m/s corresponds to g = 9.8."""
    rc, out, _ = run(
        capsys,
        "phase-portrait",
        "--com-height",
        "0.78",
        "--zmp-range",
        "-0.13",
        "0.13",
        "--gravity",
        "9.8",
        "--json",
    )
    assert rc == 0
    d = strict_json(out)
    assert d["omega"] == pytest.approx(math.sqrt(9.8 / 0.78), rel=1e-12)
    assert d["com_velocity_bounds"][0] == pytest.approx(-0.4608, abs=1e-4)
    assert d["com_velocity_bounds"][1] == pytest.approx(0.4608, abs=1e-4)


def test_phase_portrait_text(capsys):
    rc, out, _ = run(
        capsys, "phase-portrait", "--com-height", "0.78", "--zmp-range", "-0.13", "0.13"
    )
    assert rc == 0
    assert "-0.4610" in out and "0.4610" in out


@pytest.mark.parametrize(
    "argv, needles",
    [
        (["--com-height", "0", "--zmp-range", "-0.13", "0.13"], ["com_height", "0.0"]),
        (["--com-height", "-0.5", "--zmp-range", "-0.13", "0.13"], ["com_height", "-0.5"]),
        (["--com-height", "nan", "--zmp-range", "-0.13", "0.13"], ["com_height", "nan"]),
        (["--com-height", "0.78", "--zmp-range", "0.13", "-0.13"], ["zmp_range", "[0.13, -0.13]"]),
        (
            ["--com-height", "0.78", "--zmp-range", "-0.13", "0.13", "--gravity", "0"],
            ["gravity", "0.0"],
        ),
    ],
)
def test_phase_portrait_bad_values_exit_2(capsys, argv, needles):
    rc, out, err = run(capsys, "phase-portrait", *argv)
    assert out == ""
    assert_one_line_error(rc, err, "impact-balance: error:", *needles)


def test_phase_portrait_bad_value_subprocess():
    proc = run_process("phase-portrait", "--com-height", "0", "--zmp-range", "-0.13", "0.13")
    assert_one_line_error(proc.returncode, proc.stderr, "com_height")


@needs_extra("plots")
def test_phase_portrait_plot(tmp_path, capsys):
    target = tmp_path / "sub" / "pp.png"
    rc, out, _ = run(
        capsys,
        "phase-portrait",
        "--com-height",
        "0.78",
        "--zmp-range",
        "-0.13",
        "0.13",
        "--plot",
        str(target),
    )
    assert rc == 0
    assert_png(target)
    assert str(target) in out


# -- demo -------------------------------------------------------------------------------------
@needs_extra("plots")
@pytest.mark.slow
def test_demo(tmp_path, capsys):
    rc, out, err = run(capsys, "demo", "--out", str(tmp_path))
    assert rc == 0, err
    assert "Traceback" not in err
    for name in cli.DEMO_SCENARIOS:
        assert f"{name}:" in out, name
    assert out.count("max contact velocity:") == len(cli.DEMO_SCENARIOS)
    # friction sweep table: header then one row per friction
    assert "impact-friction sweep" in out
    for mu in ("0.10", "0.24", "0.40"):
        assert re.search(
            rf"^\s+{re.escape(mu)}\s+\d+\.\d{{3}} m/s\s+\d+\.\d{{3}} m/s$", out, re.M
        ), mu
    assert re.search(r"CoM velocity in \[-0\.461\d*, 0\.461\d*\] m/s", out)
    pngs = sorted(tmp_path.glob("*.png"))
    assert (tmp_path / "friction_comparison.png") in pngs
    assert (tmp_path / "phase_portrait.png") in pngs
    for name in cli.DEMO_SCENARIOS:
        assert any(p.name.startswith(name) for p in pngs), name
    for p in pngs:
        assert_png(p)
    assert f"{len(pngs)} figures written" in out
    # The index lists every figure once, with what it shows.
    index = (tmp_path / "index.md").read_text()
    for p in pngs:
        assert index.count(f"[{p.name}]({p.name}): ") == 1, p.name
    assert "index.md" in out
