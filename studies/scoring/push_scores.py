"""The push scores: per stance and body, and pooled over groups of pushes.

A push is scored on the band (0.75 to 1.05 of its direction's boundary impulse) unless said
otherwise, against its strict outcome (``strict_fail``) or the lenient one (``fell``); aborted
pushes are left out. A criterion calls a push safe when its margin (m/s) is at least its
threshold: the default's own call (``default_safe``); without the reach, the default's margin
against ``omega * zmp_margin``; the paper's margin at margin 0 against ``omega * M`` for the
scored margin M (0 or 10 mm); the angular momentum term alone against 0; a candidate's call
(any other ``*_safe`` column of the records, 0 or 1).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from scoring.markdown import called_safe, rate, table
from scoring.records import flag, number

__all__ = [
    "BAND",
    "STANDARD_CALLS",
    "Push",
    "candidate_columns",
    "pooled_table",
    "pushes",
    "stance_table",
]

#: The band of relative impulses scored (fraction of the boundary impulse).
BAND = (0.75, 1.05)
#: ``*_safe`` columns of ``push-test`` that are not candidates (the paper's, the ZMP
#: criterion's and the calls with the trial's own start).
STANDARD_CALLS = (
    "default_safe",
    "paper_com_criterion_safe",
    "com_criterion_safe_in_trial",
    "zmp_criterion_safe",
    "zmp_criterion_safe_in_trial",
)
#: The paper's criterion is scored at this ZMP margin (m) beside margin 0.
PAPER_MARGIN = 0.01
AM_COLUMN = "angular_momentum_margin_mps"
#: push-test's own call of the paper's criterion at the run's margin (exact, where the rounded
#: margins of the records are not: a margin within 1e-6 m/s of 0 rounds either way).
PAPER_CALL = "paper_com_criterion_safe"


@dataclass(frozen=True)
class Push:
    """One push of the records: where it pushed, its margins (m/s), calls and outcome."""

    stance: str
    body: str
    direction_deg: int
    relative: float
    omega: float
    zmp_margin: float
    default_margin: float
    paper_margin: float
    paper_call: bool | None
    angular_momentum_margin: float | None
    calls: dict[str, bool]
    aborted: bool
    fell: bool
    strict_fail: bool

    @property
    def in_band(self) -> bool:
        """Whether the push's relative impulse is in :data:`BAND`."""
        return BAND[0] - 1e-9 <= self.relative <= BAND[1] + 1e-9

    @property
    def one_foot(self) -> bool:
        """Whether the stance stands on one foot (``_foot_`` in its name)."""
        return "_foot_" in self.stance


def candidate_columns(rows: Sequence[dict[str, str]]) -> list[str]:
    """The ``*_safe`` columns of ``pushes.csv`` that are candidates (not standard calls)."""
    columns = rows[0].keys() if rows else []
    return [c for c in columns if c.endswith("_safe") and c not in STANDARD_CALLS]


def pushes(rows: Iterable[dict[str, str]], candidates: Sequence[str]) -> list[Push]:
    """The rows of ``pushes.csv`` as :class:`Push` (aborted ones included, marked)."""
    return [
        Push(
            stance=row["stance"],
            body=row["body"],
            direction_deg=round(float(row["direction_deg"])),
            relative=float(row["relative"]),
            omega=float(row["omega"]),
            zmp_margin=float(row["zmp_margin"]),
            default_margin=float(row["default_margin_mps"]),
            paper_margin=float(row["paper_margin_mps"]),
            paper_call=None if row.get(PAPER_CALL) in (None, "") else flag(row[PAPER_CALL]),
            angular_momentum_margin=number(row.get(AM_COLUMN)),
            calls={"default": flag(row["default_safe"])}
            | {column: flag(row.get(column)) for column in candidates},
            aborted=row["outcome"] == "aborted",
            fell=flag(row["fell"]),
            strict_fail=flag(row["strict_fail"]),
        )
        for row in rows
    ]


Call = Callable[[Push], bool]


def _paper_at_10mm(push: Push) -> bool:
    """The paper's call at 10 mm: push-test's own when the run's margin is 10 mm."""
    if push.paper_call is not None and abs(push.zmp_margin - PAPER_MARGIN) < 1e-12:
        return push.paper_call
    return push.paper_margin >= push.omega * PAPER_MARGIN - 1e-12


def _candidate_call(column: str) -> Call:
    """A candidate's own call, from its column."""

    def call(push: Push) -> bool:
        return push.calls[column]

    return call


def _calls(candidates: Sequence[str]) -> dict[str, Call]:
    """The criteria scored, by name: push -> called safe."""
    criteria: dict[str, Call] = {
        "default": lambda p: p.calls["default"],
        "noreach": lambda p: p.default_margin >= p.omega * p.zmp_margin - 1e-12,
        "paper0": lambda p: p.paper_margin >= -1e-12,
        "paper10": _paper_at_10mm,
        "am": lambda p: (p.angular_momentum_margin or 0.0) >= -1e-12,
    }
    for column in candidates:
        criteria[column] = _candidate_call(column)
    return criteria


