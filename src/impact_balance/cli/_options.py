"""Options shared by the commands, and the argparse types that check values when the line is read.

A type here runs while argparse reads the command line, before the command loads or computes
anything. Its refusals are the project's errors, which pass through argparse (they are not
``ValueError``) to the error rule of :func:`impact_balance.cli.main`: a bad value is one line
``impact-balance: error: --OPTION = VALUE: reason`` and exit status 2, an output place the
system refuses is one line and exit status 1.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from impact_balance.exceptions import ImpactBalanceError, OptionError, short_repr

if TYPE_CHECKING:
    from typing import TypeAlias

    from impact_balance.scenario import Scenario
    from impact_balance.sim.studies.journal import TrialJournal
    from impact_balance.sim.trials.balance_trial import BalanceTrialOptions

    #: The subcommands of the ``impact-balance`` parser, where each command adds its own.
    Subcommands: TypeAlias = argparse._SubParsersAction[argparse.ArgumentParser]

__all__ = [
    "DEFAULT_CONTROLLER",
    "LOG_SUFFIXES",
    "TRIAL_JOINTS",
    "CommandLineError",
    "a_number",
    "add_controller_option",
    "add_impact_model_option",
    "add_output_options",
    "add_trial_joints_option",
    "add_trial_options",
    "add_velocity_margin_option",
    "add_zmp_margin_option",
    "integer",
    "number",
    "number_or_words",
    "open_journal",
    "output_file",
    "output_folder",
    "scoring_margin",
    "with_margins",
]

#: Suffixes of a log file (``--log``).
LOG_SUFFIXES = (".parquet", ".csv")

#: The balance controller of every trial command (``validate``, ``push-test``, ``approach``)
#: unless ``--controller`` says otherwise: the inverse-dynamics QP places the ZMP anywhere in the
#: support area, as the criteria assume, and holds the commanded approach speed.
DEFAULT_CONTROLLER = "id"

#: ``--joints`` of the balance-trial commands: the study's joint model of each word. ``stiff``
#: (stiff servos, no effort limits) is what the study calls ``rigid``; in ``simulate``,
#: ``rigid`` means welded joints.
TRIAL_JOINTS = {"servo": "servo", "stiff": "rigid"}


class CommandLineError(ImpactBalanceError):
    """An option's value refused while the line is read (exit status 2).

    Not a ``ValueError``, so that argparse lets it through to the error rule instead of
    rewording it as "invalid value".

    Attributes:
        field, value, reason: As in :class:`~impact_balance.exceptions.OptionError`.
    """

    def __init__(self, field: str, value: object, reason: str):
        self.field, self.value, self.reason = field, value, reason
        super().__init__(f"{field} = {short_repr(value)}: {reason}")


def _refused(exc: OptionError) -> CommandLineError:
    """The :class:`CommandLineError` of an option the library refused."""
    return CommandLineError(exc.field, exc.value, exc.reason)


def output_folder(field: str) -> Callable[[str], str]:
    """Argparse type: a folder the command will write in.

    See :mod:`impact_balance.cli.output_paths`.
    """

    def check(text: str) -> str:
        """The folder checked before anything runs, else :class:`CommandLineError`."""
        from impact_balance.cli.output_paths import check_output_folder

        try:
            check_output_folder(text, field)
        except OptionError as exc:
            raise _refused(exc) from None
        return text

    check.__name__ = "folder"
    return check


def output_file(field: str, suffixes: Sequence[str] = ()) -> Callable[[str], str]:
    """Argparse type: a file the command will write.

    Its folder is checked, and its suffix must be among ``suffixes``.
    """

    def check(text: str) -> str:
        """The file checked before anything runs, else :class:`CommandLineError`."""
        from impact_balance.cli.output_paths import check_output_file

        try:
            check_output_file(text, field, tuple(suffixes))
        except OptionError as exc:
            raise _refused(exc) from None
        return text

    check.__name__ = "file"
    return check


def _interval(lo: float, hi: float, lo_open: bool, unit: str) -> str:
    """An interval as written in messages: ``[lo, hi] unit`` or ``(lo, hi] unit``."""
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}]{f' {unit}' if unit else ''}"


def number(
    field: str, lo: float, hi: float, unit: str = "", lo_open: bool = False, why: str = ""
) -> Callable[[str], float]:
    """Argparse type.

    A finite number in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``) for option ``field``;
    ``why`` says where the limit comes from (shown in the error).
    """
    span = _interval(lo, hi, lo_open, unit)

    def check(text: str) -> float:
        """``text`` as a finite float in the interval, else :class:`CommandLineError`."""
        try:
            value = float(text)
        except ValueError:
            raise CommandLineError(field, text, "not a number") from None
        inside = (lo < value if lo_open else lo <= value) and value <= hi
        if not (math.isfinite(value) and inside):
            raise CommandLineError(field, text, f"must be in {span}{f' ({why})' if why else ''}")
        return value

    check.__name__ = "number"
    return check


def integer(field: str, lo: int, hi: int, why: str = "") -> Callable[[str], int]:
    """Argparse type: an integer in ``[lo, hi]`` for option ``field``."""

    def check(text: str) -> int:
        """``text`` as an integer in ``[lo, hi]``, else :class:`CommandLineError`."""
        try:
            value = int(text)
        except ValueError:
            raise CommandLineError(field, text, "not an integer") from None
        if not lo <= value <= hi:
            raise CommandLineError(
                field, text, f"must be in [{lo}, {hi}]{f' ({why})' if why else ''}"
            )
        return value

    check.__name__ = "integer"
    return check


def number_or_words(
    field: str,
    words: tuple[str, ...],
    inside: Callable[[float], bool],
    not_a_number: str,
    outside: str,
    name: str,
) -> Callable[[str], float | str]:
    """Argparse type: one of ``words`` as it is, or a finite number that ``inside`` accepts.

    Args:
        field: The option, named in the errors.
        words: The words taken as they are (``off``, ``controller``).
        inside: Whether a finite number is in the option's range.
        not_a_number: The error's reason for text that is neither a word nor a number.
        outside: The error's reason for a number out of range (or not finite).
        name: The type's name (argparse's).

    Returns:
        The type: text to a float or to the word; a :class:`CommandLineError` otherwise.
    """

    def check(text: str) -> float | str:
        """``text`` as one of the words or a number in range, else :class:`CommandLineError`."""
        if text in words:
            return text
        try:
            value = float(text)
        except ValueError:
            raise CommandLineError(field, text, not_a_number) from None
        if not (math.isfinite(value) and inside(value)):
            raise CommandLineError(field, text, outside)
        return value

    check.__name__ = name
    return check


def add_controller_option(parser: argparse.ArgumentParser, default: str, why: str) -> None:
    """Add ``--controller ik|id``: the balance controller of the trials.

    Args:
        parser: The command's parser.
        default: The default controller (every trial command gives :data:`DEFAULT_CONTROLLER`).
        why: The default's reason, for the help.
    """
    parser.add_argument(
        "--controller",
        default=default,
        choices=("ik", "id"),
        help=f"ik: pink IK -> position servos; id: inverse-dynamics QP -> torque motors "
        f"(default: {default}, {why})",
    )


def add_trial_joints_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--joints servo|stiff`` to a balance-trial command (default ``servo``).

    ``rigid``, this option's former word for ``stiff``, is still read, with one deprecation line
    on stderr: in ``simulate`` ``rigid`` means welded joints, which a balance trial cannot use.
    The study's own name of the joint model is ``TRIAL_JOINTS[args.joints]``.
    """

    def check(text: str) -> str:
        """The joint model; the deprecated ``rigid`` is ``stiff``, with one line on stderr."""
        if text == "rigid":
            import sys

            print(
                "impact-balance: --joints rigid is deprecated here: it means stiff servos "
                "(write --joints stiff); rigid means welded joints in simulate",
                file=sys.stderr,
            )
            return "stiff"
        return text

    check.__name__ = "joint model"
    parser.add_argument(
        "--joints",
        default="servo",
        type=check,
        choices=tuple(TRIAL_JOINTS),
        help="servo: URDF effort limits, 15 Hz servos; stiff: stiff 30 Hz servos, no effort "
        "limits ('rigid', its former name, is deprecated: in simulate it means welded joints)",
    )


