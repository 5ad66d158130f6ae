"""The package's layers point one way (README, "Map"), read from the modules' own imports.

    core            langur, codes, diagnostics, core, primitives, values, timebox, lazy, progress, modules, core_json, observe,
                    gcpause, framestack, records, memo, failures
    sympy bridge    sympy_bridge (⟦·⟧ of Fig. 7 in sympy, names, numbers, time limits), precise (50-digit values)
    front end       syntax/*, typesys, frontend
    exact engine    denote, ddenote, onesided, symbolic/*          Monte Carlo engine  operational/*
    linter          transversality, lint/*
    top             exact, theorem, reproduce, strategies/*, fuzz/*, commands/*, cli, arguments, cliparser, __main__

A module imports only from its own layer or below; the Monte Carlo engine imports only the core
layer (no sympy, no exact engine: the engines stay independent); there is no import cycle; and a
module imports another of the package from inside a function only where :data:`LAZY` says why
(start-up time of commands that never need it), never to dodge a cycle.  A deferred import
through ``langur.lazy.module("langur.…")`` counts as an import of that module (layers, cycles).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent / "langur"

LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("core", ("langur", "langur.codes", "langur.diagnostics", "langur.core", "langur.primitives", "langur.values", "langur.timebox", "langur.lazy",
              "langur.progress", "langur.modules", "langur.core_json", "langur.observe", "langur.gcpause", "langur.framestack",
              "langur.records", "langur.memo", "langur.failures")),
    ("sympy bridge", ("langur.sympy_bridge", "langur.precise")),
    ("front end", ("langur.syntax", "langur.typesys", "langur.frontend")),
    ("exact engine", ("langur.symbolic", "langur.denote", "langur.ddenote", "langur.onesided", "langur.exact_batch")),
    ("linter", ("langur.transversality", "langur.lint")),
    ("top", ("langur.exact", "langur.steps", "langur.theorem", "langur.reproduce", "langur.reference", "langur.engines",
             "langur.strategies", "langur.fuzz", "langur.commands",
             "langur.cli", "langur.arguments", "langur.cliparser", "langur.__main__")),
]
#: The Monte Carlo engine sits beside the exact engine but reads the core layer only.
MONTE_CARLO = "langur.operational"

#: Imports from inside a function, each with its reason (importer, imported).
LAZY: dict[tuple[str, str], str] = {
    ("langur.denote", "langur.symbolic.integrate"): "scipy (0.3 s): only when integrating",
    ("langur.ddenote", "langur.symbolic.integrate"): "scipy (0.3 s): only when integrating",
    ("langur.steps", "langur.symbolic.integrate"): "scipy (0.3 s): only when integrating (show --steps)",
    ("langur.commands._engines", "langur.exact"): "sympy and scipy (0.8 s): not for --engine mc",
    ("langur.commands._engines", "langur.operational"): "not for --engine exact",
    ("langur.commands.render", "langur.exact_batch"): "sympy (0.8 s): only with --exact",
    ("langur.commands._engines", "langur.engines"): "the exact engine (sympy): only when --engine names another engine",
    ("langur.syntax.parser", "langur.syntax.larkload"): "lark (~35 ms): only to report a syntax error, or stale tables",
    ("langur.syntax.parser", "langur.syntax.tables"): "lark (~35 ms): only to report a syntax error, or stale tables",
    ("langur.syntax.lalr", "langur.syntax.grammar_driver"): "the generated tables: read on the first parse; a missing "
    "or broken module is refused (the data is then read off lark)",
}


def _modules() -> dict[str, Path]:
    out = {}
    for path in ROOT.rglob("*.py"):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _resolve(importer: str, node: ast.ImportFrom | ast.Import) -> list[str]:
    """The package's modules an import statement loads."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "langur"]
    if node.level:
        package = importer if MODULES[importer].name == "__init__.py" else importer.rsplit(".", 1)[0]
        for _ in range(node.level - 1):
            package = package.rsplit(".", 1)[0]
        base = package + ("." + node.module if node.module else "")
    else:
        base = node.module or ""
    if base.split(".")[0] != "langur":
        return []
    out = []
    for a in node.names:
        sub = f"{base}.{a.name}"
        out.append(sub if sub in MODULES else base)
    return out


def _imports(name: str) -> list[tuple[str, bool, int]]:
    """(imported module, from inside a function, line) for each import of the package."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    out = []

    def walk(node, inside: bool):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                out.extend((m, inside, child.lineno) for m in _resolve(name, child))
            elif _lazy_target(child):  # lazy.module("langur.…"): an import, deferred (langur/lazy.py)
                out.append((_lazy_target(child), inside, child.lineno))
            walk(child, inside or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))

    walk(tree, False)
    return out


def _lazy_target(node) -> str | None:
    """The package module a ``lazy.module("langur.…")`` call names, else None."""
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "module"
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "lazy" and node.args
            and isinstance(node.args[0], ast.Constant) and str(node.args[0].value).split(".")[0] == "langur"):
        return node.args[0].value
    return None


def layer(name: str) -> int:
    if name == MONTE_CARLO or name.startswith(MONTE_CARLO + "."):
        return 3
    best = None
    for i, (_, prefixes) in enumerate(LAYERS):
        for p in prefixes:
            if (name == p or name.startswith(p + ".")) and (best is None or len(p) > len(best[1])):
                best = (i, p)
    assert best is not None, f"{name} is in no layer: add it to the table above and to the README's map"
    return best[0]


def _is_mc(name: str) -> bool:
    return name == MONTE_CARLO or name.startswith(MONTE_CARLO + ".")


def test_every_module_has_a_layer():
    for name in MODULES:
        layer(name)


def test_imports_point_down():
    wrong = []
    for name in MODULES:
        for target, _, line in _imports(name):
            if target == name:
                continue
            if _is_mc(name) and not _is_mc(target) and layer(target) > 0:
                wrong.append(f"{name}:{line} (Monte Carlo engine) imports {target}")
            elif layer(target) > layer(name) or (_is_mc(target) and not _is_mc(name) and layer(name) == 3):
                wrong.append(f"{name}:{line} ({LAYERS[layer(name)][0]}) imports {target} "
                             f"({LAYERS[layer(target)][0]})")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles():
    graph = {name: {t for t, _, _ in _imports(name) if t != name and t in MODULES} for name in MODULES}
    for name in graph:  # importing a submodule runs its package's __init__ first
        graph[name] |= {p for p in (name.rsplit(".", k)[0] for k in range(1, name.count(".") + 1))
                        if p in MODULES and p != "langur" and not name.startswith(p + ".")}
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(n):
        state[n] = 1
        path.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                pytest.fail("import cycle: " + " → ".join(path[path.index(m):] + [m]))
            if m not in state:
                visit(m)
        path.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)


def test_function_level_imports_are_only_the_listed_lazy_ones():
    found = {(name, target) for name in MODULES for target, inside, _ in _imports(name) if inside}
    assert found <= set(LAZY), "imports inside functions without a reason: " + ", ".join(
        f"{a} → {b}" for a, b in sorted(found - set(LAZY)))
    assert set(LAZY) <= found, "LAZY lists imports that are gone: " + ", ".join(
        f"{a} → {b}" for a, b in sorted(set(LAZY) - found))


def test_the_monte_carlo_engine_loads_no_sympy():
    code = ("import sys, langur.operational, langur.operational.naive; "
            "bad = sorted(m for m in sys.modules if m.split('.')[0] == 'sympy' or m in "
            "('langur.denote', 'langur.ddenote', 'langur.sympy_bridge') or m.startswith('langur.symbolic')); "
            "print(bad); sys.exit(1 if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