def _score(
    scored: Sequence[Push], call: Call, failed: Callable[[Push], bool], band: bool = True
) -> tuple[int, int, int, int]:
    """(failed and called safe, called safe, standing called safe, standing) of the pushes."""
    chosen = [p for p in scored if not p.aborted and (p.in_band or not band)]
    safe = [p for p in chosen if call(p)]
    stood = [p for p in chosen if not failed(p)]
    return sum(failed(p) for p in safe), len(safe), sum(call(p) for p in stood), len(stood)


def _strict(push: Push) -> bool:
    return push.strict_fail


def _fell(push: Push) -> bool:
    return push.fell


def _by_stance(all_pushes: Sequence[Push]) -> dict[tuple[str, str], list[Push]]:
    groups: dict[tuple[str, str], list[Push]] = {}
    for push in all_pushes:
        groups.setdefault((push.stance, push.body), []).append(push)
    return groups


def stance_table(all_pushes: Sequence[Push], candidates: Sequence[str]) -> str:
    """The per stance and body table (band, strict unless said), candidates before ``aborted``."""
    criteria = _calls(candidates)
    header = [
        "stance",
        "body",
        "default: P(failed strictly | safe), band",
        "default: standing called safe",
        "default, all pushes",
        "lenient (fell), band",
        "without the reach, band",
        "without the reach: standing called safe",
        "paper, 0 mm",
        "paper, 10 mm",
    ]
    for column in candidates:
        header += [f"{column}: P(failed strictly | safe), band", f"{column}: standing called safe"]
    header.append("aborted")
    rows = []
    for (stance, body), group in _by_stance(all_pushes).items():
        k, n, ks, ns = _score(group, criteria["default"], _strict)
        ka, na, _, _ = _score(group, criteria["default"], _strict, band=False)
        kl, nl, _, _ = _score(group, criteria["default"], _fell)
        kr, nr, ksr, nsr = _score(group, criteria["noreach"], _strict)
        k0, n0, _, _ = _score(group, criteria["paper0"], _strict)
        k1, n1, _, _ = _score(group, criteria["paper10"], _strict)
        row = [f"{stance} ({1000 * group[0].zmp_margin:.0f} mm)", body]
        row += [rate(k, n), called_safe(ks, ns, "0"), rate(ka, na), rate(kl, nl)]
        row += [rate(kr, nr), called_safe(ksr, nsr, "0"), rate(k0, n0), rate(k1, n1)]
        for column in candidates:
            kc, nc, ksc, nsc = _score(group, criteria[column], _strict)
            row += [rate(kc, nc), called_safe(ksc, nsc, "0")]
        row.append(str(sum(p.aborted for p in group)))
        rows.append(row)
    return table(header, rows)


def _groups(all_pushes: Sequence[Push], extra: Sequence[tuple[str, str]]) -> dict[str, list[Push]]:
    """The pooled groups, in order, each left out when empty.

    All, one foot, two feet, ``extra`` (label, regex searched in the stance's name), sideways
    on two feet, each body, each body on two feet.
    """
    groups: dict[str, list[Push]] = {"all": list(all_pushes)}
    groups["one foot"] = [p for p in all_pushes if p.one_foot]
    groups["two feet"] = [p for p in all_pushes if not p.one_foot]
    for label, pattern in extra:
        groups[label] = [p for p in all_pushes if re.search(pattern, p.stance)]
    groups["sideways (90°, 270°), two feet"] = [
        p for p in groups["two feet"] if p.direction_deg in (90, 270)
    ]
    bodies = list(dict.fromkeys(p.body for p in all_pushes))
    for body in bodies:
        groups[body] = [p for p in all_pushes if p.body == body]
    for body in bodies:
        groups[f"{body}, two feet"] = [p for p in groups["two feet"] if p.body == body]
    return {label: group for label, group in groups.items() if group}


def pooled_table(
    all_pushes: Sequence[Push],
    candidates: Sequence[str],
    extra_groups: Sequence[tuple[str, str]] = (),
) -> str:
    """The pooled table (band, strict): each criterion's false-safe rate and standing called safe.

    The angular momentum term's columns are there when the records carry its margin.
    """
    criteria = _calls(candidates)
    names = [
        ("default", "default: P(failed strictly | safe), band", "default: standing called safe"),
        (
            "noreach",
            "without the reach: P(failed strictly | safe)",
            "without the reach: standing called safe",
        ),
    ]
    if all(p.angular_momentum_margin is not None for p in all_pushes):
        names.append(
            (
                "am",
                "without kappa and the reach (angular momentum term, 10 mm): "
                "P(failed strictly | safe)",
                "its standing called safe",
            )
        )
    names.append(
        (
            "paper10",
            "paper 10 mm: P(failed strictly | safe), band",
            "paper 10 mm: standing called safe",
        )
    )
    names += [
        (c, f"{c}: P(failed strictly | safe), band", f"{c}: standing called safe")
        for c in candidates
    ]
    header = ["pushes"] + [label for _, *labels in names for label in labels]
    rows = []
    for label, group in _groups(all_pushes, extra_groups).items():
        row = [label]
        for name, *_ in names:
            k, n, ks, ns = _score(group, criteria[name], _strict)
            row += [rate(k, n), called_safe(ks, ns)]
        rows.append(row)
    return table(header, rows)