def add_output_options(parser: argparse.ArgumentParser, log_help: str) -> None:
    """``--json``, ``--plots DIR`` and ``--log FILE`` (what the log holds: ``log_help``).

    The places are checked when the line is read, before any simulation runs.
    """
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--plots", metavar="DIR", type=output_folder("--plots"), help="write the figures to DIR"
    )
    parser.add_argument(
        "--log",
        metavar="FILE",
        type=output_file("--log", LOG_SUFFIXES),
        help=f"write the time series (.parquet or .csv) {log_help}",
    )


def add_zmp_margin_option(parser: argparse.ArgumentParser, default_help: str) -> None:
    """Add ``--zmp-margin M``: the ZMP support area shrunk by M metres.

    The value is read as a number here and checked by the scenario schema, once, when the
    command applies it (:func:`with_margins`).

    Args:
        parser: The command's parser.
        default_help: What the option defaults to, for its help.
    """
    parser.add_argument(
        "--zmp-margin",
        type=a_number("--zmp-margin"),
        default=None,
        metavar="M",
        help=f"shrink the ZMP support area by M metres, and the CoM velocity area with it "
        f"({default_help}; 0 is the paper's criterion)",
    )


def add_velocity_margin_option(parser: argparse.ArgumentParser, what: str) -> None:
    """Add ``--velocity-margin V``: every post-impact CoM velocity V m/s inside the area.

    The value is read as a number here and checked by the scenario schema, once, when the
    command applies it (:func:`with_margins`).

    Args:
        parser: The command's parser.
        what: What the margin applies to, for the help (e.g. "com governor").
    """
    parser.add_argument(
        "--velocity-margin",
        type=a_number("--velocity-margin"),
        default=None,
        metavar="V",
        help=f"{what}: every post-impact CoM velocity must lie V m/s inside the CoM velocity "
        "area (a margin for the impact model's error; default: the scenario's velocity_margin, "
        "0 unless set, the paper's criterion)",
    )


