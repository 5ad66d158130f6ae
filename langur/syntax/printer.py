"""Pretty-printer of surface terms, core terms and core programs, in `.lgr` syntax (LANGUAGE.md §6).

Public API::

    print_term(t: STerm) -> str            # surface terms (parse_term(print_term(t)) == t)
    print_module_surface(m: ModuleS) -> str
    print_core(t: core.Term, diffeo_names=None) -> str
    print_program(p: core.Program) -> str
    print_diffeo(psi: core.Diffeo) -> str  # one line: forward map, inverse branches with guards

Output uses minimal parentheses for the grammar's precedences (``let``/``if``/``ifge0``/loops lowest
and extending right, then ``+ -``, ``* /``, unary ``-``, ``^``, atoms) plus a few for legibility
(around ``let``/``if`` in a ``then`` branch or a condition, around a negation under a negation).
Printing is iterative (an explicit stack), so arbitrarily deep terms never hit Python's recursion
limit.

Core printing follows the core conventions of ``langur.core`` backwards, so that desugaring the
printed text gives the same core term:

* ``Const``: an exact decimal when the fraction has a terminating expansion (``0.125``; very long
  ones in exact scientific form ``12e-40``), else ``(p / q)``; ``Const("pi")`` is ``pi``.  A
  negative constant prints as ``-k`` (``-k`` is ``Const(-k)``, LANGUAGE.md's negative literal).
* ``Add(t, Mul(Const(-1), s))`` is ``t - s``; ``Mul(t, Pow(s, -1))`` is ``t / s``;
  ``Mul(Const(-1), t)`` is ``-t`` (but ``-1 * k`` for a literal ``k``, which ``-k`` would fold).
* ``Pow(t, k)`` is ``t ^ k``, ``Prim`` is ``exp(t)``, ``IfGe0`` is ``[c >= 0]`` when it is a bracket (then 1,
  else 0), else ``ifge0 c then s else r``,
  ``Let`` is ``let z = t in s``, ``Call`` (elaborated modules only) is ``module.name(args)``.
* ``IfDiffeo``.  A completed condition (``psi.name is None``) prints as its condition term,
  ``[<psi.forward[0]> >= 0]`` or ``ifge0 <psi.forward[0]> then … else …`` as ``IfGe0``: desugaring
  completes it again.  A *declared* diffeo
  has been instantiated (its parameters replaced by the actual argument terms), so its original
  parameter arguments cannot be recovered in general.  Choice: :func:`print_core` prints it, too,
  as its condition term (a true, readable statement of the test), unless ``diffeo_names`` maps
  it to a declaration name; :func:`print_program` does exactly that: it emits one ``diffeo``
  declaration per distinct declared diffeo of the program (variables = the instance's variables,
  parameters = the instance's free parameters in sorted order, the single inverse branch), and
  prints the conditional as ``ifge0 NAME(vars; params) then …``, which desugars back to the same
  instance.  Multi-branch or guarded diffeos cannot be declared in `.lgr`; they print as their
  condition.  :func:`print_diffeo` shows everything about one diffeo, including an implicit root
  of an inverse branch (``root(x: x ^ 3 - x - a = u0 in [-2, 2])``, not `.lgr` syntax: it never
  occurs in a program's terms).
"""

from __future__ import annotations

from fractions import Fraction

from .. import core as C
from . import surface as S

__all__ = ["decimal", "print_core", "print_diffeo", "print_module_surface", "print_program", "print_term"]

# Precedence levels: a node of level L printed where level >= M is required gets parentheses
# when L < M.
TERM, SUM, PRODUCT, UNARY, NEG_OPERAND, POWER, ATOM = 0, 1, 2, 3, 4, 5, 6
# NEG_OPERAND: what may follow a unary minus without parentheses (not another minus).


