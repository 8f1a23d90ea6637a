"""Optional parts (pip extras): the core works without them, a command that needs a
missing one says which extra to install in one line, and light commands import no heavy part.

Absence is simulated the way Python marks a blocked import: ``sys.modules[name] = None``
(in this process, through monkeypatch), or a meta-path finder that refuses the modules (in a
subprocess, so that nothing already imported by other tests hides the check).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import tomllib

from impact_balance.cli import main
from impact_balance.exceptions import ImpactBalanceError, MissingExtraError
from impact_balance.extras import COMMAND_EXTRAS, EXTRAS, installed

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"
#: Every module of every extra: the core must run with all of them missing.
OPTIONAL = sorted(
    {m for modules in EXTRAS.values() for m in modules} | {"dask", "viser", "imageio"}
)
#: Heavy parts no light command may import.
HEAVY = ("mujoco", "dask", "distributed", "viser", "matplotlib", "pandas", "pyarrow", "imageio")

#: Arguments that reach each command's extra check.
COMMAND_ARGS = {
    "simulate": ["simulate", "palm_push_two_feet"],
    "validate": ["validate", "palm_push_two_feet"],
    "push-test": ["push-test", "palm_push_ramp"],
    "calibrate": ["calibrate", "trials.json"],
    "approach": ["approach", "palm_push_two_feet", "--reference", "0.5"],
    "check-log": ["check-log", "log.parquet", "--scenario", "palm_push_two_feet"],
    "gui": ["gui", "palm_push_two_feet"],
    "sweep": ["sweep", "--list"],
}


def _block(monkeypatch, modules):
    for name in modules:
        monkeypatch.setitem(sys.modules, name, None)


@pytest.mark.parametrize("command", sorted(COMMAND_EXTRAS))
def test_missing_extra_is_one_line_naming_it(command, monkeypatch, capsys):
    extra = COMMAND_EXTRAS[command]
    _block(monkeypatch, EXTRAS[extra][:1])
    assert not installed(EXTRAS[extra][0])
    assert (
        main(COMMAND_ARGS[command]) == 1
    )  # a missing package is the machine's, not the input's: exit 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(
        f"impact-balance: error: {command} needs the '{extra}' extra: "
        f"pip install 'impact-balance[{extra}]'"
    ), err
    assert EXTRAS[extra][0] in err


@pytest.mark.parametrize(
    "argv, option",
    [
        (["analyze", "kick_one_foot", "--plots", "figs"], "analyze --plots"),
        (
            [
                "phase-portrait",
                "--com-height",
                "0.8",
                "--zmp-range",
                "-0.1",
                "0.1",
                "--plot",
                "p.png",
            ],
            "phase-portrait --plot",
        ),
        (["demo"], "demo"),
    ],
)
def test_missing_plots_extra(argv, option, monkeypatch, capsys, tmp_path):
    monkeypatch.chdir(tmp_path)
    _block(monkeypatch, ["matplotlib"])
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert (
        err.startswith(f"impact-balance: error: {option}")
        and "pip install 'impact-balance[plots]'" in err
    ), err
    assert not list(tmp_path.iterdir())  # refused before writing anything


def test_missing_extra_error_carries_its_data():
    exc = MissingExtraError("simulate", "sim", ["mujoco"])
    assert isinstance(exc, ImpactBalanceError) and isinstance(exc, ImportError)
    assert (exc.what, exc.extra, exc.missing) == ("simulate", "sim", ("mujoco",))


def test_pyproject_extras_match_the_checked_modules():
    """What extras.py checks is what pyproject.toml installs, and [all] is every extra."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    dist = {"imageio_ffmpeg": "imageio-ffmpeg", "distributed": "dask"}
    for extra, modules in EXTRAS.items():
        names = {
            r.split("[")[0].split(">")[0].split("<")[0].split("=")[0].strip().lower()
            for r in extras[extra]
        }
        assert {dist.get(m, m) for m in modules} <= names, extra
    assert extras["all"] == [f"impact-balance[{','.join(EXTRAS)}]"]
    core = " ".join(project["dependencies"]).lower()
    for heavy in ("mujoco", "dask", "viser", "matplotlib", "pandas", "pyarrow", "imageio"):
        assert heavy not in core, heavy


_BLOCKER = textwrap.dedent("""
    import sys, importlib.abc
    BLOCKED = {blocked!r}

    class Blocker(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {{name!r}} (blocked by the test)")
            return None

    sys.meta_path.insert(0, Blocker())
""")


def _run(code: str, blocked=OPTIONAL) -> subprocess.CompletedProcess:
    script = _BLOCKER.format(blocked=set(blocked)) + textwrap.dedent(code)
    return subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=300,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": str(Path.home())},
    )


