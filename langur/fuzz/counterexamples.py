"""Counterexamples people can use (``langur fuzz --out DIR``, issue 13): each failing program made
smaller and written as a `.lgr` file whose comment header holds both engines' numbers.

Shrinking a program that was found (not drawn again by hypothesis) works on its surface AST
(:mod:`langur.syntax.surface`): a candidate replaces one node of the body by one of its children
(an operand of ``+ - * /``, a branch of a conditional, the body of a ``let`` whose name it does not
use, an argument of ``min``/``max``), or drops an item the program no longer uses (a ``def``, a
``diffeo``, a parameter); the first candidate, largest cut first, that still loads and still fails
with the same status is kept, until none does or ``budget`` candidates were run (a count, not a
time: the same failure shrinks the same way on any machine).  The file is the program printed
(:func:`langur.strategies.render`, which parses back to the same AST) after a header of ``#``
comment lines: the status, every comparison of the shrunk program (quantity, exact value and
error bound, the other engine's value and standard error), and the program it was shrunk from.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from ..diagnostics import LangurError
from ..syntax import surface as S
from ..syntax.parser import parse_module
from . import bundle, generate

#: Candidates run per failing program at most (each is one unit: both engines).
BUDGET = 40


def _size(t) -> int:
    if isinstance(t, tuple):
        return sum(_size(u) for u in t)
    if hasattr(t, "__dataclass_fields__"):
        return 1 + sum(_size(getattr(t, f)) for f in t.__dataclass_fields__ if f not in ("span", "name_span"))
    return 0


def _children(t: S.STerm) -> list[S.STerm]:
    """What ``t`` may be replaced by (its children of the same sort: terms)."""
    match t:
        case S.BinOp(op, a, b) if op in "+-*/":
            return [a, b]
        case S.BinOp("^", a, _) | S.Neg(a):
            return [a]
        case S.IfCmp(_, _, _, s, r) | S.IfGe0S(_, s, r) | S.IfLogic(_, s, r):
            return [s, r]
        case S.LetIn(n, _, body) if n not in generate.strategies.terms.names_in(body):
            return [body]
        case S.Apply("min" | "max", args):
            return list(args)
    return []


def _replacements(t: S.STerm):
    """Every term obtained from ``t`` by replacing one node by one of its children."""
    for c in _children(t):
        yield c
    if not hasattr(t, "__dataclass_fields__"):
        return
    for f in t.__dataclass_fields__:
        if f in ("span", "name_span"):
            continue
        v = getattr(t, f)
        if isinstance(v, tuple):
            for i, u in enumerate(v):
                if hasattr(u, "__dataclass_fields__") and not isinstance(u, (S.Num, S.Name)):
                    for r in _replacements(u):
                        yield type(t)(**{**_fields(t), f: (*v[:i], r, *v[i + 1:])})
        elif hasattr(v, "__dataclass_fields__") and not isinstance(v, (S.Num, S.Name, str)):
            for r in _replacements(v):
                yield type(t)(**{**_fields(t), f: r})


def _fields(t) -> dict:
    return {f: getattr(t, f) for f in t.__dataclass_fields__ if f not in ("span", "name_span")}


def _unused_items(m: S.ModuleS) -> list[S.ModuleS]:
    """``m`` without one item (or one parameter) its program no longer mentions."""
    used = generate.strategies.terms.names_in((m.program.body, m.program.domain,
                                               *(i for i in m.items if isinstance(i, S.DefDecl))))
    out = []
    for i, item in enumerate(m.items):
        rest = (*m.items[:i], *m.items[i + 1:])
        if isinstance(item, (S.DefDecl, S.DiffeoDecl)) and item.name.name not in used:
            out.append(S.ModuleS(m.path, rest, m.program))
        elif isinstance(item, S.ParamItem):
            for j, d in enumerate(item.decls):
                if d.name.name not in used and len(item.decls) > 1:
                    fewer = S.ParamItem((*item.decls[:j], *item.decls[j + 1:]))
                    out.append(S.ModuleS(m.path, (*m.items[:i], fewer, *m.items[i + 1:]), m.program))
    return out


def shrink(result, unit: Callable[[str], object], budget: int = BUDGET):
    """The smallest failing program found from ``result`` (a failing ``ProgramResult``) by running
    ``unit(text)`` on at most ``budget`` candidates (module doc); ``result`` itself if none fails.
    A program with modules (a :mod:`.bundle`) is shrunk in its main module, its libraries kept."""
    libraries = bundle.split(result.text)[1]
    try:
        module = parse_module(result.text, "<fuzz>.lgr")
    except LangurError:
        return result
    if module.program is None:
        return result
    best, runs, seen = result, 0, {result.text}
    improved = True
    while improved and runs < budget:
        improved = False
        candidates = [S.ModuleS(module.path, module.items, S.ProgramS(module.program.domain, b, module.program.variables))
                      for b in _replacements(module.program.body)] + _unused_items(module)
        candidates.sort(key=_size)
        for cand in candidates:
            text = bundle.join(generate.strategies.render(cand), libraries)
            if text in seen:
                continue
            seen.add(text)
            if runs >= budget:
                break
            runs += 1
            res = unit(text)
            if res.failed and res.status == result.status:
                best, module, improved = res, cand, True
                break
    return best


def annotated(small, original=None) -> str:
    """The `.lgr` file of a counterexample: a ``#`` header (status, both engines' numbers, the
    program it was shrunk from), then the program."""
    lines = [f"# langur fuzz: {small.status}" + (f" ({small.reason})" if small.reason else "")]
    if small.rows:
        lines.append("# quantity | wrt | exact | exact error bound | engine | engine value | engine standard error | ok")
    for row in small.rows:
        lines.append(f"# {row.quantity} | {row.wrt or '-'} | {row.exact!r} | {row.error!r} | {row.engine} | "
                     f"{row.mc!r} | {row.stderr!r} | {'ok' if row.ok else 'DISAGREE'}")
    if original is not None and original.text != small.text:
        lines.append("# shrunk from:")
        lines += [f"#   {line}" for line in original.text.splitlines()]
    return "\n".join(lines) + "\n" + small.text


def header_rows(text: str) -> list[tuple]:
    """The comparisons written in a counterexample's header: ``(quantity, wrt, exact, error,
    engine, value, stderr, ok)`` per row (``wrt`` None for the value)."""
    out = []
    for line in text.splitlines():
        if not line.startswith("# ") or line.count(" | ") != 7 or line.startswith("# quantity |"):
            continue
        q, wrt, ex, err, engine, val, se, ok = line[2:].split(" | ")
        out.append((q, None if wrt == "-" else wrt, float(ex), float(err), engine, float(val), float(se), ok == "ok"))
    return out


def write(directory: str, stem: str, text: str) -> str:
    """Write ``text`` to a new file ``STEM.lgr`` in ``directory`` (``STEM-1.lgr``, … when taken):
    a file already there is never overwritten."""
    for k in range(10_000):
        path = os.path.join(directory, f"{stem}{f'-{k}' if k else ''}.lgr")
        try:
            with open(path, "x", encoding="utf-8") as fh:
                fh.write(text)
            return path
        except FileExistsError:
            continue
    raise FileExistsError(f"{directory}: no free name for {stem}.lgr")