def decimal(value: Fraction) -> str | None:
    """The exact decimal text of a non-negative fraction, or ``None`` if it does not terminate."""
    value = Fraction(value)
    if value < 0:
        raise ValueError("decimal() takes a non-negative fraction")
    den = value.denominator
    twos = fives = 0
    while den % 2 == 0:
        den //= 2
        twos += 1
    while den % 5 == 0:
        den //= 5
        fives += 1
    if den != 1:
        return None
    k = max(twos, fives)  # value * 10^k is an integer
    scaled = value.numerator * 10**k // value.denominator
    if k == 0:
        text = str(scaled)
    else:
        digits = str(scaled).rjust(k + 1, "0")
        text = digits[:-k] + "." + digits[-k:]
    if len(text) <= 24:
        return text
    # exact scientific form: m e x with m an integer without trailing zeros
    m, x = scaled, -k
    while m and m % 10 == 0:
        m //= 10
        x += 1
    return f"{m}e{x}" if x else str(m)


def _render(root, rule, level: int = TERM) -> str:
    """Iterative printer: ``rule(node, level)`` returns parts, each a string or ``(node, level)``."""
    out: list[str] = []
    stack: list = [(root, level)]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            out.append(item)
            continue
        node, lvl = item
        stack.extend(reversed(rule(node, lvl)))
    return "".join(out)


def _wrap(own: int, level: int, parts: list) -> list:
    return ["(", *parts, ")"] if own < level else parts


def _commas(items, level: int = TERM, sep: str = ", ") -> list:
    parts: list = []
    for i, t in enumerate(items):
        if i:
            parts.append(sep)
        parts.append((t, level))
    return parts


# ----------------------------------------------------------------------------------------------
# Surface terms.

_SURFACE_BINOP = {"+": (SUM, SUM, PRODUCT), "-": (SUM, SUM, PRODUCT), "*": (PRODUCT, PRODUCT, UNARY),
                  "/": (PRODUCT, PRODUCT, UNARY), "^": (POWER, ATOM, UNARY)}  # fmt: skip


def _num_parts(value: Fraction) -> tuple[int, list]:
    text = decimal(abs(value))
    if text is None:
        body = f"({abs(value.numerator)} / {value.denominator})"
        return (UNARY, ["-" + body]) if value < 0 else (ATOM, [body])
    return (UNARY, ["-" + text]) if value < 0 else (ATOM, [text])


def _chain(terms, ops) -> list:
    """``t0 op0 t1 op1 t2 …`` (inside an Iverson bracket)."""
    parts: list = []
    for i, u in enumerate(terms):
        if i:
            parts.append(f" {ops[i - 1]} ")
        parts.append((u, SUM))
    return parts


def _surface_rule(t, level: int) -> list:
    match t:
        case S.Num(value):
            own, parts = _num_parts(value)
            return _wrap(own, level, parts)
        case S.Name(name):
            return [name]
        case S.BinOp(op, left, right):
            own, lo, ro = _SURFACE_BINOP[op]
            return _wrap(own, level, [(left, lo), f" {op} ", (right, ro)])
        case S.Neg(arg):
            return _wrap(UNARY, level, ["-", (arg, NEG_OPERAND)])
        case S.Apply(name, args):
            return [name, "(", *_commas(args), ")"]
        case S.Iverson(terms, ops):
            return ["["] + _chain(terms, ops) + ["]"]
        case S.Logic(op, chains):
            if op == "not":
                return ["[not "] + _chain(chains[0].terms, chains[0].ops) + ["]"]
            sep = " & " if op == "and" else " | "
            parts = ["["]
            for i, c in enumerate(chains):
                parts += ([sep] if i else []) + _chain(c.terms, c.ops)
            return parts + ["]"]
        case S.LetIn(name, bound, body):
            return _wrap(TERM, level, ["let ", name, " = ", (bound, SUM), " in ", (body, TERM)])
        case S.IfGe0S(cond, then, orelse):
            return _wrap(
                TERM, level, ["ifge0 ", (cond, SUM), " then ", (then, SUM), " else ", (orelse, TERM)]
            )
        case S.IfCmp(left, op, right, then, orelse):
            return _wrap(
                TERM,
                level,
                [
                    "if ",
                    (left, SUM),
                    f" {op} ",
                    (right, SUM),
                    " then ",
                    (then, SUM),
                    " else ",
                    (orelse, TERM),
                ],
            )
        case S.IfLogic(S.Logic(op, chains), then, orelse):
            cond: list = ["not "] + _chain(chains[0].terms, chains[0].ops) if op == "not" else []
            for i, c in enumerate(chains if op != "not" else ()):
                cond += ([" & " if op == "and" else " | "] if i else []) + _chain(c.terms, c.ops)
            return _wrap(TERM, level, ["if ", *cond, " then ", (then, SUM), " else ", (orelse, TERM)])
        case S.Loop(op, index, lo, hi, body):
            return _wrap(TERM, level, [f"{op} {index} in ", (lo, SUM), "..", (hi, SUM), ": ", (body, TERM)])
        case S.Vector(parts):
            return ["(", *_commas(parts), ")"]
        case S.Component(S.Num() as base, name):
            return ["(", (base, TERM), ").", name]  # `3.x` would lex as the number `3.` and a name
        case S.Component(base, name):
            return [(base, ATOM), ".", name]
        case S.DiffeoApp(name, variables, params):
            return [name, "(", *_commas(variables), ";", *([" "] if params else []), *_commas(params), ")"]
        case S.NestedInt(domain, body, variables):
            dom: list = []
            for i, iv in enumerate(domain or ()):
                dom += ["(" if i == 0 else ", ", "[", (iv.lo, TERM), ", ", (iv.hi, TERM), "]"]
            dom += [") "] if domain else []
            return ["int ", *dom, (body, TERM), " d(", _idents(variables), ")"]
    raise TypeError(f"not a surface term: {t!r}")


