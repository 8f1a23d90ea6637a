"""Options shared by the simulation commands (``simulate``, ``validate``, ``push-test``)."""

from __future__ import annotations

import argparse

__all__ = ["add_controller_option", "add_output_options", "add_zmp_margin_option", "with_zmp_margin",
           "add_trial_options", "open_journal"]


def add_controller_option(parser: argparse.ArgumentParser, default: str, why: str) -> None:
    """``--controller ik|id``: the balance controller of the trials (``why``: the default's reason)."""
    parser.add_argument("--controller", default=default, choices=("ik", "id"),
                        help=f"ik: pink IK -> position servos; id: inverse-dynamics QP -> torque motors "
                             f"(default: {default}, {why})")


def add_output_options(parser: argparse.ArgumentParser, log_help: str) -> None:
    """``--json``, ``--plots DIR`` and ``--log FILE`` (what the log holds: ``log_help``)."""
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plots", metavar="DIR", help="write the figures to DIR")
    parser.add_argument("--log", metavar="FILE", help=f"write the time series (.parquet or .csv) {log_help}")


def add_zmp_margin_option(parser: argparse.ArgumentParser, default_help: str) -> None:
    """``--zmp-margin M``: the ZMP support area shrunk by M metres (``default_help``: what it defaults to)."""
    parser.add_argument("--zmp-margin", type=float, default=None, metavar="M",
                        help=f"shrink the ZMP support area by M metres, and the CoM velocity area with it "
                             f"({default_help}; 0 is the paper's criterion)")


def with_zmp_margin(scenario, margin: float | None):
    """``scenario`` with its ``zmp_margin`` replaced by ``margin`` (m) when given, checked like the key."""
    if margin is None:
        return scenario
    from ..constants import MAX_SIZE
    from ..exceptions import ScenarioError

    if not (margin == margin and 0.0 <= margin <= MAX_SIZE):  # NaN fails the first test
        raise ScenarioError("--zmp-margin", margin, f"must be in [0, {MAX_SIZE:g}] m")
    return scenario.model_copy(update={"zmp_margin": float(margin)})


def add_trial_options(parser: argparse.ArgumentParser, impact: bool) -> None:
    """Options of the balance-trial commands (``validate``, ``push-test``): ``--rigid-impact`` (impacts only),
    ``--zmp-margin``, and the trials journal (``--journal FILE``, ``--fresh``, ``--no-journal``)."""
    if impact:
        parser.add_argument("--rigid-impact", action="store_true",
                            help="hold every joint's velocity through the impact (the paper's rigid robot), "
                                 "until the contact's normal velocity reaches zero")
    add_zmp_margin_option(parser, "default: the ZMP margin the trials' controller keeps")
    parser.add_argument("--journal", metavar="FILE",
                        help="JSON-lines file of the finished trials, written as they end; running the same "
                             "command again resumes from it (default: impact-balance-trials/<command>_<scenario>_<digest>.jsonl)")
    parser.add_argument("--fresh", action="store_true", help="discard the journal's trials and run them all again")
    parser.add_argument("--no-journal", action="store_true", help="keep no journal (nothing resumes)")


def open_journal(args: argparse.Namespace, command: str, scenario, joints: str, options, extra: dict):
    """The trials journal of a command (:class:`impact_balance.sim.journal.TrialJournal`), by the digest of
    everything its trials depend on (the scoring margin excluded: scores are recomputed from the trials)."""
    import dataclasses
    import sys
    from pathlib import Path

    from ..sim.balance_trial import TRIAL_VERSION
    from ..sim.journal import TrialJournal, default_journal_path, journal_digest

    parts = {"command": command, "trial_version": TRIAL_VERSION,
             "scenario": scenario.model_dump(mode="json", exclude={"zmp_margin", "name", "description"}),
             "joints": joints, "options": dataclasses.asdict(dataclasses.replace(options, record=False)), **extra}
    digest = journal_digest(parts)
    if args.no_journal:
        return TrialJournal.open(None, digest)
    path = Path(args.journal) if args.journal else default_journal_path(command, scenario.name or "scenario", digest)
    if args.fresh and path.exists():
        path.unlink()
    journal = TrialJournal.open(path, digest, {"command": command, "scenario": scenario.name})
    note = f", {len(journal.entries)} finished trials to reuse" if journal.entries else ""
    cut = f", {journal.skipped_lines} unreadable line(s) skipped" if journal.skipped_lines else ""
    print(f"impact-balance: trials journal {path}{note}{cut}", file=sys.stderr)
    return journal
