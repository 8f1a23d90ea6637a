"""What each command's ``--help`` says above and below its options: a paragraph, an example."""

from __future__ import annotations

import argparse
import textwrap
from collections.abc import Mapping

__all__ = ["COMMAND_HELP", "describe"]

#: Per command: (description, example command lines). The description is one paragraph.
COMMAND_HELP: dict[str, tuple[str, str]] = {
    "demo": (
        "Run the paper's bundled studies on the default robot (Talos): the palm push on two "
        "feet, the ramp, the one-foot kick and the friction sweep; print a report and write "
        "the figures to a folder.",
        "impact-balance demo --out demo_figures",
    ),
    "analyze": (
        "Analyze one scenario (a YAML file or a bundled scenario's name): the ZMP support "
        "area, the CoM velocity area, and, when the scenario has an impact, the impulse and "
        "the maximum contact velocity of both criteria. Exit 0 whether or not the stance can "
        "balance; --json gives every number.",
        "impact-balance analyze palm_push_two_feet --json",
    ),
    "phase-portrait": (
        "The linear inverted pendulum's phase portrait for a CoM height and a ZMP range "
        "(paper sec. III-B): the CoM velocity bounds that keep the capture point inside.",
        "impact-balance phase-portrait --com-height 0.9 --zmp-range -0.1 0.1 --plot lipm.png",
    ),
    "scenarios": (
        "List the bundled scenarios, one per line with its description; any of these names "
        "goes wherever a scenario file does.",
        "impact-balance scenarios",
    ),
    "robots": (
        "List the robots a scenario names with `robot: NAME`: the bundled ones, or with "
        "--all every floating-base robot of example-robot-data (go2, anymal_c, solo12, ...), "
        "with its mass, standing configuration, foot frames and sole size where known.",
        "impact-balance robots --all",
    ),
    "frames": (
        "List a robot's frames and joints, or a scenario's, with each frame's world position "
        "and axes at the standing configuration or the scenario's stance, and the scenario's "
        "contacts resolved (centre, normal, tilt): what to write in a contact or `pose`.",
        "impact-balance frames go2 --frame FL_foot --frame RR_foot",
    ),
    "pose": (
        "Place frames by whole-body IK and write the posed scenario: each --place puts a "
        "contact's centre (or a frame) at a world point, every other contact is kept, the "
        "CoM goes to --com; feet on the ground are laid flat (their contacts written with "
        "`normal:`). It ends with the verdict of the stance it wrote: can balance or not, "
        "and why.",
        "impact-balance pose draft.yaml --place FL_foot 0.2 0.15 0 --com 0 0 --out posed.yaml",
    ),
    "gui": (
        "Start the interactive web GUI on a scenario: drag the robot's frames and contacts, "
        "see the areas and the maximum contact velocity update live, save the scenario.",
        "impact-balance gui palm_push_two_feet --port 8080",
    ),
    "simulate": (
        "Simulate the scenario's impact in MuJoCo at one or more approach speeds and compare "
        "the measured CoM velocity jump and impulse with the impact model's.",
        "impact-balance simulate palm_push_two_feet --speed 0.2,0.4 --plots sim_figures",
    ),
    "validate": (
        "Bisect, in MuJoCo, the approach speed at which the robot falls after the impact, "
        "and set it beside the maximum contact velocity the criteria predict.",
        "impact-balance validate palm_push_two_feet --max-speed 1.0 --rigid-impact",
    ),
    "push-test": (
        "Push the simulated robot in every direction at several impulses and score both "
        "criteria's predictions (balanced or fell) against the outcomes.",
        "impact-balance push-test palm_push_two_feet --directions 8 --magnitudes 5 10",
    ),
    "calibrate": (
        "From push-test --json outputs of one robot and one controller, the smallest ZMP "
        "margin that brings the pooled P(fell | predicted safe) to a target (strict outcome by "
        "default), with its Wilson interval, the share of standing pushes still called safe, "
        "each file's rates and the whole curve; --out writes the file that --calibration reads.",
        "impact-balance calibrate train_*.json --target 0.05 --out talos_id.yaml",
    ),
    "approach": (
        "Send the impact point at a wall the robot does not know, its speed capped every tick "
        "by the governor, and report the speed at contact and whether the robot stayed up.",
        "impact-balance approach palm_push_two_feet --reference 1.0 --governor com",
    ),
    "check-log": (
        "Check a recorded time series (.parquet or .csv of CoM velocity and contact states) "
        "against both criteria, sample by sample.",
        "impact-balance check-log run.parquet --scenario palm_push_two_feet --json",
    ),
    "sweep": (
        "Evaluate a sweep file (a grid or quasi-random points over scenario keys) on every "
        "core or a Dask cluster, and write its table, summary and figures to a folder.",
        "impact-balance sweep wall_palm_push --out sweep_out --workers 2",
    ),
}


def describe(parsers: Mapping[str, argparse.ArgumentParser]) -> None:
    """Give every command's parser its paragraph (unless it has its own) and its example.

    Args:
        parsers: The subcommand parsers by command name (``subparsers.choices``).
    """
    for name, parser in parsers.items():
        if name not in COMMAND_HELP:
            continue
        description, example = COMMAND_HELP[name]
        if parser.epilog is None:
            paragraph = " ".join((parser.description or description).split())
            parser.description = textwrap.fill(paragraph, width=79)
            parser.epilog = f"Example:\n  {example}"
            parser.formatter_class = argparse.RawDescriptionHelpFormatter
