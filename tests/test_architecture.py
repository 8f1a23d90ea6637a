"""The package's shape: pipeline-order layers, no import circle, few top-level modules, short
functions.

These are the rules of the house (CONTRIBUTING.md): a module imports only from its own layer or the
ones below it, a private name (``_x``) is imported only inside its own package, the top level keeps
the public API, exceptions and a few shared constants, and no function outside the compiled kernels
is over 100 lines.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "impact_balance"

#: Layers from the bottom up: a module may import from its own layer and the ones below.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("exceptions", "constants", "ranges", "_jit", "extras", "exit_status", "json_values", "files"),
    ("geometry", "solvers"),
    ("robot",),
    ("contacts",),
    ("projection",),
    ("balance",),
    ("impact",),
    ("criteria",),
    ("scenario",),
    ("analysis", "governor", "authoring"),
    ("logs", "plots"),
    ("sim",),
    ("sweep",),
    ("gui",),
    ("cli",),
)
#: Modules whose functions are compiled kernels (long by nature: one loop, no calls).
KERNELS = {"impact_balance.projection.kernel"}
MAX_FUNCTION_LINES = 100
MAX_TOP_LEVEL_MODULES = 10


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


MODULES = _modules()


def _imports(name: str) -> list[tuple[str, str, int]]:
    """(module imported, name imported or '', line) for every import of the package in a module."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join([*base, node.module] if node.module else base)
            else:
                target = node.module or ""
            if target.split(".")[0] == "impact_balance":
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    if full in MODULES:
                        out.append((full, "", node.lineno))
                    else:
                        out.append((target, alias.name, node.lineno))
        elif isinstance(node, ast.Import):
            out += [
                (a.name, "", node.lineno)
                for a in node.names
                if a.name.split(".")[0] == "impact_balance"
            ]
    return out


def _layer(name: str) -> int | None:
    parts = name.split(".")
    if len(parts) < 2 or parts[1] == "__main__":
        return None  # the public API and ``python -m``: above everything
    for i, layer in enumerate(LAYERS):
        if parts[1] in layer:
            return i
    raise AssertionError(f"{name} is in no layer: add its folder to LAYERS")


def _graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {}
    for name in MODULES:
        deps = set()
        for target, _, _ in _imports(name):
            while target not in MODULES and "." in target:
                target = target.rsplit(".", 1)[0]
            if target != name:
                deps.add(target)
        graph[name] = deps
    return graph


def test_top_level_keeps_few_modules():
    top = sorted(p.stem for p in PACKAGE.glob("*.py") if p.stem not in ("__init__", "__main__"))
    assert len(top) <= MAX_TOP_LEVEL_MODULES, top


def test_every_module_sits_in_a_layer():
    for name in MODULES:
        _layer(name)


def test_no_import_from_a_higher_layer():
    wrong = []
    for name in MODULES:
        own = _layer(name)
        if own is None:
            continue
        for target, _, line in _imports(name):
            theirs = _layer(target)
            if theirs is not None and theirs > own:
                wrong.append(f"{name}:{line} imports {target}")
    assert not wrong, "\n".join(wrong)


def test_no_import_circle():
    graph = _graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    assert not circles, circles


def test_private_names_stay_in_their_package():
    wrong = []
    for name in MODULES:
        own_package = name if MODULES[name].name == "__init__.py" else name.rsplit(".", 1)[0]
        for target, imported, line in _imports(name):
            private = imported.startswith("_") or any(
                p.startswith("_") for p in target.split(".")[1:] if p != "_jit"
            )
            target_package = (
                target
                if MODULES.get(target, Path()).name == "__init__.py"
                else target.rsplit(".", 1)[0]
            )
            if private and imported != "__version__" and target_package != own_package:
                wrong.append(f"{name}:{line} imports {target}.{imported}".rstrip("."))
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n not in KERNELS))
def test_functions_are_short(name):
    long = [
        f"{node.name} ({node.end_lineno - node.lineno + 1} lines)"
        for node in ast.walk(ast.parse(MODULES[name].read_text(encoding="utf-8")))
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]
    assert not long, long


def test_every_module_declares_its_public_names():
    missing = [
        name
        for name, path in MODULES.items()
        if path.name != "__main__.py"
        and not any(
            isinstance(n, (ast.Assign, ast.AnnAssign))
            and any(
                getattr(t, "id", None) == "__all__"
                for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
            )
            for n in ast.parse(path.read_text(encoding="utf-8")).body
        )
    ]
    assert not missing, missing
