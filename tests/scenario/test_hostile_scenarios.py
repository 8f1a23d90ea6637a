"""Fuzz: hostile mutations of the bundled scenario files through ``impact-balance analyze --json``.

The contract, for any file whatever its content: either exit status 2 with stdout empty and
exactly one line ``impact-balance: error: ...`` (bounded in length) on stderr, or exit status 0
with stdout one strict JSON document (no NaN/Infinity) and nothing on stderr. Never a
traceback (an exception escaping ``cli.main`` fails the test), never a numpy RuntimeWarning,
never a hang or unbounded memory (the alias bomb runs in a subprocess under a timeout and an
address-space limit).

Mutations: wrong types, NaN/inf/huge/negative numbers, huge integers, long and odd strings,
deep nesting, lists for scalars, unknown keys, deleted keys (on the parsed mapping, written
back as YAML), and at the text level YAML aliases (shared and cyclic), extends chains and
cycles, and very long names.
"""

from __future__ import annotations

import contextlib
import copy
import io
import os
import resource
import subprocess
import sys
import tempfile
import warnings
from importlib import resources
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance import cli
from impact_balance.exceptions import MESSAGE_CHARS
from tests.helpers.cli import strict_json
from tests.helpers.hostile import apply_mutation, hostile_values, mapping_paths

#: Multiplies the number of examples: IMPACT_BALANCE_FUZZ_SCALE=20 for a deeper search (minutes).
SCALE = float(os.environ.get("IMPACT_BALANCE_FUZZ_SCALE", "1"))
BUNDLED = sorted(
    p.name
    for p in (resources.files("impact_balance") / "scenarios").iterdir()
    if p.name.endswith(".yaml")
)
#: The parsed bundled files (extends unresolved: a mutation may remove it or point it elsewhere).
RAW = {
    name: yaml.safe_load((resources.files("impact_balance") / "scenarios" / name).read_text())
    for name in BUNDLED
}


@st.composite
def mutated_scenarios(draw):
    name = draw(st.sampled_from(BUNDLED))
    data = copy.deepcopy(RAW[name])
    for _ in range(draw(st.integers(1, 3))):
        op = draw(
            st.sampled_from(
                ["number", "number", "number", "set", "set", "delete", "wrap", "unknown_key"]
            )
        )
        numbers = [
            p
            for p, v in mapping_paths(data)
            if isinstance(v, (int, float)) and not isinstance(v, bool)
        ]
        if op == "number" and numbers:
            # A plausible-looking number of any magnitude: often valid, so the analysis runs
            # (and its numerics are exercised) far more often than with arbitrary values.
            path = draw(st.sampled_from(numbers))
            scale = 10.0 ** draw(st.integers(-12, 12))
            data = apply_mutation(data, path, "set", draw(st.sampled_from([1, -1, 0.5, 3])) * scale)
            continue
        paths = [p for p, _ in mapping_paths(data)] if isinstance(data, (dict, list)) else [()]
        path = draw(st.sampled_from(paths))
        if op in ("delete", "number") and not path:
            op = "set"
        data = apply_mutation(data, path, "set" if op == "number" else op, draw(hostile_values))
        if not isinstance(data, (dict, list)):
            break
    return data