def print_term(t) -> str:
    """A surface term in `.lgr` syntax; ``parse_term(print_term(t)) == t`` for parser output."""
    return _render(t, _surface_rule)


def _semi(params) -> str:
    return "; " + ", ".join(params) if params else ";"


def _idents(xs) -> str:
    return ", ".join(x.name for x in xs)


def print_module_surface(m: S.ModuleS) -> str:
    """A whole surface module, one item per line (comments are not kept by the parser)."""
    lines: list[str] = []
    for item in m.items:
        match item:
            case S.ParamItem(decls):
                ds = []
                for d in decls:
                    if d.default is None:
                        ds.append(d.name.name)
                    else:
                        ds.append(f"{d.name.name} = {_render(S.Num(d.default), _surface_rule, UNARY)}")
                lines.append("param " + ", ".join(ds))
            case S.DiffeoDecl(name, variables, params, forward, inputs, inverse):
                fw = ", ".join(print_term(f) for f in forward)
                inv = ", ".join(print_term(f) for f in inverse)
                lines.append(
                    f"diffeo {name.name}({_idents(variables)}{_semi([p.name for p in params])}) = ({fw}) "
                    f"inverse ({_idents(inputs)}) = ({inv})"
                )
            case S.DefDecl(name, args, body):
                a = ", ".join(f"{x.name.name}: {x.kind}" for x in args)
                lines.append(f"def {name.name}({a}) = {print_term(body)}")
            case S.ImportItem(module, names):
                ns = ", ".join(n.name.name + (f" as {n.alias.name}" if n.alias else "") for n in names)
                lines.append(f"from {module.name} import {ns}")
            case _:
                raise TypeError(f"not a surface item: {item!r}")
    p = m.program
    if p is not None:
        dom = ""
        if p.domain is not None:
            dom = "(" + ", ".join(f"[{print_term(i.lo)}, {print_term(i.hi)}]" for i in p.domain) + ") "
        lines.append(f"int {dom}{print_term(p.body)} d({_idents(p.variables)})")
    return "\n".join(lines) + ("\n" if lines else "")


# ----------------------------------------------------------------------------------------------
# Core terms.

_MINUS_ONE = Fraction(-1)


def _is_minus_one(t) -> bool:
    return isinstance(t, C.Const) and t.value == _MINUS_ONE and not isinstance(t.value, str)


def _is_literal(t) -> bool:
    return isinstance(t, C.Const) and not isinstance(t.value, str)


def _is_zero(t) -> bool:
    return _is_literal(t) and t.value == 0


def _bracket(cond, then, orelse):
    """``ifge0 t then 1 else 0`` as the bracket ``[t >= 0]``, which desugars back to the same term (its
    condition ``t − 0`` is ``t``: ``compare`` in ``syntax/conditionals.py``, ``syntax/folding.py``); None
    for other branches (printed ``ifge0 t then s else r``)."""
    if _is_literal(then) and then.value == 1 and _is_zero(orelse):
        return ["[", (cond, SUM), " >= 0]"]
    return None


