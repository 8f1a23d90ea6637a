"""``studies/score_held_out.py``: the published held-out scores re-scored from the records.

The report is run on the committed records of sets 7 and 8 and every table of the published
scores' file is compared, cell by cell, with the report's table of the same first column (the
numbers parsed from the file, not written here). A synthetic run checks that ``export`` carries
a candidate's ``*_safe`` call and an unknown prediction through, and that ``report`` scores them.
"""

from __future__ import annotations

import importlib.util
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.helpers.markdown_tables import markdown_tables
from tests.helpers.scripts import load_study

pytest.importorskip("mujoco")  # the library's Wilson interval lives in impact_balance.sim

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ROOT / "docs" / "studies"
#: The pooled groups the published files name, by set: label=regex on the stance's name.
TWO_FEET = "^(?!.*_foot_)"
GROUPS = {
    7: [
        f"ordinary width (six stances)={TWO_FEET}(?!.*narrow)",
        f"staggered={TWO_FEET}.*stagger",
        f"side by side={TWO_FEET}(?!.*stagger)",
        f"narrow (Talos)={TWO_FEET}.*narrow",
        f"crouched (G1, JVRC-1)={TWO_FEET}.*crouch",
        f"step (Romeo)={TWO_FEET}.*step",
        f"diagonal slope (Talos)={TWO_FEET}.*diagonal",
    ],
    8: [
        "one foot (G1; Talos with a hand hold)=_foot_",
        "broad, 0.24 m (Talos, Romeo)=broad",
        "toe-up ramp (G1)=ramp",
    ],
}
#: Rows keyed by their first two cells (the others by their first).
TWO_KEYS = ("body", "model", "reference (m/s)")


def _script() -> Callable[[list[str]], int]:
    main: Callable[[list[str]], int] = load_study("score_held_out").main
    return main


@pytest.fixture(scope="module")
def score() -> Callable[[list[str]], int]:
    return _script()


def _run(score: Callable[[list[str]], int], capsys: Any, *argv: str) -> tuple[int, str, str]:
    try:
        status = score(list(argv))
    except SystemExit as exit_:  # argparse's usage errors
        status = int(exit_.code or 0)
    out, err = capsys.readouterr()
    return status, out, err


def _compare(published: str, report: str) -> tuple[int, list[str]]:
    """Compare every published table with the report's: (cells equal, differences)."""
    mine = markdown_tables(report)
    equal, problems = 0, []
    for header, rows in markdown_tables(published):
        candidates = [t for t in mine if t[0][0] == header[0] and len(set(t[0]) & set(header)) > 2]
        if not candidates:
            continue  # a table the report does not print (the protocol's, before any trial)
        their_header, their_rows = max(candidates, key=lambda t: len(set(t[0]) & set(header)))
        problems += [f"column {c!r} missing" for c in header if c not in their_header]
        keys = 2 if header[1] in TWO_KEYS else 1
        if header[0] == "":  # the ratio summary: its rows by order, their labels the file's own
            their = dict(enumerate(their_rows))
            ours = dict(enumerate(rows))
        else:
            their = {tuple(row[:keys]): row for row in their_rows}
            ours = {tuple(row[:keys]): row for row in rows}
        for key, row in ours.items():
            if key not in their:
                problems.append(f"row {key} missing")
                continue
            for column in header[keys:]:
                if column in their_header:
                    a = row[header.index(column)].replace("**", "")  # the file's emphasis
                    b = their[key][their_header.index(column)]
                    if a == b:
                        equal += 1
                    else:
                        problems.append(f"{key} {column!r}: published {a!r}, report {b!r}")
    return equal, problems