def _run(argv: list[str]) -> tuple[int, str, str]:
    """``cli.main`` in process, stdout and stderr captured, RuntimeWarnings recorded."""
    out, err = io.StringIO(), io.StringIO()
    with (
        warnings.catch_warnings(record=True) as caught,
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        warnings.simplefilter("always")
        rc = cli.main(argv)
    runtime = [w for w in caught if issubclass(w.category, RuntimeWarning)]
    assert not runtime, f"RuntimeWarning: {runtime[0].message}"
    return rc, out.getvalue(), err.getvalue()


def assert_clean(rc: int, out: str, err: str) -> None:
    """One clean error line with exit 2, or one strict JSON document with exit 0."""
    assert "Traceback" not in err, err
    if rc == 0:
        document = strict_json(out)
        assert isinstance(document, dict) and "verdict" in document
        assert err == "", err
    else:
        assert rc == 2, (rc, err)
        assert out == "", out[:200]
        lines = err.splitlines()
        assert len(lines) == 1, err[:1000]
        assert lines[0].startswith("impact-balance: error: "), lines[0]
        assert len(lines[0]) <= len("impact-balance: error: ") + MESSAGE_CHARS


@pytest.fixture(scope="module", autouse=True)
def warm_up():
    """Compile the kernel and load the robots once, outside the examples' timing."""
    for name in ("palm_push_two_feet", "g1_two_feet"):
        rc, _out, err = _run(["analyze", name, "--json"])
        assert rc == 0, err


@settings(
    max_examples=int(300 * SCALE),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(data=mutated_scenarios())
def test_mutated_scenario_gives_clean_error_orstrict_json(data):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_text(yaml.safe_dump(data, allow_unicode=True))
        assert_clean(*_run(["analyze", str(path), "--json"]))


# -- text-level mutations: aliases, extends, names ---------------------------------------
def _alias_text(base: str, fan: int, levels: int) -> str:
    """A file whose first key is an alias tree that expands to fan**levels strings."""
    lines = [f"l0: &l0 [{', '.join(['x'] * fan)}]"]
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * fan)}]")
    return "\n".join(lines) + "\n" + base


@settings(max_examples=int(60 * SCALE), deadline=None)
@given(
    name=st.sampled_from(BUNDLED),
    kind=st.sampled_from(
        [
            "alias_tree",
            "alias_as_value",
            "cycle",
            "extends_cycle",
            "extends_chain",
            "long_extends",
            "deep_flow",
            "deep_block",
            "merge_key",
            "duplicate_key",
            "many_keys",
            "fifo_extends",
        ]
    ),
    size=st.integers(1, 40),
)
def test_text_mutation_gives_clean_error_orstrict_json(name, kind, size):
    base = (resources.files("impact_balance") / "scenarios" / name).read_text()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "fuzz.yaml"
        if kind == "alias_tree":
            text = _alias_text(base, fan=size + 1, levels=min(size, 9))
        elif kind == "alias_as_value":  # the contacts themselves are a shared alias tree
            text = (
                _alias_text(
                    base.replace("contacts:", "contacts_original:", 1), size + 1, min(size, 9)
                )
                + f"contacts: *l{min(size, 9) - 1}\n"
            )
        elif kind == "cycle":
            text = base + "\ncyclic: &c [1, *c]\n"
        elif kind == "extends_cycle":
            (tmp / "other.yaml").write_text("extends: fuzz.yaml\n")
            text = "extends: other.yaml\n" + base.replace("extends:", "# extends:")
        elif kind == "extends_chain":
            for i in range(size):
                (tmp / f"c{i}.yaml").write_text(
                    f"extends: c{i + 1}.yaml\n" if i + 1 < size else f"extends: {name[:-5]}\n"
                )
            text = "extends: c0.yaml\n"
        elif kind == "long_extends":
            text = f"extends: {'e' * (200 + 10 * size)}\n"
        elif kind == "deep_flow":
            text = base + "\nextra: " + "[" * (10 * size) + "]" * (10 * size) + "\n"
        elif kind == "deep_block":
            text = (
                base
                + "\n"
                + "".join(f"{'  ' * i}k{i}:\n" for i in range(5 * size))
                + f"{'  ' * 5 * size}v: 1\n"
            )
        elif kind == "duplicate_key":  # a top-level key of the file given again
            key = next(k for k in yaml.safe_load(base) if k != "extends")
            text = base + f"\n{key}: {yaml.safe_load(base)[key]!r}\n"
        elif kind == "many_keys":
            text = base + "".join(f"\nk{i}: {i}" for i in range(200 * size)) + "\n"
        elif kind == "fifo_extends":
            os.mkfifo(tmp / "pipe.yaml")
            text = "extends: pipe.yaml\n"
        else:  # merge keys over an anchored contact
            text = (
                base
                + "\ndefaults: &d {friction: 0.7, size: [0.2, 0.1]}\n"
                + "contacts: [{<<: *d, frame: left_sole_link}, {<<: *d, frame: right_sole_link}]\n"
            )
        path.write_text(text)
        rc, out, err = _run(["analyze", str(path), "--json"])
        assert_clean(rc, out, err)
        refusal = {"duplicate_key": "duplicate key", "fifo_extends": "FIFO"}.get(kind)
        if kind == "many_keys" and 200 * size > 1000:
            refusal = "more than 1000 keys"
        if refusal is not None:
            assert rc == 2 and refusal in err, (kind, err)


