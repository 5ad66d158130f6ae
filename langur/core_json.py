"""The core AST as versioned JSON: a language-neutral program format for other engines (§4).

A program is sent to an engine written in any language as one JSON object (schema:
``docs/core-json.schema.json``; ``docs/engines.md`` explains it)::

    {"format": "langur-core", "version": 1,
     "nodes":   [{"op": "var", "name": "x"}, {"op": "param", "name": "a"}, …],
     "diffeos": [{"variables": [...], "forward": [node], "inputs": [...],
                  "branches": [{"components": [node], "guards": [node]}], …}],
     "program": {"variables": ["x"], "integrand": node, "box": [[node, node]],
                 "domain": [{"variable": "x", "lo": node, "hi": node, "lower": node, "upper": node}]},
     "params":  {"a": "1/2"}}

Terms are a table of nodes, each naming its children by their index in the table, always an
earlier one: the format is acyclic by construction, and a subterm shared after inlining (§9) is
one node however often it is reached, so the JSON is never larger than the term's distinct nodes.
Numbers are exact: a rational as ``"p/q"`` (or ``"p"``), π as ``"pi"``.  One op per core term
former (Fig. 6 with the conditional on a diffeomorphism, §4): ``const``, ``var``, ``param``,
``add``, ``mul``, ``prim``, ``pow``, ``ifge0``, ``ifdiffeo``, ``let``, and ``root`` (an implicit
root, :class:`~langur.core.ImplicitRoot`, only in inverse branches).  Calls never appear: the
program is the inlined one.

:func:`dumps`/:func:`to_json` write a :class:`~langur.core.Program`; :func:`loads`/:func:`from_json`
read one back, equal to the original, refusing malformed or oversized input with a
:class:`FormatError` that says where (a JSON path).  Nothing in the input is evaluated.
"""

from __future__ import annotations

import json
import re
from fractions import Fraction

from .core import (
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Interval,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Term,
    Var,
    children,
)
from .primitives import REGISTRY

FORMAT, VERSION = "langur-core", 1
#: Bounds on what :func:`from_json` accepts (hostile input costs bounded time and memory).
MAX_NODES = 1_000_000
MAX_DIGITS = 4300
MAX_NAME = 200
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_RATIONAL = re.compile(r"-?[0-9]+(/[0-9]+)?\Z")


class FormatError(ValueError):
    """Malformed program JSON; ``where`` is a JSON path (``$.nodes[3].args``)."""

    def __init__(self, where: str, why: str):
        super().__init__(f"{where}: {why}")
        self.where, self.why = where, why


# -- writing -------------------------------------------------------------------------------------

def _number(v: Fraction | str) -> str:
    if isinstance(v, str):
        return v
    return str(v.numerator) if v.denominator == 1 else f"{v.numerator}/{v.denominator}"