@pytest.mark.parametrize("number", [7, 8])
def test_report_reproduces_the_published_tables(
    score: Callable[[list[str]], int], capsys: Any, number: int
) -> None:
    groups = [arg for g in GROUPS[number] for arg in ("--group", g)]
    protocol = STUDIES / f"held-out-protocol-{number}.md"
    records = ROOT / "studies" / f"held_out_results_{number}"
    status, out, err = _run(
        score, capsys, "report", str(records), "--protocol", str(protocol), *groups
    )
    assert status == 0, err
    published = (STUDIES / f"held-out-scores-{number}.md").read_text()
    equal, problems = _compare(published, out)
    if number == 8:
        # The file prints 2 for the held stance with L "below 1.0"; its own impact table gives
        # 0.93 (iCub), 0.98 (Talos stagger) and 0.65 (the hand hold): three.
        typo = "2 'below 1.0 (above the failure)': published '2', report '3'"
        if typo in problems:
            problems.remove(typo)
    assert not problems, problems
    pushes = markdown_tables(published)
    published_cells = sum(len(rows) * (len(h) - 1) for h, rows in pushes if h[0] == "pushes")
    assert equal > published_cells > 0  # the pooled table at least, and more
    assert "Rule 4 holds: 0 of" in out


def _push(direction: float, relative: float, default: bool, candidate: bool, failed: bool):
    return {
        "direction_deg": direction,
        "relative": relative,
        "magnitude": 10.0 * relative,
        "predicted_com_velocity_margin": 0.05 if default else -0.05,
        "com_velocity_margin": 0.05 if default else -0.05,
        "effective_com_velocity_margin": None,
        "com_criterion_safe": default,
        "paper_com_criterion_safe": default,
        "hand_contact_safe": candidate,
        "com_reach_margin": None if direction == 90 else 0.1,  # no reach: an empty cell
        "outcome": "fell" if failed else "balanced",
        "fell": failed,
        "strict_fail": failed,
        "strict_reason": "fell" if failed else None,
    }


def _synthetic_run(run: Path, pushes: list[dict[str, Any]]) -> None:
    run.mkdir()
    document = {"omega": 3.0, "zmp_margin": 0.01, "com_reach": None, "pushes": pushes}
    (run / "push_robot_wide_front_pelvis.json").write_text(json.dumps(document))
    validate = {
        "empirical": {"survived": 0.9, "fell": 1.1, "strict_failed": 1.0},
        "predicted": {
            "default": 0.8,
            "com_criterion": {"composite": 1.2},
            "com_reach": {"max_contact_velocity": 0.8},
            "hand_contact": {"max_contact_velocity": 0.5},
        },
        "trials": [{"outcome": "fell"}, {"outcome": "aborted"}],
    }
    (run / "val_robot_wide_front_free.json").write_text(json.dumps(validate))
    trial = {"reference": 0.8, "wall_distance": 0.1, "cap_at_contact": 0.4}
    trial |= {"speed_at_contact": 0.4, "outcome": "balanced", "strict_fail": False}
    (run / "approachhand_robot_wide_front_ref08.json").write_text(json.dumps({"trials": [trial]}))


def test_export_carries_a_candidate_and_report_scores_it(
    score: Callable[[list[str]], int], capsys: Any, tmp_path: Path
) -> None:
    calls = [(d, r, d % 90 == 0, r < 0.9, r > 0.95) for d in (0, 45, 90) for r in (0.8, 0.9, 1.0)]
    pushes = [_push(*call) for call in calls]
    run, out_dir = tmp_path / "run", tmp_path / "records"
    _synthetic_run(run, pushes)
    status, out, err = _run(score, capsys, "export", str(run), str(tmp_path), str(out_dir))
    assert status == 0, err
    assert "hand_contact_safe" in (out_dir / "pushes.csv").read_text().splitlines()[0]
    assert "predicted_hand_contact_mps" in (out_dir / "impacts.csv").read_text()
    status, out, err = _run(score, capsys, "report", str(out_dir))
    assert status == 0, err
    tables = {h[0]: (h, rows) for h, rows in markdown_tables(out)}
    header, rows = tables["pushes"]
    all_row = rows[0]
    safe = [c for c in calls if c[3]]
    failed_safe = sum(c[4] for c in safe)
    cell = all_row[header.index("hand_contact_safe: P(failed strictly \\| safe), band")]
    assert cell.endswith(f"({failed_safe}/{len(safe)})")
    stood = [c for c in calls if not c[4]]
    cell = all_row[header.index("hand_contact_safe: standing called safe")]
    assert cell.endswith(f"({sum(c[3] for c in stood)}/{len(stood)})")
    impacts = next(t for t in markdown_tables(out) if "model" in t[0])
    assert "hand_contact prediction" in impacts[0]
    assert impacts[1][0][impacts[0].index("hand_contact prediction")] == "0.500"
    assert impacts[1][0][impacts[0].index("aborted")] == "1"
    approaches = next(t for t in markdown_tables(out) if "trials" in t[0])
    assert approaches[1][0][0] == "hand: robot_wide_front"


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["report", "no/such/dir"], "RECORDS_DIR 'no/such/dir'"),
        (["report", "studies/held_out_results_8", "--group", "nolabel"], "--group 'nolabel'"),
        (["report", "studies/held_out_results_8", "--candidate", "x_safe"], "--candidate 'x_safe'"),
        (["export", "no/such/run", ".", "out"], "RUN_DIR 'no/such/run'"),
    ],
)
def test_bad_input_is_one_line_and_status_2(
    score: Callable[[list[str]], int], capsys: Any, monkeypatch: Any, argv: list[str], needle: str
) -> None:
    monkeypatch.chdir(ROOT)
    status, out, err = _run(score, capsys, *argv)
    assert status == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err


