"""Every figure is readable: each is rendered and checked by :mod:`tests.helpers.figure_layout` (no
text or legend outside the canvas, no overlapping texts, no legend or note over data, axis labels
with units), plus what each figure must say.

The simulation, sweep and video figures run short trials (a few hundredths of a second).
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib", reason="needs the plots extra (matplotlib)")

import impact_balance as ib
from impact_balance.plots import (
    analysis_phase_portrait,
    plot_areas,
    plot_friction_comparison,
    plot_impulse_set,
    plot_phase_portrait,
    plot_stance,
    save_figures,
)
from impact_balance.robot.robot import example_robot_data_root
from tests.helpers.figure_layout import assert_layout, largest_gap, layout_problems

SCENARIOS = [
    "palm_push_ramp",
    "kick_one_foot",
    "talos_three_contacts",
    "g1_two_feet",
    "palm_push_two_feet",
]
SIMPLE = example_robot_data_root() / "simple_humanoid_description"


@pytest.fixture(scope="module")
def analyses():
    return {name: ib.analyze(name) for name in SCENARIOS}


@pytest.fixture(scope="module")
def cannot_balance(tmp_path_factory):
    """simple_humanoid on its ankles: the torque limits stop it (WAIST_P x1.4)."""
    path = tmp_path_factory.mktemp("simple") / "simple.yaml"
    path.write_text(
        f"name: simple_ankles\nrobot: {{urdf: {SIMPLE / 'urdf' / 'simple_humanoid.urdf'}, "
        f"srdf: {SIMPLE / 'srdf' / 'simple_humanoid.srdf'}, standing: half_sitting}}\n"
        "contacts:\n  - {frame: l_ankle, friction: 0.7, size: [0.2, 0.1]}\n"
        "  - {frame: r_ankle, friction: 0.7, size: [0.2, 0.1]}\n"
    )
    return ib.analyze(str(path))


def test_layout_checks_catch_the_defects_they_are_for():
    """The checks fail on a figure with each defect (so a pass means something)."""
    from impact_balance.plots.style import new_figure

    fig = new_figure(4, 3)
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], label="data")
    ax.legend(loc="center")  # over the line
    ax.set_xlabel("time")  # no unit
    ax.set_ylabel("y (m)")
    ax.text(0.5, 0.5, "note over the line")
    ax.text(1.3, 0.5, "a note off the canvas", transform=ax.transAxes)
    problems = "\n".join(layout_problems(fig))
    assert "legend covers" in problems
    assert "'time' has no unit" in problems
    assert "outside the canvas" in problems
    assert "note over the line" in problems and "overlaps legend" in problems
    # A 6 pt annotation, and a legend over a filled area.
    fig = new_figure(4, 3)
    ax = fig.subplots()
    ax.fill_between([0, 1], [0, 0], [1, 1], label="band")
    ax.legend(loc="center")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.annotate("tiny", (0.5, 0.1), fontsize=6)
    problems = "\n".join(layout_problems(fig))
    assert "'tiny' is 6 pt" in problems
    assert "legend lies over a filled area" in problems


@pytest.mark.parametrize("name", SCENARIOS)
def test_areas(analyses, name):
    fig = plot_areas(analyses[name])
    assert_layout(fig)
    assert largest_gap(fig)[0] < 0.06


def test_areas_keep_the_vmax_set_visible_under_the_reference(analyses):
    """palm_push_ramp: the reference (0.8 m/s) is 1.5 % above v_max; its set is an outline on
    top of the v_max set, not a filled set hiding it, and the legend says they nearly coincide."""
    fig = plot_areas(analyses["palm_push_ramp"])
    ax = fig.axes[1]
    ref = [p for p in ax.patches if "reference" in str(p.get_label())]
    vmax = [p for p in ax.patches if str(p.get_label()).startswith("post-impact set at v_max")]
    assert ref and vmax
    assert all(p.get_fill() is False or p.get_facecolor()[3] == 0 for p in ref)
    assert min(p.get_zorder() for p in ref) > max(p.get_zorder() for p in vmax)
    assert "nearly the same set" in ref[0].get_label()


def test_cannot_balance_figure_says_why_and_hides_nothing(cannot_balance):
    fig = plot_areas(cannot_balance)
    assert_layout(fig)  # the message boxes cover neither the CoM projection nor the velocity
    assert "WAIST_P x1.4" in fig.get_suptitle()
    texts = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "WAIST_P x1.4" in texts and "torque limits" in texts
    left, right = fig.axes[:2]
    assert any(line.get_label() == "CoM projection" for line in left.lines)
    assert any(line.get_label() == "pre-impact CoM velocity" for line in right.lines)


@pytest.mark.parametrize("name", SCENARIOS)
def test_stance(analyses, name):
    fig = plot_stance(analyses[name])
    assert_layout(fig)
    assert largest_gap(fig)[0] < 0.08, "a blank band between the views"


def test_stance_top_view_shows_vertical_contact_normals(analyses):
    fig = plot_stance(analyses["palm_push_two_feet"])
    top = fig.axes[0]
    symbols = [line for line in top.lines if str(line.get_marker()).startswith("$\\odot")]
    assert len(symbols) == 2  # one per flat foot: an arrow seen end-on would be invisible
    labels = fig.legends[0].get_texts()
    assert any("contact normals" in t.get_text() for t in labels)


@pytest.mark.parametrize("name", SCENARIOS)
def test_impulse_set(analyses, name):
    fig = plot_impulse_set(analyses[name])
    assert_layout(fig)
    two_d = fig.axes[1]
    fig.canvas.draw()
    # The 2D panel fills its half: at least 60 % of the figure's height.
    assert two_d.get_window_extent().height >= 0.6 * fig.bbox.height


@pytest.mark.parametrize("name", SCENARIOS[:3])
def test_phase_portrait(analyses, name, tmp_path):
    portrait = analysis_phase_portrait(analyses[name])
    fig = plot_phase_portrait(portrait)
    assert_layout(fig)  # the trajectories cross no label and run under no legend
    assert "g = 9.81 m/s²" in fig.axes[0].get_title()
    legend = " ".join(t.get_text() for t in fig.legends[0].get_texts())
    lo, hi = portrait.com_velocity_bounds
    assert f"{lo:+.4f}" in legend and f"{hi:+.4f}" in legend


def test_phase_portrait_paper_gravity():
    from impact_balance.balance.lipm import phase_portrait

    fig = plot_phase_portrait(phase_portrait(0.78, (-0.13, 0.13), 9.8))
    assert_layout(fig)
    assert "g = 9.8 m/s²" in fig.axes[0].get_title()
    assert "+0.4608" in " ".join(t.get_text() for t in fig.legends[0].get_texts())


@pytest.mark.slow
def test_saved_figures_titles_give_gravity(analyses, tmp_path):
    save_figures(analyses["kick_one_foot"], tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "kick_one_foot_areas.png",
        "kick_one_foot_impulse_set.png",
        "kick_one_foot_phase_portrait.png",
        "kick_one_foot_stance.png",
    ]


def test_friction_comparison():
    runs = [ib.analyze(f"palm_push_mu0{k}") for k in ("10", "24", "40")]
    assert_layout(plot_friction_comparison(runs))


# -- simulation ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def trials():
    pytest.importorskip("mujoco")
    from impact_balance.sim import build_model
    from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
    from impact_balance.sim.trials.measure import measure

    out = {}
    for joints in ("rigid", "servo"):
        sim = build_model("kick_one_foot", joints)
        record = run_trial(sim, TrialOptions(0.5, after=0.03))
        out[joints] = (sim, record, measure(sim, record, 0.5))
    return out


@pytest.mark.parametrize("joints", ["rigid", "servo"])
def test_simulation_time_series(trials, joints):
    from impact_balance.plots.simulation import plot_time_series

    fig = plot_time_series(trials[joints][2], f"kick_one_foot: {joints}")
    assert_layout(fig)  # the legend is below: the force transient is clear
    legend = " ".join(t.get_text() for t in fig.legends[0].get_texts())
    assert "impact window" in legend
    assert ("the contacts carry no force" in legend) == (joints == "rigid")


@pytest.mark.parametrize("joints", ["rigid", "servo"])
def test_simulation_jump(trials, joints):
    from impact_balance.plots.simulation import _flat, plot_jump_on_sets

    result = trials[joints][2]
    fig = plot_jump_on_sets(result, f"kick_one_foot: {joints}")
    assert_layout(fig)
    assert largest_gap(fig)[1] < 0.08, "blank bands above or below the panels"
    legend = " ".join(t.get_text() for t in fig.legends[0].get_texts())
    flat = [name for name, p in result.predicted.items() if _flat(p.com_velocity_jumps)]
    assert ("seen from above" in legend) == bool(flat)


def test_flat_set_test():
    from impact_balance.plots.simulation import _flat

    t = np.linspace(0.0, 1.0, 8)
    assert _flat(np.column_stack([t, 2 * t + 1e-4 * np.sin(7 * t)]))
    assert not _flat(np.column_stack([np.cos(6 * t), 0.5 * np.sin(6 * t)]))


@pytest.mark.slow
def test_video_frame(trials, tmp_path):
    """1280 x 720 frames, light background, caption with time and slow motion, CoM marker."""
    from impact_balance.sim.trials.video import frame_caption
    from tests.helpers.cli import run_process

    lines = frame_caption(0.103, 0.1, 10.0, True)
    assert lines[0].startswith("t =") and "+3.0 ms" in lines[0]
    assert "10x slower than real time" in lines[1] and lines[2].startswith("IMPACT")
    video = tmp_path / "v.mp4"
    proc = run_process(
        "simulate", "kick_one_foot", "--speed", "0.6", "--duration", "0.01", "--video", str(video)
    )
    if proc.returncode != 0:
        assert proc.returncode == 2 and "Traceback" not in proc.stderr
        pytest.skip(f"no offscreen GL here: {proc.stderr.strip()}")
    import imageio.v2 as imageio

    frame = imageio.get_reader(video).get_data(0)
    assert frame.shape == (720, 1280, 3)
    assert frame[5:40, -200:].mean() > 180  # light background, not MuJoCo's black
    r, g, b = (frame[..., k].astype(int) for k in range(3))
    assert ((r > 200) & (g > 160) & (b < 90)).sum() > 40  # the yellow CoM marker
    assert ((r > 170) & (g < 60) & (b < 60)).sum() > 40  # the red impact marker


_PROJECTION_SCRIPT = """
import mujoco, numpy as np
from impact_balance.sim import build_model
from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
from impact_balance.sim.trials.video import project
sim = build_model("kick_one_foot", "rigid")
record = run_trial(sim, TrialOptions(0.5, after=0.01))
renderer = mujoco.Renderer(sim.model, 240, 320)
data = mujoco.MjData(sim.model)
data.qpos[:] = record.qpos[0]
mujoco.mj_forward(sim.model, data)
camera = mujoco.MjvCamera()
camera.lookat[:] = sim.stance.com
camera.distance, camera.azimuth, camera.elevation = 3.0, 90.0, -10.0
renderer.update_scene(data, camera=camera)
renderer.enable_segmentation_rendering()
seg = renderer.render()
hits = mirrored = 0
for geom in range(sim.model.ngeom):  # every drawn geom whose centre is on screen
    uv = project(renderer.scene, data.geom_xpos[geom], 320, 240)
    if uv is None or sim.model.geom_group[geom] > 2 or not (2 <= uv[0] < 318 and 2 <= uv[1] < 238):
        continue
    u, v = int(uv[0]), int(uv[1])
    hits += int(geom in seg[v - 2:v + 3, u - 2:u + 3, 0])
    # a wrong projection, for contrast
    mirrored += int(geom in seg[v - 2:v + 3, 317 - u:322 - u, 0])
