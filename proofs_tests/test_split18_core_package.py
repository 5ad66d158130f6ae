"""The package ``langur.core`` (split18, issue 15's renovation): each public name is declared in one of
its modules and handed on by the package, the same object, so ``from langur.core import X`` reads what the
module declaring ``X`` holds."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import langur.core

PACKAGE = Path(langur.core.__file__).parent


def _declared() -> dict[str, list[str]]:
    """Public names defined at the top level of each module of the package (not imported ones)."""
    out: dict[str, list[str]] = {}
    for path in sorted(PACKAGE.glob("*.py")):
        if path.name == "__init__.py":
            continue
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names = [node.name]
            elif isinstance(node, ast.Assign):
                names = [t.id for t in node.targets if isinstance(t, ast.Name)]
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                names = [node.target.id]
            else:
                names = []
            for name in names:
                if not name.startswith("_"):
                    out.setdefault(name, []).append(path.stem)
    return out


def test_every_public_name_is_declared_once_and_handed_on_as_is():
    declared = _declared()
    assert {n: ms for n, ms in declared.items() if len(ms) > 1} == {}
    assert set(langur.core.__all__) == set(declared)
    for name, (module,) in declared.items():
        owner = importlib.import_module(f"langur.core.{module}")
        assert getattr(langur.core, name) is getattr(owner, name), name