@pytest.mark.slow
def test_core_runs_without_any_extra():
    r = _run("""
        import impact_balance as ib
        a = ib.analyze("palm_push_ramp")
        assert a.verdict == "balanced", a.verdict
        print(round(a.impact.max_contact_velocity, 3))
        from impact_balance.cli import main
        assert main(["analyze", "kick_one_foot", "--json"]) == 0
        assert main(["robots"]) == 0 and main(["scenarios"]) == 0
        assert main(["demo", "--no-plots"]) == 0
    """)
    assert r.returncode == 0, r.stderr
    first = r.stdout.splitlines()[0]
    assert first == "0.788"


@pytest.mark.parametrize(
    "argv, absent",
    [
        (["robots"], (*HEAVY, "numba", "scipy", "pydantic")),
        (["scenarios"], (*HEAVY, "numba", "scipy", "pinocchio", "pydantic", "numpy")),
        (["analyze", "palm_push_two_feet", "--json"], (*HEAVY, "qpsolvers", "numba")),
    ],
)
def test_light_commands_import_no_heavy_part(argv, absent):
    """Nothing blocked: the command simply never imports these."""
    r = _run(
        f"""
        import io, contextlib
        from impact_balance.cli import main
        with contextlib.redirect_stdout(io.StringIO()) as out:
            assert main({argv!r}) == 0
        print(sorted(name for name in {absent!r} if name in sys.modules))
    """,
        blocked=(),
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]", r.stdout


def test_one_shot_analyze_is_interpreted_and_answers_as_the_compiled_kernel():
    """``analyze`` in a fresh process runs the kernels as Python (numba never imported, the
    variable not left behind); its answer is the compiled kernels' to the last digit."""
    r = _run(
        """
        import io, json, os, contextlib
        from impact_balance.cli import main
        with contextlib.redirect_stdout(io.StringIO()) as out:
            assert main(["analyze", "talos_three_contacts", "--json"]) == 0
        assert "numba" not in sys.modules and "IMPACT_BALANCE_JIT" not in os.environ
        from impact_balance._jit import HAVE_NUMBA
        assert not HAVE_NUMBA
        print(out.getvalue())
    """,
        blocked=(),
    )
    assert r.returncode == 0, r.stderr
    interpreted = json.loads(r.stdout)
    from impact_balance import _jit
    from impact_balance.analysis.analyze import analyze

    assert _jit.HAVE_NUMBA  # this process compiles
    compiled = analyze("talos_three_contacts").to_dict()
    for answer in (interpreted, compiled):
        answer.pop("timings_ms")
    assert json.dumps(interpreted, sort_keys=True) == json.dumps(compiled, sort_keys=True)


def test_jit_variable_is_named_once():
    from impact_balance import _jit, cli

    assert cli._JIT_VARIABLE == _jit.JIT_VARIABLE


def test_json_answer_without_extras_is_strict():
    r = _run("""
        from impact_balance.cli import main
        assert main(["analyze", "palm_push_two_feet", "--json"]) == 0
    """)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["verdict"] == "balanced"


def test_readme_test_command_is_what_ci_runs():
    """README's second command (after the venv) and .ci/run install and test the same way."""
    readme = (ROOT / "README.md").read_text()
    block = readme.split("```bash", 1)[1].split("```", 1)[0]
    lines = [line for line in block.splitlines() if line and not line.startswith("#")]
    assert 'pip install ".[all]"' in lines[0]  # the first command installs everything
    test_command = lines[1].split("&& ", 2)[
        2
    ]  # after "python3 -m venv .venv && . .venv/bin/activate &&"
    ci = (ROOT / ".ci" / "run").read_text()
    assert test_command.strip() in ci


def test_compiled_pipeline_cache_is_stamped_with_the_modules_it_embeds(tmp_path):
    """numba stamps a cached function with its own file only; a compiled function that embeds
    another module's compiled functions (the areas pipeline) is also stamped with that
    module's file, so that editing the module makes its cache stale."""
    import importlib.util
    import os

    pytest.importorskip("numba")
    from impact_balance._jit import HAVE_NUMBA, cache_depends_on

    if not HAVE_NUMBA:
        pytest.skip("numba turned off")
    from impact_balance.balance import areas

    cache_file = getattr(getattr(areas._walk_areas, "_cache", None), "_cache_file", None)
    if cache_file is None:
        pytest.skip("numba's cache API moved (its own rule applies)")
    dependency = tmp_path / "dependency.py"
    dependency.write_text("X = 1\n")
    spec = importlib.util.spec_from_file_location("dependency_for_test", dependency)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)

    class Dispatcher:  # the attributes cache_depends_on reads, as numba's dispatcher has them
        class _cache:
            class _cache_file:
                _source_stamp = "own"

    cache_depends_on(Dispatcher, module)
    first = Dispatcher._cache._cache_file._source_stamp
    assert first != "own"
    Dispatcher._cache._cache_file._source_stamp = "own"
    st = os.stat(dependency)
    os.utime(dependency, (st.st_atime, st.st_mtime + 10))
    cache_depends_on(Dispatcher, module)
    assert Dispatcher._cache._cache_file._source_stamp not in ("own", first)
    # The real dispatchers were stamped at import: not numba's own stamp of their file.
    assert isinstance(cache_file._source_stamp, str)