def _const_parts(value) -> tuple[int, list]:
    if isinstance(value, str):
        return ATOM, [value]
    return _num_parts(Fraction(value))


class _CoreRule:
    def __init__(self, diffeo_names: dict | None):
        self.names = diffeo_names or {}

    def __call__(self, t, level: int) -> list:
        match t:
            case C.Const(value):
                own, parts = _const_parts(value)
                return _wrap(own, level, parts)
            case C.Var(name) | C.Param(name):
                return [name]
            case C.Add(left, C.Mul(m, right)) if _is_minus_one(m):
                return _wrap(SUM, level, [(left, SUM), " - ", (right, PRODUCT)])
            case C.Add(left, right):
                return _wrap(SUM, level, [(left, SUM), " + ", (right, PRODUCT)])
            case C.Mul(left, C.Pow(right, k)) if k == _MINUS_ONE:
                return _wrap(PRODUCT, level, [(left, PRODUCT), " / ", (right, UNARY)])
            case C.Mul(m, right) if _is_minus_one(m) and not _is_literal(right):
                return _wrap(UNARY, level, ["-", (right, NEG_OPERAND)])
            case C.Mul(left, right):
                return _wrap(PRODUCT, level, [(left, PRODUCT), " * ", (right, UNARY)])
            case C.Prim(op, arg):
                return [op, "(", (arg, TERM), ")"]
            case C.Pow(base, k):
                _, kparts = _const_parts(Fraction(k))
                return _wrap(POWER, level, [(base, ATOM), " ^ ", *kparts])
            case C.IfGe0(cond, then, orelse) if (parts := _bracket(cond, then, orelse)) is not None:
                # an Iverson bracket, printed as one: [t >= 0]
                return parts
            case C.IfGe0(cond, then, orelse):
                return _wrap(
                    TERM, level, ["ifge0 ", (cond, SUM), " then ", (then, SUM), " else ", (orelse, TERM)]
                )
            case C.IfDiffeo(psi, then, orelse) if psi not in self.names and (
                    parts := _bracket(psi.forward[0], then, orelse)) is not None:
                return parts
            case C.IfDiffeo(psi, then, orelse):
                return _wrap(
                    TERM,
                    level,
                    ["ifge0 ", *self.condition(psi), " then ", (then, SUM), " else ", (orelse, TERM)],
                )
            case C.Let(name, bound, body):
                return _wrap(TERM, level, ["let ", name, " = ", (bound, SUM), " in ", (body, TERM)])
            case C.Call(module, name, args):
                return [f"{module}.{name}" if module else name, "(", *_commas(args), ")"]
            case C.ImplicitRoot(eq, x, target, lo, hi, index, of):
                # only in a diffeo's inverse branches (print_diffeo): not `.lgr` syntax
                head = "root(" if index is None else f"sign_change_{index}("
                tail = ")" if index is None else f"; at most {of})"
                return [head, x, ": ", (eq, SUM), " = ", (target, SUM), " in [", (lo, TERM), ", ", (hi, TERM),
                        "]", tail]
        raise TypeError(f"not a core term: {t!r}")

    def condition(self, psi: C.Diffeo) -> list:
        name = self.names.get(psi)
        if name is None:
            return [(psi.forward[0], SUM)]
        params = _diffeo_param_names(psi)
        return [name, "(", ", ".join(psi.variables), _semi(params), ")"]


def print_core(t, diffeo_names: dict | None = None, operand: bool = False) -> str:
    """A core term in `.lgr` syntax (see the module docstring for the choices made).  ``operand``:
    printed to stand in any position of a larger term (an atom as it is, anything else in
    parentheses), as ``check --fix`` splices it into the source."""
    return _render(t, _CoreRule(diffeo_names), ATOM if operand else TERM)


def _diffeo_param_names(psi: C.Diffeo) -> list[str]:
    names = set(C.diffeo_params(psi))
    for b in psi.branches:
        for u in b.components + b.guards:
            names |= C.free_params(u)
    return sorted(names)


