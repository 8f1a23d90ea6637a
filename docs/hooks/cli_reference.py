"""mkdocs hook: the reference pages generated from the code, so that they cannot drift.

- A page that holds the line ``<!-- cli-reference -->`` gets, in its place, one section per
  command of ``impact-balance`` (its paragraph, usage, every option with its default and help,
  and its example), built from the parser the command line itself uses.
  ``python docs/hooks/cli_reference.py`` prints that Markdown.
- A line ``<!-- api: PACKAGE ... -->`` becomes one mkdocstrings directive per public name of
  ``impact_balance`` (``impact_balance.__all__``) that lives in one of those subpackages. After
  the build, every public name must have been placed exactly once, or the build fails.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import re
import sys
from collections import Counter
from pathlib import Path
from typing import Any

MARKER = "<!-- cli-reference -->"
API_MARKER = re.compile(r"^<!-- api: ([\w ]+) -->$", re.MULTILINE)

__all__ = [
    "API_MARKER",
    "MARKER",
    "api_directives",
    "cli_reference",
    "on_page_markdown",
    "on_post_build",
    "on_pre_build",
    "public_names",
]

#: How many times each public name was placed on a page during this build.
_placed: Counter[str] = Counter()


def _use_source_tree() -> None:
    """Import ``impact_balance`` from this tree's ``src/`` (what mkdocstrings documents)."""
    src = Path(__file__).resolve().parents[2] / "src"
    if str(src) not in sys.path:
        sys.path.insert(0, str(src))


def public_names() -> dict[str, tuple[str, str]]:
    """Every name of ``impact_balance.__all__``: (its subpackage, the path that defines it)."""
    _use_source_tree()
    import impact_balance

    exports: dict[str, str] = impact_balance._EXPORTS
    names = {}
    for name in impact_balance.__all__:
        if name not in exports:  # __version__ and the like: no page
            continue
        module = importlib.import_module("impact_balance" + exports[name])
        obj = getattr(module, name)
        home = module.__name__
        if inspect.isclass(obj) or inspect.isfunction(obj):
            home = obj.__module__
        names[name] = (exports[name].lstrip(".").split(".")[0], f"{home}.{name}")
    return names


def api_directives(packages: list[str]) -> str:
    """The mkdocstrings directives of the public names that live in ``packages``."""
    lines = []
    for name, (package, path) in public_names().items():
        if package in packages:
            _placed[name] += 1
            lines += [f"::: {path}", ""]
    if not lines:
        raise ValueError(f"<!-- api: {' '.join(packages)} -->: no public name lives there")
    return "\n".join(lines)


def _parser() -> argparse.ArgumentParser:
    """The ``impact-balance`` parser, exactly as the command line builds it."""
    _use_source_tree()
    # The command line's own (private) builder: the reference shows what `main` parses.
    from impact_balance.cli import _parser as build

    parser, _ = build()
    return parser


def _cell(text: str) -> str:
    """``text`` made safe inside a Markdown table cell."""
    return " ".join(text.split()).replace("|", "\\|")


def _option_name(action: argparse.Action) -> str:
    """``--speed V`` / ``SCENARIO``: the option as it is typed."""
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    metavar = ""
    if action.nargs != 0:
        formatter = argparse.HelpFormatter("impact-balance")
        metavar = " " + formatter._format_args(action, action.dest.upper())
    return ", ".join(f"`{s}{metavar}`" for s in action.option_strings)


def _help(action: argparse.Action, parser: argparse.ArgumentParser) -> str:
    """The option's help with ``%(default)s`` and friends expanded, and its choices."""
    text = action.help or ""
    if "%" in text:
        formatter = parser._get_formatter()
        text = formatter._expand_help(action)
    if action.choices is not None and not isinstance(action.choices, dict):
        choices = ", ".join(f"`{c}`" for c in action.choices)
        if choices not in text:
            text += f" (one of {choices})"
    return _cell(text)


def _default(action: argparse.Action) -> str:
    """The default as the reader would type it, or an empty cell."""
    if action.nargs == 0 or action.default in (None, argparse.SUPPRESS):
        return ""
    if isinstance(action.default, (list, tuple)):
        return _cell(" ".join(f"`{d}`" for d in action.default))
    return f"`{_cell(str(action.default))}`"


def _usage(parser: argparse.ArgumentParser) -> str:
    """The usage block without its ``usage:`` label (continuation lines kept aligned)."""
    lines = parser.format_usage().strip().splitlines()
    return "\n".join(line.removeprefix("usage: ").removeprefix(" " * 7) for line in lines)


def _command(name: str, parser: argparse.ArgumentParser) -> list[str]:
    """One command's section."""
    lines = [f"## `impact-balance {name}`", ""]
    if parser.description:
        lines += [" ".join(parser.description.split()), ""]
    lines += ["```text", _usage(parser), "```", ""]
    rows = [
        a
        for a in parser._actions
        if a.help != argparse.SUPPRESS and not isinstance(a, argparse._HelpAction)
    ]
    if rows:
        lines += ["| argument | default | meaning |", "|---|---|---|"]
        lines += [f"| {_option_name(a)} | {_default(a)} | {_help(a, parser)} |" for a in rows]
        lines.append("")
    if parser.epilog:
        example = [line.strip() for line in parser.epilog.splitlines() if line.strip()]
        example = [line for line in example if line != "Example:"]
        lines += ["Example:", "", "```text", *example, "```", ""]
    return lines


def cli_reference() -> str:
    """Every command of ``impact-balance``, as Markdown (one ``##`` section per command)."""
    parser = _parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    lines = ["## `impact-balance`", "", parser.description or "", ""]
    lines += ["```text", _usage(parser), "```", ""]
    lines += ["| argument | meaning |", "|---|---|"]
    for action in parser._actions:
        if action.option_strings and not isinstance(action, argparse._HelpAction):
            lines.append(f"| {_option_name(action)} | {_help(action, parser)} |")
    lines.append("")
    for name, command in sub.choices.items():
        lines += _command(name, command)
    return "\n".join(lines)


def on_page_markdown(markdown: str, **kwargs: Any) -> str:
    """On each page: put the generated references in place of their markers."""
    if MARKER in markdown:
        markdown = markdown.replace(MARKER, cli_reference())
    return API_MARKER.sub(lambda m: api_directives(m.group(1).split()), markdown)


def on_pre_build(**kwargs: Any) -> None:
    """Before a build: a new build places every public name anew."""
    _placed.clear()


def on_post_build(**kwargs: Any) -> None:
    """After a build: fail unless every public name was placed on exactly one page."""
    names = public_names()
    missing = sorted(n for n in names if _placed[n] == 0)
    twice = sorted(n for n in names if _placed[n] > 1)
    if missing or twice:
        raise ValueError(
            f"API reference: public names on no page: {missing}; on more than one: {twice} "
            "(add their subpackage to a `<!-- api: ... -->` line of docs/reference/api/)"
        )


if __name__ == "__main__":
    print(cli_reference())
