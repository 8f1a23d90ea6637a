"""Score a held-out set from its run, in two steps: export the records, report the tables.

Usage (from the repository root, with impact-balance and its ``sim`` extra installed)::

    python studies/score_held_out.py export RUN_DIR SET_DIR OUT_DIR [--commit HASH]
    python studies/score_held_out.py report RECORDS_DIR [--protocol PROTOCOL.md]
        [--group LABEL=REGEX ...] [--candidate COLUMN ...]

``export`` reads the run's ``--json`` outputs in ``RUN_DIR`` (``push_*.json``, ``val_*.json``,
``approach*_*.json``) and the set's stances in ``SET_DIR`` (``<stance>.yaml``, for the capture's
premise) and writes the records to ``OUT_DIR``: ``pushes.csv``, ``impacts.csv``,
``approaches.csv``, ``com_reach.csv`` and ``premise.json``. It writes nothing else, anywhere.

``report`` prints the scores' markdown tables from the records: pushes per stance and body,
pooled (the groups: all, one foot, two feet, each ``--group``, sideways on two feet, each
body), impacts with every prediction the records carry, the rigid impacts' ratios, the
premise, the governed approaches, and rule 4's check against ``--protocol``.

Exit status: 0, 2 for bad input (a missing directory, a file that is not a record), 1 for the
environment, 130 when interrupted. Errors are one line on stderr.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import NoReturn

sys.path.insert(0, str(Path(__file__).resolve().parent))

from scoring import export, impact_scores, push_scores, rule4
from scoring.premise import premise
from scoring.records import read_csv, read_json

from impact_balance.exit_status import describe_error

__all__ = ["main"]

EXIT_INPUT = 2


class InputError(ValueError):
    """Bad input named by its field and value."""

    def __init__(self, field: str, value: object, problem: str) -> None:
        super().__init__(f"{field} {value!r}: {problem}")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}\n")


def _directory(field: str, value: str) -> Path:
    path = Path(value)
    if not path.is_dir():
        raise InputError(field, value, "not a directory")
    return path


def _group(value: str) -> tuple[str, str]:
    label, sep, pattern = value.partition("=")
    if not sep or not label:
        raise InputError("--group", value, "expected LABEL=REGEX")
    try:
        re.compile(pattern)
    except re.error as error:
        raise InputError("--group", value, f"not a regular expression ({error})") from error
    return label, pattern


def run_export(args: argparse.Namespace) -> None:
    """Write the records of ``args.run_dir`` to ``args.out_dir`` and say how many rows each."""
    run_dir = _directory("RUN_DIR", args.run_dir)
    set_dir = _directory("SET_DIR", args.set_dir)
    out_dir = Path(args.out_dir)
    if out_dir.resolve() == run_dir.resolve():
        raise InputError("OUT_DIR", args.out_dir, "is RUN_DIR (the run's outputs stay as they are)")
    tables = {
        "pushes.csv": export.push_rows(run_dir, args.commit),
        "impacts.csv": export.impact_rows(run_dir),
        "approaches.csv": export.approach_rows(run_dir),
        "com_reach.csv": export.com_reach_rows(run_dir),
    }
    if not any(tables.values()):
        raise InputError("RUN_DIR", args.run_dir, "holds no push_, val_ or approach output")
    try:
        premises = premise(run_dir, set_dir)
    except FileNotFoundError as error:
        raise InputError("SET_DIR", args.set_dir, str(error)) from error
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, rows in tables.items():
        if rows:
            print(name, export.write_csv(out_dir / name, rows))
    (out_dir / "premise.json").write_text(json.dumps(premises, indent=1))
    print("premise.json", len(premises))


def run_report(args: argparse.Namespace) -> None:
    """Print the scores' markdown tables from ``args.records_dir``."""
    records = _directory("RECORDS_DIR", args.records_dir)
    groups = [_group(value) for value in args.group]
    push_rows = read_csv(records, "pushes.csv")
    impacts = read_csv(records, "impacts.csv")
    approaches = read_csv(records, "approaches.csv")
    if not (push_rows or impacts or approaches):
        raise InputError("RECORDS_DIR", args.records_dir, "holds no pushes, impacts or approaches")
    candidates = args.candidate or push_scores.candidate_columns(push_rows)
    for column in candidates:
        if push_rows and column not in push_rows[0]:
            raise InputError("--candidate", column, "not a column of pushes.csv")
    sections = []
    if push_rows:
        pushes = push_scores.pushes(push_rows, candidates)
        sections += ["### Pushes", push_scores.stance_table(pushes, candidates)]
        sections += [
            "Pooled (the band, strict):",
            push_scores.pooled_table(pushes, candidates, groups),
        ]
    if impacts:
        sections += ["### Impacts", impact_scores.impact_table(impacts)]
        premises = read_json(records, "premise.json")
        if premises:
            sections += ["The capture's premise:", impact_scores.premise_table(premises)]
        sections += ["At the rigid impact, the strict failure over each prediction:"]
        sections += [impact_scores.ratio_summary(impacts)]
    if approaches:
        sections += ["### The governor", impact_scores.approach_table(approaches)]
    if args.protocol:
        protocol = Path(args.protocol)
        if not protocol.is_file():
            raise InputError("--protocol", args.protocol, "not a file")
        checks = rule4.check(
            protocol.read_text(), push_rows, impacts, read_csv(records, "com_reach.csv")
        )
        sections += ["### Rule 4", rule4.check_table(checks)]
    print("\n\n".join(sections))


