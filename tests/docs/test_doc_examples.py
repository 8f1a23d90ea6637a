"""Every code example of README.md and docs/ runs (issue 29).

- A ```python block runs as it is, in a fresh namespace, in a temporary folder; a block that
  needs a missing extra is skipped, naming it. Consecutive blocks of one page do not share
  names: each block is whole.
- Each ``impact-balance ...`` line of a ```bash, ```sh or ```console block (``$ `` prompts
  allowed, ``# comments`` ignored) is parsed by the command line's own parser: every option the
  docs show exists and takes the values shown. The cheap commands (``analyze``,
  ``scenarios``, ``robots``, ``frames``, ``phase-portrait``, ``--version``) without
  placeholders (``SCENARIO``, ``DIR``, ``my.yaml``) also run, and must exit 0.
- A block that is not meant to run (a fragment inside a control loop, a command on the
  reader's own files) has the line ``<!-- docs-test: skip (reason) -->`` right above its
  fence; a skipped block must say why. ``<!-- docs-test: slow -->`` there marks a block that
  takes over about 5 s ``slow``.
- The reference pages name every key: every key of ``analyze --json`` is in
  docs/reference/json.md, every key of the scenario model in docs/reference/scenario.md.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pytest

from impact_balance import cli
from impact_balance.cli._options import CommandLineError
from impact_balance.extras import EXTRAS, installed
from tests.helpers.cli import run_cli

ROOT = Path(__file__).resolve().parents[2]
SKIP = re.compile(r"^<!-- docs-test: skip \((.+)\) -->$")
SLOW = "<!-- docs-test: slow -->"
FENCE = re.compile(r"^(\s*)```(\w*)\s*$")
#: Commands cheap enough to run in the fast suite (well under a second once loaded).
CHEAP = {"analyze", "scenarios", "robots", "frames", "phase-portrait"}
#: A token that stands for the reader's own value.
PLACEHOLDER = re.compile(r"^[A-Z][A-Z_0-9]*$|\.(ya?ml|parquet|csv)$|[<>$]")


@dataclass(frozen=True)
class Block:
    """One fenced code block: where it is, its language, its text, and its skip reason."""

    path: Path
    line: int
    lang: str
    text: str
    skip: str | None
    slow: bool = False

    @property
    def id(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def doc_files() -> list[Path]:
    """README.md and every page of docs/."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def blocks(path: Path) -> list[Block]:
    """The fenced code blocks of a Markdown file."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, lang = m.group(1), m.group(2)
        j = i + 1
        while j < len(lines) and lines[j].strip() != "```":
            j += 1
        body = "\n".join(line.removeprefix(indent) for line in lines[i + 1 : j])
        above = lines[i - 1].strip() if i > 0 else ""
        skip = SKIP.match(above)
        found.append(Block(path, i + 1, lang, body, skip.group(1) if skip else None, above == SLOW))
        i = j + 1
    return found


ALL = [b for path in doc_files() for b in blocks(path)]
PYTHON = [
    pytest.param(b, id=b.id, marks=[pytest.mark.slow] if b.slow else [])
    for b in ALL
    if b.lang == "python"
]


def command_lines(block: Block) -> list[str]:
    """The ``impact-balance`` command lines of a shell block, without prompts and comments.

    Continued lines (``\\``) are joined; a synopsis's brackets (``[--json]``) are dropped, so
    that every option it shows is parsed.
    """
    out = []
    for raw in block.text.replace("\\\n", " ").splitlines():
        line = raw.strip().removeprefix("$ ")
        if line.startswith("impact-balance "):
            line = line.split(" #", 1)[0].strip()
            out.append(re.sub(r"\[(--?[\w-]+[^\[\]]*)\]", r"\1", line))
    return out


def argv_of(line: str) -> list[str]:
    """The arguments of a command line, up to a shell operator; ``a|b`` alternatives: ``a``."""
    argv = []
    for token in shlex.split(line)[1:]:
        if token in (">", ">>", "|", "&&", ";", "2>", "&"):
            break
        if token != "...":
            argv.append(token.split("|")[0] if token.startswith("-") or "|" in token else token)
    return argv


COMMANDS = [
    pytest.param(b, line, id=f"{b.id}:{line.split()[1]}")
    for b in ALL
    if b.lang in ("bash", "sh", "shell", "console")
    for line in command_lines(b)
]


def _missing_extra(exc: BaseException) -> str | None:
    """The extra whose module ``exc`` says is missing, if any."""
    name = getattr(exc, "name", None) or ""
    for extra, modules in EXTRAS.items():
        if name.split(".")[0] in modules and not installed(name.split(".")[0]):
            return extra
    extra = getattr(exc, "extra", None)
    return extra if isinstance(extra, str) else None


def test_there_are_examples_to_run():
    assert len(PYTHON) >= 8 and len(COMMANDS) >= 20
    assert all(b.skip is None or b.skip.strip() for b in ALL)


def test_a_skip_marker_sits_right_above_a_block():
    for path in doc_files():
        lines = path.read_text(encoding="utf-8").splitlines()
        for k, line in enumerate(lines):
            if line.strip().startswith("<!-- docs-test"):
                assert SKIP.match(line.strip()) or line.strip() == SLOW, f"{path}:{k + 1}"
                assert k + 1 < len(lines) and FENCE.match(lines[k + 1]), f"{path}:{k + 1}"


@pytest.mark.parametrize("block", PYTHON)
def test_python_example_runs(block, tmp_path, monkeypatch):
    if block.skip:
        pytest.skip(block.skip)
    monkeypatch.chdir(tmp_path)
    code = compile(block.text, block.id, "exec")
    try:
        exec(code, {"__name__": "__docs_example__"})
    except ImportError as exc:
        extra = _missing_extra(exc)
        if extra is None:
            raise
        pytest.skip(f"needs the {extra} extra")


@pytest.mark.parametrize(("block", "line"), COMMANDS)
def test_command_line_example_parses_and_cheap_ones_run(block, line, tmp_path, monkeypatch, capsys):
    if block.skip:
        pytest.skip(block.skip)
    monkeypatch.chdir(tmp_path)
    argv = argv_of(line)
    parser, _ = cli._parser()
    try:
        parser.parse_args(argv)
    except CommandLineError as exc:  # an option's own check: fine for a placeholder value
        assert PLACEHOLDER.search(str(exc.value)), f"{block.id}: {line}: {exc}"
        return
    except ImportError as exc:  # an option's check that needs an extra (sweep --scheduler)
        extra = _missing_extra(exc)
        if extra is None:
            raise
        pytest.skip(f"needs the {extra} extra")
    except SystemExit as exc:  # --help and --version end here, with status 0
        out, err = capsys.readouterr()
        assert exc.code in (0, None), f"{block.id}: {line}: {err.strip()}"
        return
    capsys.readouterr()
    if argv[0] not in CHEAP or any(PLACEHOLDER.search(token) for token in argv):
        return
    if any(a in ("--plots", "--plot") for a in argv) and not installed("matplotlib"):
        pytest.skip("needs the plots extra")
    rc, out, err = run_cli(capsys, *argv)
    assert rc == 0, f"{block.id}: {line}: {err.strip()}"
    assert out.strip()


def _keys(value: object) -> set[str]:
    """Every key of a JSON document, at any depth."""
    if isinstance(value, dict):
        return set(value) | {k for v in value.values() for k in _keys(v)}
    if isinstance(value, list):
        return {k for v in value for k in _keys(v)}
    return set()


def test_every_analyze_json_key_is_in_the_reference(capsys):
    import json

    from impact_balance.balance.infeasibility import BindingJoint, CannotBalanceReason

    rc, out, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--qp", "--json")
    assert rc == 0, err
    keys = _keys(json.loads(out))
    reason = CannotBalanceReason("torque_limits", "why", (BindingJoint("j", 30.0, 1.4),), 1.2)
    keys |= _keys(reason.to_dict()) | {"kernel_loading", "kernel_compiling", "diagnosis"}
    assert {"qp", "approach_speed", "min_scale"} <= keys  # the run covers what it should
    page = (ROOT / "docs" / "reference" / "json.md").read_text(encoding="utf-8")
    missing = sorted(k for k in keys if f"`{k}`" not in page)
    assert not missing, f"docs/reference/json.md does not name {missing}"


def test_every_scenario_key_is_in_the_reference():
    import typing

    import pydantic

    from impact_balance.scenario.schema import Scenario

    def fields(model: type[pydantic.BaseModel]) -> set[str]:
        names = set()
        for name, field in model.model_fields.items():
            if field.exclude:
                continue
            names.add(name)
            for t in (field.annotation, *typing.get_args(field.annotation)):
                for u in (t, *typing.get_args(t)):
                    if isinstance(u, type) and issubclass(u, pydantic.BaseModel):
                        names |= fields(u)
        return names

    keys = fields(Scenario)
    assert {"contacts", "restitution", "peak_factor", "urdf", "angle"} <= keys
    page = (ROOT / "docs" / "reference" / "scenario.md").read_text(encoding="utf-8")
    missing = sorted(k for k in keys if not re.search(rf"(^|[\s{{,]){k}:", page, re.MULTILINE))
    assert not missing, f"docs/reference/scenario.md does not show {missing}"


def test_readme_links_resolve():
    """README's relative links (into the site's pages, the project files) point at files."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
    local = [link for link in links if "://" not in link]
    assert len(local) >= 20
    missing = sorted(link for link in local if not (ROOT / link).exists())
    assert not missing, f"README.md links to missing files: {missing}"
    assert len(text.splitlines()) <= 250


