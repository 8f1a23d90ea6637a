"""``angular_momentum_damping_time`` in ``analyze``: off is the paper, on is the extended map."""

from __future__ import annotations

import numpy as np
import pytest

from impact_balance import analyze
from impact_balance.constants import MAX_ANGULAR_MOMENTUM_DAMPING_TIME
from impact_balance.exceptions import ScenarioError
from impact_balance.impact.angular_momentum import angular_momentum_gain
from impact_balance.scenario import load_scenario
from tests.helpers.cli import assert_one_line_error, run_cli, strict_json

ABOVE_THE_COM = ["palm_push_two_feet", "talos_side_slope", "g1_two_feet"]


def _without_timings(analysis):
    out = analysis.to_dict()
    out.pop("timings_ms")
    return out


@pytest.mark.parametrize("name", ["palm_push_two_feet", "kick_one_foot"])
def test_off_is_the_paper_and_on_keeps_the_paper_keys(name):
    scenario = load_scenario(name)
    assert scenario.angular_momentum_damping_time is None
    off = analyze(scenario)
    assert off.impact.extended is None and off.impact.default is off.impact.com
    assert "angular_momentum_damping_time" not in off.to_dict()
    assert "angular_momentum" not in off.to_dict()["impact"]
    on = analyze(scenario.replace(angular_momentum_damping_time=0.1))
    a, b = _without_timings(off)["impact"], _without_timings(on)["impact"]
    for key in ("max_contact_velocity", "status", "zmp_max_contact_velocity", "W", "point"):
        assert a[key] == b[key]
    assert b["angular_momentum"]["damping_time"] == 0.1
    assert b["default_max_contact_velocity"] == on.impact.extended.max_contact_velocity
    # tau -> inf tends to the paper's answer
    far = analyze(scenario.replace(angular_momentum_damping_time=MAX_ANGULAR_MOMENTUM_DAMPING_TIME))
    assert far.impact.extended.max_contact_velocity == pytest.approx(
        off.impact.max_contact_velocity, rel=1e-4
    )


def test_an_impact_below_the_com_keeps_the_papers_maximum():
    """A kick (below the CoM) leaves an angular momentum whose effective velocity is smaller;
    the contacts may never remove it, so the paper's answer stands."""
    scenario = load_scenario("kick_one_foot")
    paper = analyze(scenario).impact.max_contact_velocity
    for tau in (0.0, 0.1):
        ext = analyze(scenario.replace(angular_momentum_damping_time=tau)).impact.extended
        assert ext.max_contact_velocity == pytest.approx(paper, rel=1e-9)


@pytest.mark.parametrize("name", ABOVE_THE_COM)
def test_an_impact_above_the_com_lowers_the_maximum_the_more_the_faster_it_is_removed(name):
    scenario = load_scenario(name)
    paper = analyze(scenario).impact.max_contact_velocity
    at_once = analyze(scenario.replace(angular_momentum_damping_time=0.0)).impact
    slow = analyze(scenario.replace(angular_momentum_damping_time=0.1)).impact
    assert at_once.model.point[2] > analyze(scenario).stance.com[2]
    assert at_once.extended.max_contact_velocity <= slow.extended.max_contact_velocity <= paper
    assert at_once.extended.max_contact_velocity < paper


@pytest.mark.parametrize("name", ["palm_push_two_feet", "kick_one_foot", "g1_two_feet"])
@pytest.mark.parametrize("tau", [0.0, 0.05])
def test_the_extended_maximum_puts_the_effective_velocities_on_the_boundary(name, tau):
    """Independent of the kernel: v_eff = c0 + (iota + S((p - c) x iota) / (h (1 + w tau))) / m."""
    scenario = load_scenario(name).replace(angular_momentum_damping_time=tau, velocity_margin=0.01)
    a = analyze(scenario)
    im = a.impact
    s = im.extended.max_contact_velocity
    iota = im.model.impulse_vertices(s)
    L = np.cross(im.model.point - a.stance.com, iota)
    h = a.areas.gravity / a.areas.omega**2
    assert angular_momentum_gain(a.areas.omega, a.areas.gravity, tau) == pytest.approx(
        1 / (h * (1 + a.areas.omega * tau)), rel=1e-12
    )
    v_eff = iota[:, :2] + np.column_stack([L[:, 1], -L[:, 0]]) / (h * (1 + a.areas.omega * tau))
    c0 = np.asarray(scenario.com_velocity)[None, :]
    v_eff = c0 + v_eff / a.stance.mass
    v_paper = c0 + iota[:, :2] / a.stance.mass
    G, off = a.areas.com_velocity_area.halfplanes
    # Both ends of the removal rate (1/tau and never) must be captured: the paper's and the
    # effective velocities together, none outside the eroded area and one on its boundary.
    slack = (off - 0.01)[None, :] - np.vstack([v_eff, v_paper]) @ G.T
    assert slack.min() == pytest.approx(0.0, abs=1e-9)
    assert im.contact_velocity is None or -im.model.normal @ im.contact_velocity <= s + 1e-12


@pytest.mark.parametrize("value", [-0.1, "soon", 1e9])
def test_a_bad_damping_time_names_the_field(value):
    with pytest.raises(ScenarioError, match="angular_momentum_damping_time"):
        load_scenario("palm_push_two_feet").replace(angular_momentum_damping_time=value)


def test_the_cli_option(capsys):
    rc, out, _ = run_cli(
        capsys, "analyze", "palm_push_two_feet", "--json", "--angular-momentum-damping-time", "0"
    )
    assert rc == 0
    doc = strict_json(out)
    assert doc["angular_momentum_damping_time"] == 0.0
    impact = doc["impact"]
    assert impact["default_max_contact_velocity"] < impact["max_contact_velocity"]
    assert impact["contact_velocity"][0] == pytest.approx(impact["default_max_contact_velocity"])
    rc, out, _ = run_cli(
        capsys, "analyze", "palm_push_two_feet", "--json", "--angular-momentum-damping-time", "off"
    )
    assert rc == 0 and "angular_momentum_damping_time" not in strict_json(out)
    for bad in ("-1", "controller", "nan", "x"):
        rc, _, err = run_cli(
            capsys, "analyze", "palm_push_two_feet", "--angular-momentum-damping-time", bad
        )
        assert_one_line_error(rc, err, "--angular-momentum-damping-time")