print(hits, mirrored)
"""


def test_video_projection_matches_mujoco(trials, tmp_path):
    """The markers' projection is the renderer's: the centres of the robot's geoms land on
    their own pixels in MuJoCo's segmentation image (those not hidden behind another). In a
    fresh process: the GL backend (EGL) must be chosen before MuJoCo is imported."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, MUJOCO_GL="egl")
    proc = subprocess.run(
        [sys.executable, "-c", _PROJECTION_SCRIPT],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    if proc.returncode != 0 and ("OpenGL" in proc.stderr or "EGL" in proc.stderr):
        pytest.skip("no offscreen GL here")
    assert proc.returncode == 0, proc.stderr[-2000:]
    hits, mirrored = map(int, proc.stdout.split()[-2:])
    assert hits >= 10 and hits > 2 * mirrored, (hits, mirrored)  # occluded geoms miss, not most


# -- sweep -------------------------------------------------------------------------------


def test_sweep_axis_labels():
    from impact_balance.sweep.figures import axis_label

    assert axis_label("impact.friction").startswith("impact friction coefficient (-)")
    assert axis_label("impact.restitution[1]").startswith(
        "impact restitution coefficient, upper bound (-)"
    )
    assert axis_label("com_velocity[0]").startswith("pre-impact CoM velocity x (m/s)")
    assert axis_label("contacts[1].friction").startswith("contact 1 friction coefficient (-)")
    assert axis_label("posture.z").startswith("target z of the impact frame by IK, world (m)")
    assert axis_label("impact.normal.azimuth").startswith("normal azimuth (deg)")
    assert axis_label("impact.friction").endswith("\nimpact.friction")  # the key path, to reproduce


def test_sweep_heatmap_marks_falling_points(tmp_path):
    """Points already falling are drawn as such, not as 0 m/s, and are not the lowest maximum."""
    pytest.importorskip("pandas")
    from impact_balance.sweep import make_plan, run_sweep, sweep_spec_from_dict
    from impact_balance.sweep.figures import sweep_figures

    plan = make_plan(
        sweep_spec_from_dict(
            {
                "base": "palm_push_two_feet",
                "sampling": "grid",
                "axes": [
                    {"path": "com_velocity[0]", "values": [0.0, 0.2, 0.9]},
                    {"path": "impact.friction", "values": [0.1, 0.3]},
                ],
            }
        )
    )
    run_sweep(plan, tmp_path / "res", workers=1, progress=False)
    [(_name, fig)] = sweep_figures(tmp_path / "res")
    assert_layout(fig)
    ax = fig.axes[0]
    falling = [
        line for line in ax.lines if str(line.get_label()).startswith("falling before the impact")
    ]
    assert falling and len(falling[0].get_xdata()) == 2  # c_x = 0.9 m/s is outside the area
    lowest = [line for line in ax.lines if str(line.get_label()).startswith("lowest maximum")]
    assert lowest and float(lowest[0].get_xdata()[0]) < 0.9
    assert "(m/s)" in ax.get_xlabel() and "(-)" in ax.get_ylabel()


# -- GUI ----------------------------------------------------------------------------------


def test_gui_view_labels_both_axes_with_units(analyses):
    from impact_balance.gui.view2d import svg_view

    svg = svg_view(analyses["palm_push_two_feet"])
    for label in ("CoM velocity x (m/s)", "CoM velocity y (m/s)", "x (m)", "y (m)"):
        assert f">{label}<" in svg or f", {label}<" in svg, label
    assert "rotate(-90" in svg  # the y labels run along their axes
    assert "padding-right" in svg  # kept clear of the panel's scroll bar


# -- balance trials (synthetic results: the figures, not the simulation) ---------------------
@pytest.fixture(scope="module")
def balance_results():
    from types import SimpleNamespace

    from impact_balance.scenario import load_scenario
    from impact_balance.sim.studies.push import (
        PushOutcome,
        PushTestResult,
        boundary_impulse,
        predict_push,
    )
    from impact_balance.sim.studies.validate import ValidationResult, ValidationTrial, predictions
    from impact_balance.sim.trials.balance_trial import Push

    analysis = ib.analyze("palm_push_ramp")
    scenario = load_scenario("palm_push_ramp")
    trials = []
    times = np.linspace(0.4, 1.9, 80)
    for v, outcome in (
        (0.2, "balanced"),
        (0.4, "balanced"),
        (0.6, "contact_broken"),
        (0.69, "fell"),
        (0.77, "fell"),
    ):
        grow = 4.0 if outcome == "fell" else 1.0
        path = [
            [-0.58 * v * np.exp(-(t - 0.41)) * (1 + grow * (t - 0.41)), 0.04 * v] for t in times
        ]
        summary = {
            "outcome": outcome,
            "approach_speed_measured": v,
            "events": [],
            "reason": None,
            "detail": "",
        }
        trials.append(
            ValidationTrial(
                speed=0.98 * v,
                summary=summary,
                trajectory={"time": list(times), "com_velocity": path},
            )
        )
    validation = ValidationResult(
        "palm_push_ramp",
        "servo",
        True,
        predictions(scenario),
        predictions(scenario, 0.01),
        0.01,
        analysis.areas.omega,
        trials,
        {},
        {},
        0.05,
        4.0,
    )
    setup = SimpleNamespace(analysis=analysis, controller="id")
    outcomes = []
    for fraction in (0.5, 0.85, 1.05, 1.5):
        for k in range(8):
            angle = 2 * np.pi * k / 8
            push = Push(
                angle,
                fraction
                * boundary_impulse(analysis.areas.com_velocity_area, analysis.stance.mass, angle),
            )
            prediction = predict_push(setup, push, 1.2)
            path = [list(prediction.com_velocity * s) for s in np.linspace(0, 1, 20)]
            zmp = [list(analysis.stance.com[:2] + 0.1 * np.array(p)) for p in path]
            outcomes.append(
                PushOutcome(
                    push=push,
                    relative=fraction,
                    prediction=prediction,
                    summary={"outcome": "fell" if fraction > 1 else "balanced", "events": []},
                    trajectory={"com_velocity": path, "zmp": zmp},
                )
            )
    pushes = PushTestResult(
        "palm_push_ramp", outcomes, {"name": "id"}, {}, setup, 0.01, 0.01, analysis.areas.omega, 0.0
    )
    return analysis, validation, pushes


def test_validation_figure_in_measured_speed(balance_results):
    from impact_balance.plots.balance import plot_validation

    _, validation, _ = balance_results
    fig = plot_validation(validation)
    assert_layout(fig, units=False)  # the y axis is the outcome (a category)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "approach speed (m/s)"
    assert [t.get_text() for t in ax.get_yticklabels()] == [
        "balanced",
        "contact broken",
        "fell",
        "aborted",
    ]
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "measured at first contact" in labels and "commanded" in labels
    assert (
        any("ZMP margin 10 mm" in t for t in labels)
        and "stood 0.600 m/s, fell 0.690 m/s (measured)" in ax.get_title()
    )


@pytest.mark.parametrize("kind", ["com_velocity", "zmp"])
def test_push_figures_label_directions_and_keep_survivors_on_top(balance_results, kind):
    from impact_balance.plots.balance import OUTCOME_COLORS, plot_push_trajectories

    _, _, pushes = balance_results
    fig = plot_push_trajectories(pushes, kind)
    assert_layout(fig)
    note = fig.legends[0].get_title().get_text()
    assert "push direction from world x" in note and "0°:" in note and "315°:" in note
    lines = [
        line
        for line in fig.axes[0].get_lines()
        if line.get_linestyle() == "-" and len(line.get_xdata()) > 1
    ]
    colors = [line.get_color() for line in lines]
    last_fall = max(i for i, c in enumerate(colors) if c == OUTCOME_COLORS["fell"])
    first_ok = min(i for i, c in enumerate(colors) if c == OUTCOME_COLORS["balanced"])
    assert (
        last_fall < first_ok
    )  # falls drawn first: the pushes that did not fall stay visible on top


def test_push_figure_dashes_the_pushes_beyond_the_strict_bounds(balance_results):
    from dataclasses import replace

    from impact_balance.plots.balance import OUTCOME_COLORS, plot_push_trajectories

    _, _, pushes = balance_results
    first = pushes.outcomes[0]
    broken = replace(
        first,
        summary={"outcome": "contact_broken", "strict_fail": True, "events": []},
    )
    strict = replace(pushes, outcomes=[broken, *pushes.outcomes[1:]])
    fig = plot_push_trajectories(strict, "com_velocity")
    broken_lines = [
        line
        for line in fig.axes[0].get_lines()
        if line.get_color() == OUTCOME_COLORS["contact_broken"] and len(line.get_xdata()) > 1
    ]
    assert [line.get_linestyle() for line in broken_lines] == ["--"]  # the one push, dashed
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "a contact beyond the strict bounds" in labels
    plain = plot_push_trajectories(pushes, "com_velocity")
    assert "a contact beyond the strict bounds" not in [
        t.get_text() for t in plain.legends[0].get_texts()
    ]


def test_impact_trajectories_name_each_trial(balance_results):
    from impact_balance.plots.balance import plot_impact_trajectories

    analysis, validation, _ = balance_results
    fig = plot_impact_trajectories(validation, analysis)
    assert_layout(fig)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "0.690 m/s: fell" in labels and "0.200 m/s: balanced" in labels