class _Writer:
    def __init__(self):
        self.nodes: list[dict] = []
        self.index: dict[Term, int] = {}
        self.diffeos: list[dict] = []
        self.diffeo_index: dict[Diffeo, int] = {}

    def term(self, t: Term) -> int:
        """The node of ``t`` (equal subterms are one node), children first, without recursion."""
        stack = [(t, False)]
        while stack:
            u, ready = stack.pop()
            if u in self.index:
                continue
            if not ready:
                stack.append((u, True))
                stack.extend((c, False) for c in reversed(children(u)) if c not in self.index)
                if isinstance(u, IfDiffeo):
                    psi = u.psi
                    stack.extend((f, False) for f in (*psi.forward, *psi.nonzero,
                                                      *(c for b in psi.branches for c in (*b.components, *b.guards)))
                                 if f not in self.index)
                continue
            self.index[u] = len(self.nodes)
            self.nodes.append(self.node(u))
        return self.index[t]

    def node(self, u: Term) -> dict:
        ix = self.index
        match u:
            case Const(value):
                return {"op": "const", "value": _number(value)}
            case Var(name):
                return {"op": "var", "name": name}
            case Param(name):
                return {"op": "param", "name": name}
            case Add(a, b):
                return {"op": "add", "args": [ix[a], ix[b]]}
            case Mul(a, b):
                return {"op": "mul", "args": [ix[a], ix[b]]}
            case Prim(op, a):
                return {"op": "prim", "fn": op, "arg": ix[a]}
            case Pow(a, k):
                return {"op": "pow", "base": ix[a], "exponent": _number(k)}
            case IfGe0(c, a, b):
                return {"op": "ifge0", "cond": ix[c], "then": ix[a], "else": ix[b]}
            case IfDiffeo(psi, a, b):
                return {"op": "ifdiffeo", "diffeo": self.diffeo(psi), "then": ix[a], "else": ix[b]}
            case Let(name, bound, body):
                return {"op": "let", "name": name, "bound": ix[bound], "body": ix[body]}
            case Call(module, name, _):
                raise ValueError(f"call of {module}.{name}: only inlined programs are written (no Call nodes)")
            case ImplicitRoot(eq, x, target, lo, hi, index, of, slope):
                node = {"op": "root", "equation": ix[eq], "variable": x, "target": ix[target], "lo": ix[lo],
                        "hi": ix[hi]}
                if slope is not None:  # ∂equation/∂variable: the engines certify the sign changes with it
                    node["slope"] = ix[slope]
                return node if index is None else {**node, "index": index, "of": of}
        raise TypeError(f"not a core term: {u!r}")

    def diffeo(self, psi: Diffeo) -> int:
        if psi not in self.diffeo_index:
            self.diffeo_index[psi] = len(self.diffeos)
            self.diffeos.append({
                "variables": list(psi.variables), "forward": [self.term(f) for f in psi.forward],
                "inputs": list(psi.inputs),
                "branches": [{"components": [self.term(c) for c in b.components],
                              "guards": [self.term(g) for g in b.guards]} for b in psi.branches],
                "solved_for": psi.solved_for, "name": psi.name, "nonzero": [self.term(t) for t in psi.nonzero]})
        return self.diffeo_index[psi]


def to_json(program: Program, params: dict | None = None) -> dict:
    """``program`` (inlined: no calls) as the JSON object of the module docstring; ``params``:
    parameter defaults to include (numbers, written exactly)."""
    w = _Writer()
    integrand = w.term(program.integrand)
    box = [[w.term(lo), w.term(hi)] for lo, hi in program.box]
    domain = [{"variable": iv.variable, "lo": w.term(iv.lo), "hi": w.term(iv.hi), "lower": w.term(iv.lower),
               "upper": w.term(iv.upper)} for iv in program.domain]
    out = {"format": FORMAT, "version": VERSION, "nodes": w.nodes, "diffeos": w.diffeos,
           "program": {"variables": list(program.variables), "integrand": integrand, "box": box, "domain": domain}}
    if params:
        out["params"] = {k: _number(Fraction(str(v)) if not isinstance(v, Fraction) else v)
                         for k, v in params.items() if v is not None}
    return out


def dumps(program: Program, params: dict | None = None, **kw) -> str:
    return json.dumps(to_json(program, params), **kw)


# -- reading -------------------------------------------------------------------------------------

def _field(obj, key: str, where: str, kind):
    if not isinstance(obj, dict):
        raise FormatError(where, "expected an object")
    if key not in obj:
        raise FormatError(where, f"missing {key!r}")
    v = obj[key]
    if kind is int and (not isinstance(v, int) or isinstance(v, bool)):
        raise FormatError(f"{where}.{key}", "expected an integer")
    if kind is not int and not isinstance(v, kind):
        raise FormatError(f"{where}.{key}", f"expected {kind.__name__ if isinstance(kind, type) else 'a value'}")
    return v


def _name(v, where: str) -> str:
    if not isinstance(v, str) or len(v) > MAX_NAME or not _NAME.match(v):
        raise FormatError(where, "expected a name ([A-Za-z_][A-Za-z0-9_]*)")
    return v