def add_impact_model_option(parser: argparse.ArgumentParser, what: str) -> None:
    """Add ``--impact-model {floating,held-stance}`` (default ``floating``, the paper's model).

    Args:
        parser: The command's parser.
        what: What the held-stance model does in this command, for the help.
    """
    from impact_balance.impact import IMPACT_MODELS

    parser.add_argument(
        "--impact-model",
        default=IMPACT_MODELS[0],
        choices=IMPACT_MODELS,
        help=f"floating: the paper's impact model (default); held-stance: {what} "
        "(docs/simulation.md#the-held-stance-impact-model-impact-model)",
    )


def a_number(field: str) -> Callable[[str], float]:
    """Argparse type: any number (its range is the scenario schema's to check).

    Args:
        field: The option, named in the error.

    Returns:
        The type: text to float, :class:`CommandLineError` for text that is not a number.
    """

    def check(text: str) -> float:
        """``text`` as a float, else :class:`CommandLineError` ("not a number")."""
        try:
            return float(text)
        except ValueError:
            raise CommandLineError(field, text, "not a number") from None

    check.__name__ = "number"
    return check


def with_margins(
    scenario: Scenario, zmp_margin: float | None = None, velocity_margin: float | None = None
) -> Scenario:
    """``scenario`` with the margins given on the command line (None: the scenario's own).

    The values go through :meth:`~impact_balance.scenario.Scenario.replace`, so the schema
    checks them as it checks a file's keys; its refusal names the option.

    Args:
        scenario: The command's scenario.
        zmp_margin: ``--zmp-margin``, m.
        velocity_margin: ``--velocity-margin``, m/s.

    Returns:
        The scenario to use (``scenario`` itself when no margin is given).

    Raises:
        ScenarioError: A margin the schema refuses, its field the option (``--zmp-margin``).
    """
    from impact_balance.exceptions import ScenarioError

    given = {"zmp_margin": zmp_margin, "velocity_margin": velocity_margin}
    changes = {key: value for key, value in given.items() if value is not None}
    try:
        return scenario.replace(**changes)
    except ScenarioError as exc:
        option = "--" + exc.field.replace("_", "-")
        raise ScenarioError(option, exc.value, exc.reason) from None


def scoring_margin(scenario: Scenario) -> float | None:
    """The ZMP margin (m) a trial command scores with: the scenario's, when set.

    Args:
        scenario: The command's scenario, with ``--zmp-margin`` applied (:func:`with_margins`).

    Returns:
        Its ``zmp_margin`` when its file or the command line set it, else None (the trials'
        controller's own margin).
    """
    return scenario.zmp_margin if "zmp_margin" in scenario.set_keys else None