# -- real processes: bounded time and memory -------------------------------------------
def _bomb(fan: int = 9, levels: int = 9) -> str:
    """A ~400-byte file whose `name` stands for fan**levels strings ("billion laughs"). The
    anchors sit in `impact`, validated after `name`, so the first error is about the bomb's
    value (whose full repr took 8 s and 900 MB for 9**8 strings, and was printed: 226 MB)."""
    lines = ["impact:", f"  - &l0 [{', '.join(['x'] * fan)}]"]
    lines += [f"  - &l{i} [{', '.join([f'*l{i - 1}'] * fan)}]" for i in range(1, levels)]
    return "\n".join(lines) + f"\nname: *l{levels - 1}\ncontacts: []\n"


ALIAS_BOMB = _bomb()


def _limited_memory():  # runs in the child: 1.5 GB of address space
    resource.setrlimit(resource.RLIMIT_AS, (1_500_000_000, 1_500_000_000))


@pytest.mark.parametrize("argv", [["analyze", "{path}"], ["analyze", "{path}", "--json"]])
def test_alias_bomb_in_a_real_process_is_refused_quickly(tmp_path, argv):
    path = tmp_path / "bomb.yaml"
    path.write_text(ALIAS_BOMB)
    assert len(ALIAS_BOMB) < 500
    proc = subprocess.run(
        [sys.executable, "-m", "impact_balance", *(a.format(path=path) for a in argv)],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_limited_memory,
    )
    err = [
        line for line in proc.stderr.splitlines() if "compiling the projection kernel" not in line
    ]
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert proc.stdout == ""
    assert len(err) == 1 and err[0].startswith("impact-balance: error: "), proc.stderr[-2000:]
    assert "expands to more than" in err[0]


LOAD = r"""
import resource, sys
from impact_balance.exceptions import ScenarioError
from impact_balance.scenario import load_scenario
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
try:
    load_scenario(sys.argv[1])
    print("LOADED")
except ScenarioError as exc:
    print("REFUSED", str(exc).splitlines()[0][:200])
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("PEAK_KB", before, after)
"""


@pytest.mark.parametrize(
    ("kind", "needle"),
    [("keys", "more than 1000 keys"), ("duplicates", "duplicate key"), ("nodes", "larger than")],
    ids=["60000-keys", "duplicates", "nodes"],
)
def test_hostile_files_of_2_mb_are_refused_within_50_mb(tmp_path, kind, needle):
    """Files of at most 2 MB are refused, growing the loader's peak by less than 50 MB (the
    imports alone take ~230 MB: the whole stays under 500 MB). Parsed whole, the 60 000 keys
    grew it by 98 MB."""
    if kind == "keys":
        text = "".join(f"k{i}: 1\n" for i in range(60_000))
    elif kind == "duplicates":
        text = "gravity: 9.81\n" * 60_000
    else:  # a huge flat list: many nodes, one key, over the reader's 1 MB
        text = "contacts: [" + ", ".join(["0"] * 600_000) + "]\n"
    path = tmp_path / "hostile.yaml"
    path.write_text(text if kind == "nodes" else text[:1_000_000].rsplit("\n", 1)[0] + "\n")
    assert path.stat().st_size <= 2_000_000
    proc = subprocess.run(
        [sys.executable, "-c", LOAD, str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")},
    )
    assert proc.returncode == 0 and "REFUSED" in proc.stdout, proc.stdout + proc.stderr[-2000:]
    assert needle in proc.stdout
    before, after = (int(x) for x in proc.stdout.split("PEAK_KB")[1].split())
    assert after - before < 50 * 1024, f"loading grew the peak by {(after - before) / 1024:.0f} MB"