def parser() -> argparse.ArgumentParser:
    """The command line: ``export`` and ``report``."""
    top = _Parser(prog="score_held_out.py", description=__doc__.split("\n\n")[0])
    commands = top.add_subparsers(dest="command", required=True, parser_class=_Parser)
    exporting = commands.add_parser("export", help="the run's JSON outputs to the records")
    exporting.add_argument("run_dir", metavar="RUN_DIR", help="the run's --json outputs")
    exporting.add_argument("set_dir", metavar="SET_DIR", help="the set's stances (<stance>.yaml)")
    exporting.add_argument("out_dir", metavar="OUT_DIR", help="where the records are written")
    exporting.add_argument("--commit", default="", help="the frozen commit (the pushes' column)")
    exporting.set_defaults(run=run_export)
    reporting = commands.add_parser("report", help="the scores' markdown tables from the records")
    reporting.add_argument("records_dir", metavar="RECORDS_DIR", help="studies/held_out_results_N")
    reporting.add_argument("--protocol", help="the protocol's markdown file: check rule 4")
    reporting.add_argument(
        "--group",
        action="append",
        default=[],
        metavar="LABEL=REGEX",
        help="a pooled group of its own: the pushes whose stance matches REGEX (repeatable)",
    )
    reporting.add_argument(
        "--candidate",
        action="append",
        default=[],
        metavar="COLUMN",
        help="a *_safe column of pushes.csv to score as a candidate (repeatable; default: "
        "every *_safe column but the default's and push-test's standard calls)",
    )
    reporting.set_defaults(run=run_report)
    return top


def main(argv: list[str] | None = None) -> int:
    """Run the command; the exit status (0, 2 bad input, 1 environment, 130 interrupted)."""
    args = parser().parse_args(argv)
    try:
        args.run(args)
    except KeyboardInterrupt:
        print("score_held_out.py: interrupted", file=sys.stderr)
        return 130
    except (InputError, export.RecordsError) as error:
        print(f"score_held_out.py: error: {error}", file=sys.stderr)
        return EXIT_INPUT
    except Exception as error:
        line, status = describe_error(error)
        print(f"score_held_out.py: error: {line}", file=sys.stderr)
        return status
    return 0


if __name__ == "__main__":
    sys.exit(main())
