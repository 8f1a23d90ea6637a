"""Every command's ``--help``: one paragraph that says what it does, and an example that parses."""

from __future__ import annotations

import shlex

import pytest

from impact_balance import cli
from impact_balance.cli.help_text import COMMAND_HELP
from tests.helpers.cli import run_cli as run


def _commands() -> list[str]:
    _, owners = cli._parser()
    return sorted(owners)


def test_every_command_has_a_paragraph_and_an_example():
    assert set(COMMAND_HELP) == set(_commands())


@pytest.mark.parametrize("command", _commands())
def test_help_exits_0_with_the_description_and_an_example(capsys, command):
    with pytest.raises(SystemExit) as info:
        cli.main([command, "--help"])
    out = capsys.readouterr().out
    assert info.value.code == 0
    example = COMMAND_HELP[command][1]
    description = cli._parser()[0]._subparsers._group_actions[0].choices[command].description
    assert len(description.split()) >= 10  # a paragraph
    assert " ".join(description.split()) in " ".join(out.split())
    assert f"Example:\n  {example}" in out


@pytest.mark.parametrize("command", sorted(COMMAND_HELP))
def test_each_example_is_a_valid_command_line(command):
    parser, _ = cli._parser()
    words = shlex.split(COMMAND_HELP[command][1])
    assert words[:2] == ["impact-balance", command]
    args = parser.parse_args(words[1:])
    assert args.command == command


def test_the_robots_example_runs(capsys):
    rc, out, _ = run(capsys, *shlex.split(COMMAND_HELP["robots"][1])[1:])
    assert rc == 0 and "go2" in out