def _rational(v, where: str, pi: bool = False) -> Fraction | str:
    if pi and v == "pi":
        return "pi"
    if not isinstance(v, str) or len(v) > 2 * MAX_DIGITS + 2 or not _RATIONAL.match(v):
        raise FormatError(where, "expected an exact rational \"p\" or \"p/q\"" + (" or \"pi\"" if pi else ""))
    q = Fraction(v)
    if q.denominator == 0:  # pragma: no cover - Fraction raises first
        raise FormatError(where, "zero denominator")
    return q


class _Reader:
    def __init__(self, data: dict):
        self.data = data
        self.terms: list[Term] = []
        self.diffeos: dict[int, Diffeo] = {}

    def ref(self, v, where: str, limit: int | None = None) -> Term:
        limit = len(self.terms) if limit is None else limit
        if not isinstance(v, int) or isinstance(v, bool) or not 0 <= v < limit:
            raise FormatError(where, f"expected the index of an earlier node (0 to {limit - 1})")
        return self.terms[v]

    def read_nodes(self):
        nodes = _field(self.data, "nodes", "$", list)
        if len(nodes) > MAX_NODES:
            raise FormatError("$.nodes", f"more than {MAX_NODES:,} nodes")
        diffeos = self.data.get("diffeos", [])
        if not isinstance(diffeos, list):
            raise FormatError("$.diffeos", "expected a list")
        self.raw_diffeos = diffeos
        for i, n in enumerate(nodes):
            self.terms.append(self.node(n, f"$.nodes[{i}]"))

    def node(self, n, where: str) -> Term:
        op = _field(n, "op", where, str)
        r = self.ref
        match op:
            case "const":
                return Const(_rational(n.get("value"), f"{where}.value", pi=True))
            case "var":
                return Var(_name(n.get("name"), f"{where}.name"))
            case "param":
                return Param(_name(n.get("name"), f"{where}.name"))
            case "add" | "mul":
                args = _field(n, "args", where, list)
                if len(args) != 2:
                    raise FormatError(f"{where}.args", "expected two nodes")
                a, b = r(args[0], f"{where}.args[0]"), r(args[1], f"{where}.args[1]")
                return Add(a, b) if op == "add" else Mul(a, b)
            case "prim":
                fn = n.get("fn")
                if fn not in REGISTRY:
                    raise FormatError(f"{where}.fn", f"expected a primitive ({', '.join(sorted(REGISTRY))})")
                return Prim(fn, r(n.get("arg"), f"{where}.arg"))
            case "pow":
                k = _rational(n.get("exponent"), f"{where}.exponent")
                return Pow(r(n.get("base"), f"{where}.base"), k)
            case "ifge0":
                return IfGe0(r(n.get("cond"), f"{where}.cond"), r(n.get("then"), f"{where}.then"),
                             r(n.get("else"), f"{where}.else"))
            case "ifdiffeo":
                psi = self.diffeo(n.get("diffeo"), f"{where}.diffeo")
                return IfDiffeo(psi, r(n.get("then"), f"{where}.then"), r(n.get("else"), f"{where}.else"))
            case "let":
                return Let(_name(n.get("name"), f"{where}.name"), r(n.get("bound"), f"{where}.bound"),
                           r(n.get("body"), f"{where}.body"))
            case "root":
                index, of = n.get("index"), n.get("of", 0)
                for key, v in (("index", index), ("of", of)):
                    if v is not None and (not isinstance(v, int) or isinstance(v, bool) or not 0 <= v <= 1000):
                        raise FormatError(f"{where}.{key}", "expected an integer from 0 to 1000")
                return ImplicitRoot(r(n.get("equation"), f"{where}.equation"),
                                    _name(n.get("variable"), f"{where}.variable"), r(n.get("target"), f"{where}.target"),
                                    r(n.get("lo"), f"{where}.lo"), r(n.get("hi"), f"{where}.hi"), index, of,
                                    None if n.get("slope") is None else r(n.get("slope"), f"{where}.slope"))
        raise FormatError(f"{where}.op", f"unknown op {op!r}")

    def diffeo(self, k, where: str) -> Diffeo:
        if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k < len(self.raw_diffeos):
            raise FormatError(where, "expected the index of a diffeo in $.diffeos")
        if k not in self.diffeos:
            d, at = self.raw_diffeos[k], f"$.diffeos[{k}]"
            names = lambda key: tuple(_name(v, f"{at}.{key}[{i}]")  # noqa: E731
                                      for i, v in enumerate(_field(d, key, at, list)))
            refs = lambda vs, w: tuple(self.ref(v, f"{w}[{i}]") for i, v in enumerate(vs))  # noqa: E731
            branches = []
            for j, b in enumerate(_field(d, "branches", at, list)):
                bw = f"{at}.branches[{j}]"
                branches.append(InverseBranch(refs(_field(b, "components", bw, list), f"{bw}.components"),
                                              refs(b.get("guards", []), f"{bw}.guards")))
            solved, name = d.get("solved_for"), d.get("name")
            psi = Diffeo(names("variables"), refs(_field(d, "forward", at, list), f"{at}.forward"), names("inputs"),
                         tuple(branches), None if solved is None else _name(solved, f"{at}.solved_for"),
                         None if name is None else _name(name, f"{at}.name"),
                         refs(d.get("nonzero", []), f"{at}.nonzero"))
            if not (len(psi.forward) == len(psi.variables) == len(psi.inputs) and psi.branches
                    and all(len(b.components) == len(psi.variables) for b in psi.branches)):
                raise FormatError(at, "a diffeomorphism needs as many forward components, inputs and components per "
                                  "branch as variables, and at least one branch")
            self.diffeos[k] = psi
        return self.diffeos[k]

    def program(self) -> Program:
        p = _field(self.data, "program", "$", dict)
        variables = tuple(_name(v, f"$.program.variables[{i}]")
                          for i, v in enumerate(_field(p, "variables", "$.program", list)))
        integrand = self.ref(p.get("integrand"), "$.program.integrand")
        box = []
        for i, pair in enumerate(_field(p, "box", "$.program", list)):
            if not isinstance(pair, list) or len(pair) != 2:
                raise FormatError(f"$.program.box[{i}]", "expected [lo, hi]")
            box.append((self.ref(pair[0], f"$.program.box[{i}][0]"), self.ref(pair[1], f"$.program.box[{i}][1]")))
        if len(box) != len(variables):
            raise FormatError("$.program.box", "expected one [lo, hi] per variable")
        domain = []
        for i, iv in enumerate(p.get("domain", [])):
            w = f"$.program.domain[{i}]"
            domain.append(Interval(_name(_field(iv, "variable", w, str), f"{w}.variable"),
                                   *(self.ref(iv.get(k), f"{w}.{k}") for k in ("lo", "hi", "lower", "upper"))))
        if domain and len(domain) != len(variables):
            raise FormatError("$.program.domain", "expected no domain or one interval per variable")
        return Program(integrand, variables, tuple(box), tuple(domain))

    def params(self) -> dict[str, Fraction]:
        ps = self.data.get("params", {})
        if not isinstance(ps, dict):
            raise FormatError("$.params", "expected an object")
        return {_name(k, f"$.params.{k}"): _rational(v, f"$.params.{k}") for k, v in ps.items()}


def from_json(data) -> tuple[Program, dict[str, Fraction]]:
    """The program and its parameter defaults; :class:`FormatError` when ``data`` is not a
    well-formed program of this format and version (well-formed, not yet type-checked: see
    :func:`langur.typesys.type_program`)."""
    if not isinstance(data, dict):
        raise FormatError("$", "expected an object")
    if data.get("format") != FORMAT:
        raise FormatError("$.format", f"expected {FORMAT!r}")
    if data.get("version") != VERSION:
        raise FormatError("$.version", f"this reader knows version {VERSION}")
    r = _Reader(data)
    r.read_nodes()
    return r.program(), r.params()


def loads(text: str | bytes) -> tuple[Program, dict[str, Fraction]]:
    try:
        data = json.loads(text)
    except (ValueError, RecursionError) as e:
        raise FormatError("$", f"not JSON: {e}") from None
    return from_json(data)
