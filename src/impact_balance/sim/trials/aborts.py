"""Why trials were aborted, said once per reason, and the error of a run that tested nothing.

A trial is ``aborted`` when it went wrong before its disturbance (:mod:`.outcomes`): it tests
nothing. The commands that run trials (``validate``, ``push-test``, ``approach``) list the
distinct reasons with their counts in their text output (:func:`aborted_lines`), and a run
whose trials were all aborted ends with :class:`AllTrialsAbortedError` (exit status 1: the
robot, its controller or the model could not be simulated as the scenario asks), after its
output.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from impact_balance.exceptions import EnvironmentFailure

__all__ = ["AllTrialsAbortedError", "aborted_lines", "aborted_reasons", "check_not_all_aborted"]


class AllTrialsAbortedError(EnvironmentFailure):
    """Every trial of a run was aborted: nothing was tested (exit status 1).

    Attributes:
        field: ``scenario``.
        value: The scenario's name.
        reason: The command, the number of trials and each distinct reason with its count.
        reasons: ``(reason, count)`` pairs, most frequent first.
    """

    def __init__(self, command: str, scenario: str | None, reasons: list[tuple[str, int]]):
        self.reasons = reasons
        n = sum(count for _, count in reasons)
        said = "; ".join(f"{reason} ({count})" for reason, count in reasons)
        super().__init__(
            "scenario",
            scenario,
            f"all {n} trials of {command} were aborted before their disturbance, so nothing was "
            f"tested: {said}",
        )


def _why(trial: Mapping[str, Any]) -> str:
    """One aborted trial's reason in words: its detail, else its reason's code."""
    detail = str(trial.get("detail") or "").strip()
    return detail or str(trial.get("reason") or "no reason recorded")


def aborted_reasons(trials: Iterable[Mapping[str, Any]]) -> list[tuple[str, int]]:
    """The distinct reasons of the aborted trials and how many trials each, most frequent first.

    Args:
        trials: Trial summaries (mappings with ``outcome``, ``reason`` and ``detail``, as
            :meth:`~impact_balance.sim.trials.result.BalanceTrialResult.summary` gives).

    Returns:
        ``(reason, count)`` pairs; ties in the order first seen. Empty when none was aborted.
    """
    counts: dict[str, int] = {}
    for trial in trials:
        if trial.get("outcome") == "aborted":
            why = _why(trial)
            counts[why] = counts.get(why, 0) + 1
    return sorted(counts.items(), key=lambda item: -item[1])


def aborted_lines(trials: Iterable[Mapping[str, Any]], indent: str = "  ") -> list[str]:
    """Text lines ``aborted (N): reason``, one per distinct reason (none when none aborted)."""
    return [f"{indent}aborted ({count}): {why}" for why, count in aborted_reasons(trials)]


def check_not_all_aborted(
    command: str, scenario: str | None, trials: Iterable[Mapping[str, Any]]
) -> None:
    """Raise :class:`AllTrialsAbortedError` when there were trials and every one was aborted."""
    trials = list(trials)
    if trials and all(t.get("outcome") == "aborted" for t in trials):
        raise AllTrialsAbortedError(command, scenario, aborted_reasons(trials))