def add_trial_options(parser: argparse.ArgumentParser, impact: bool) -> None:
    """Options of the balance-trial commands (``validate``, ``push-test``).

    ``--rigid-impact`` (impacts only), ``--zmp-margin``, and the trials journal (``--journal
    FILE``, ``--fresh``, ``--no-journal``).
    """
    if impact:
        parser.add_argument(
            "--rigid-impact",
            action="store_true",
            help="hold every joint's velocity through the impact (the paper's rigid robot), "
            "until the contact's normal velocity reaches zero",
        )
    add_zmp_margin_option(
        parser,
        "default: the scenario's zmp_margin when it sets one, else the ZMP margin the trials' "
        "controller keeps",
    )
    parser.add_argument(
        "--journal",
        metavar="FILE",
        type=output_file("--journal", (".jsonl",)),
        help="JSON-lines file of the finished trials, written as they end; running the same "
        "command again resumes from it (default: "
        "impact-balance-trials/<command>_<scenario>_<digest>.jsonl)",
    )
    parser.add_argument(
        "--fresh", action="store_true", help="discard the journal's trials and run them all again"
    )
    parser.add_argument(
        "--no-journal", action="store_true", help="keep no journal (nothing resumes)"
    )


def open_journal(
    args: argparse.Namespace,
    command: str,
    scenario: Scenario,
    joints: str,
    options: BalanceTrialOptions,
    extra: dict[str, Any],
) -> TrialJournal:
    """The trials journal of a command, by the digest of everything its trials depend on.

    The scoring margins are excluded: scores are recomputed from the trials.

    Returns:
        The :class:`impact_balance.sim.studies.journal.TrialJournal` to write to.
    """
    import dataclasses
    import sys
    from pathlib import Path

    from impact_balance.sim.studies.journal import (
        TrialJournal,
        default_journal_path,
        journal_digest,
    )
    from impact_balance.sim.trials.balance_trial import TRIAL_VERSION

    parts = {
        "command": command,
        "trial_version": TRIAL_VERSION,
        "scenario": scenario.model_dump(
            # The criterion's settings judge trials; they are not an input of any trial.
            mode="json",
            exclude={
                "zmp_margin",
                "velocity_margin",
                "angular_momentum_damping_time",
                "friction_scale",
                "name",
                "description",
            },
        ),
        "joints": joints,
        "options": dataclasses.asdict(dataclasses.replace(options, record=False)),
        **extra,
    }
    digest = journal_digest(parts)
    if args.no_journal:
        return TrialJournal.open(None, digest)
    path = (
        Path(args.journal)
        if args.journal
        else default_journal_path(command, scenario.name or "scenario", digest)
    )
    if args.fresh and path.exists():
        path.unlink()
    journal = TrialJournal.open(path, digest, {"command": command, "scenario": scenario.name})
    note = f", {len(journal.entries)} finished trials to reuse" if journal.entries else ""
    cut = f", {journal.skipped_lines} line(s) not reused" if journal.skipped_lines else ""
    print(f"impact-balance: trials journal {path}{note}{cut}", file=sys.stderr)
    for problem in journal.problems:
        print(f"impact-balance: --journal {path}: {problem}", file=sys.stderr)
    return journal


def import_mujoco(video: bool) -> None:
    """Import MuJoCo for a simulation command.

    With ``video``, offscreen rendering first picks EGL (it works headless, and must be chosen
    before MuJoCo is imported) unless ``MUJOCO_GL`` says otherwise. An unusable backend is one
    :class:`~impact_balance.exceptions.SimulationError`.
    """
    from impact_balance.exceptions import SimulationError

    if video:
        os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco  # noqa: F401  (reads MUJOCO_GL when imported)
    except Exception as exc:  # an unusable backend fails inside MuJoCo's import, with various types
        raise SimulationError(
            "MUJOCO_GL",
            os.environ.get("MUJOCO_GL"),
            f"MuJoCo cannot start with this OpenGL "
            f"backend ({type(exc).__name__}); use MUJOCO_GL=egl, or unset it",
        ) from None