STANCES = ("talos_wide_front", "g1_left_foot_toe_front")
push_draws = st.lists(
    st.tuples(
        st.sampled_from(STANCES),
        st.sampled_from(("pelvis", "torso")),
        st.sampled_from((0, 90, 180)),
        st.sampled_from((0.5, 0.78, 0.99, 1.05, 1.3)),
        st.booleans(),  # the default's call
        st.booleans(),  # the candidate's call
        st.booleans(),  # failed strictly
        st.booleans(),  # aborted
    ),
    min_size=1,
    max_size=40,
)


@settings(max_examples=40, deadline=None)
@given(draws=push_draws)
def test_pooled_counts_equal_an_independent_count(draws: list[tuple[Any, ...]]) -> None:
    _script()  # puts studies/ on the path
    push_scores = importlib.import_module("scoring.push_scores")
    rows = [
        {
            "stance": stance,
            "body": body,
            "direction_deg": str(direction),
            "relative": str(relative),
            "omega": "3.0",
            "zmp_margin": "0.01",
            "default_margin_mps": "0.05" if default else "-0.05",
            "paper_margin_mps": "0.08" if default else "0.0",
            "default_safe": str(int(default)),
            "hand_safe": str(int(candidate)),
            "outcome": "aborted" if aborted else ("fell" if failed else "balanced"),
            "fell": str(int(failed and not aborted)),
            "strict_fail": str(int(failed and not aborted)),
        }
        for stance, body, direction, relative, default, candidate, failed, aborted in draws
    ]
    candidates = push_scores.candidate_columns(rows)
    assert candidates == ["hand_safe"]
    header, table_rows = markdown_tables(
        push_scores.pooled_table(push_scores.pushes(rows, candidates), candidates)
    )[0]
    by_label = {row[0]: row for row in table_rows}
    groups = {
        "all": lambda d: True,
        "one foot": lambda d: "_foot_" in d[0],
        "two feet": lambda d: "_foot_" not in d[0],
    }
    for label, member in groups.items():
        chosen = [d for d in draws if member(d) and not d[7] and 0.75 <= d[3] <= 1.05]
        if not [d for d in draws if member(d)]:
            assert label not in by_label
            continue
        for index, column in ((4, "default"), (5, "hand_safe")):
            safe = [d for d in chosen if d[index]]
            failed = sum(d[6] for d in safe)
            cell = by_label[label][header.index(f"{column}: P(failed strictly \\| safe), band")]
            assert cell.endswith(f"({failed}/{len(safe)})")
            if safe:
                assert cell.startswith(f"{100 * failed / len(safe):.0f} %")
            stood = [d for d in chosen if not d[6]]
            cell = by_label[label][header.index(f"{column}: standing called safe")]
            expected = f"({sum(d[index] for d in stood)}/{len(stood)})" if stood else "–"
            assert cell.endswith(expected)