def _declarable(psi: C.Diffeo) -> bool:
    return psi.name is not None and len(psi.branches) == 1 and not psi.branches[0].guards


def _diffeos_in(t) -> list[C.Diffeo]:
    found: list[C.Diffeo] = []
    seen: set = set()
    for u in C.subterms(t):
        if isinstance(u, C.IfDiffeo) and u.psi not in seen:
            seen.add(u.psi)
            found.append(u.psi)
    return found


def print_program(p: C.Program, defaults: dict | None = None) -> str:
    """A core program as a `.lgr` file: ``param`` for its free parameters, one ``diffeo``
    declaration per declared diffeo instance, then ``int (domain)? body d(x⃗)``.

    A declared domain is printed as the domain; otherwise the box (read off the integrand's own
    bounding indicators) is printed as a comment.  ``defaults`` (``Loaded.params``) gives the ``param``
    declarations their default values.
    """
    lines: list[str] = []
    names: dict = {}
    taken: set[str] = set(p.variables)
    decls: list[str] = []
    for psi in _diffeos_in(p.body):
        if not _declarable(psi):
            continue
        base = psi.name
        name, k = base, 2
        while name in taken:
            name, k = f"{base}_{k}", k + 1
        taken.add(name)
        names[psi] = name
        forward = ", ".join(print_core(f) for f in psi.forward)
        inverse = ", ".join(print_core(c) for c in psi.branches[0].components)
        decls.append(
            f"diffeo {name}({', '.join(psi.variables)}{_semi(_diffeo_param_names(psi))}) = ({forward}) "
            f"inverse ({', '.join(psi.inputs)}) = ({inverse})"
        )
    params = set(C.free_params(p.body))
    for lo, hi in p.box:
        params |= C.free_params(lo) | C.free_params(hi)
    defaults = defaults or {}
    if params:
        decl = []
        for name in sorted(params):
            v = defaults.get(name)
            decl.append(
                name if v is None else f"{name} = {_render(C.Const(Fraction(v)), _CoreRule(None), UNARY)}"
            )
        lines.append("param " + ", ".join(decl))
    lines.extend(decls)
    if p.domain:
        domain = ", ".join(f"[{print_core(iv.lo)}, {print_core(iv.hi)}]" for iv in p.domain)
        lines.append(f"int ({domain}) {print_core(p.integrand, names)} d({', '.join(p.variables)})")
    else:
        if p.box:
            box = ", ".join(
                f"{x} in [{print_core(lo)}, {print_core(hi)}]" for x, (lo, hi) in zip(p.variables, p.box)
            )
            lines.append(f"# box: {box}")
        lines.append(f"int {print_core(p.integrand, names)} d({', '.join(p.variables)})")
    return "\n".join(lines)


def print_diffeo(psi: C.Diffeo) -> str:
    """One line: what Ψ̂ is, its forward map and its inverse branches with their guards.

    ``declared (x, y; c) ↦ (x + y + c, y); inverse (u, v) ↦ (u - v - c, v)``
    ``completed for x: (x, y; a) ↦ (x ^ 2 - a, y); inverse (u0, u1) ↦ (sqrt(u0 + a), u1) where
    u0 + a >= 0 | (-sqrt(u0 + a), u1) where u0 + a >= 0``
    """
    if psi.name is not None:
        kind = f"declared {psi.name}"
    elif psi.solved_for is not None:
        kind = f"completed for {psi.solved_for}"
    else:
        kind = "diffeo"
    params = _diffeo_param_names(psi)
    head = f"({', '.join(psi.variables)}{'; ' + ', '.join(params) if params else ''})"
    forward = "(" + ", ".join(print_core(f) for f in psi.forward) + ")"
    branches = []
    for b in psi.branches:
        text = "(" + ", ".join(print_core(c) for c in b.components) + ")"
        if b.guards:
            text += " where " + " and ".join(f"{print_core(g)} >= 0" for g in b.guards)
        branches.append(text)
    out = f"{kind}: {head} ↦ {forward}; inverse ({', '.join(psi.inputs)}) ↦ {' | '.join(branches)}"
    if psi.nonzero:
        out += "; needs " + ", ".join(f"{print_core(n)} ≠ 0" for n in psi.nonzero)
    return out