def test_license_and_citation_match_the_project():
    import tomllib
    import yaml

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "BSD-3-Clause"
    license_text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert license_text.startswith("BSD 3-Clause License")
    assert "the impact-balance developers" in license_text
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0" and cff["license"] == project["license"]
    assert cff["version"] == project["version"]
    paper = cff["preferred-citation"]
    tex = "\n".join(p.read_text(errors="replace") for p in (ROOT / "docs").glob("*.md"))
    assert paper["title"] == "Impact-Aware Multi-Contact Balance Criteria" and paper["title"] in tex
    assert [a["family-names"] for a in paper["authors"]] == ["Wang", "Tanguy", "Kheddar"]
    assert "Keep a Changelog" in (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert any(c.startswith("Programming Language :: Python :: 3") for c in project["classifiers"])


def test_the_generated_cli_reference_has_every_command_and_option():
    import argparse
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "cli_reference", ROOT / "docs" / "hooks" / "cli_reference.py"
    )
    assert spec is not None and spec.loader is not None
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    page = hook.on_page_markdown(f"# Command line\n\n{hook.MARKER}\n")
    assert hook.MARKER not in page
    parser, _ = cli._parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert len(sub.choices) >= 14
    for name, command in sub.choices.items():
        assert f"## `impact-balance {name}`" in page
        for action in command._actions:
            if action.help == argparse.SUPPRESS or isinstance(action, argparse._HelpAction):
                continue
            shown = action.option_strings or [action.metavar or action.dest]
            assert all(f"`{s}" in page for s in shown), (name, shown)
    # The API markers: every public name of impact_balance lives in some subpackage.
    names = hook.public_names()
    import impact_balance

    assert set(names) == set(impact_balance.__all__) - {"__version__"}
