"""Random well-typed, transverse Langur programs as `.lgr` text (the generator behind
``langur fuzz``; see :mod:`langur.fuzz` for what is generated and why).
"""

from __future__ import annotations

import contextlib
import math
import os
import re
from dataclasses import dataclass

# Parameter defaults: irregular decimals, drawn without replacement (no two parameters equal).
GENERIC = ("0.37", "0.61", "0.23", "0.83", "0.47", "0.71", "0.29", "0.53", "0.67", "0.41", "0.79", "0.31")
PARAMS = ("a", "b", "c")
OFFSETS = ("0", "0.3", "-0.2", "0.15", "-0.45", "0.55")
SIGMA = 5.0          # standard errors allowed (false alarm ≈ 6e-7 per comparison under normality)
ABS_SLACK = 1e-9
REL_SLACK = 1e-9
LINT_DISCARD = ("X301", "X305")


class MissingHypothesis(RuntimeError):
    """``hypothesis`` (a development dependency) is not installed."""


def _hypothesis():
    try:
        import hypothesis
        from hypothesis import strategies as st
    except ImportError:  # pragma: no cover - depends on the environment
        raise MissingHypothesis("`langur fuzz` needs hypothesis: pip install hypothesis "
                                "(or pip install -e '.[dev]')") from None
    return hypothesis, st


def default_storage() -> str:
    """Where a campaign lets hypothesis keep its files (its cache of source constants; campaigns
    keep no example database): ``$HYPOTHESIS_STORAGE_DIRECTORY`` when set, else the user's cache
    folder (``$XDG_CACHE_HOME/langur/hypothesis``, ``~/.cache/langur/hypothesis``), never the
    current folder."""
    where = os.environ.get("HYPOTHESIS_STORAGE_DIRECTORY")
    if where:
        return where
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(cache, "langur", "hypothesis")


@contextlib.contextmanager
def hypothesis_home(directory: str | None):
    """Hypothesis's storage folder is ``directory`` (``default_storage()`` when None) while the
    block runs, and what it was before afterwards."""
    _hypothesis()
    from hypothesis import configuration

    before = getattr(configuration, "__hypothesis_home_directory", None)
    configuration.set_hypothesis_home_dir(directory or default_storage())
    try:
        yield
    finally:
        configuration.set_hypothesis_home_dir(before)


# ---------------------------------------------------------------------------------------------
# Program generator
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FuzzProgram:
    """A generated program: its ``.lgr`` text and the parameter defaults it declares."""

    text: str
    params: tuple[tuple[str, str], ...]

    def __str__(self) -> str:
        return self.text


@dataclass
class _Cond:
    """A condition ``lhs CMP rhs``; ``g(x, y) = lhs − rhs`` numerically at the defaults;
    ``line`` = (cx, cy, c) when the zero set is the straight line cx·x + cy·y = c (or vertical
    lines, several for x² = r)."""

    lhs: str
    cmp: str
    rhs: str
    g: object
    lines: tuple = ()
    key: tuple = ()


class _Ctx:
    def __init__(self, draw, st, variables, pvals):
        self.draw, self.st = draw, st
        self.variables = variables
        self.pvals = dict(pvals)     # name -> float, includes let names
        self.names = list(pvals)     # parameter-like names usable in terms
        self.conds: list[_Cond] = []
        self.diffeos: dict[str, str] = {}  # declared diffeos used: name -> declaration
        self.n_smooth = 19                 # how many of _smooth's forms may be used
        self.kinks = False                 # conditions with abs/min/max inside (issue 18)

    def pick(self, seq):
        return self.draw(self.st.sampled_from(seq))

    def var(self):
        return self.pick(self.variables)

    def ev(self, expr_py: str, x=0.0, y=0.0) -> float:
        env = dict(self.pvals, x=x, y=y, exp=math.exp, sin=math.sin, cos=math.cos, sqrt=math.sqrt)
        return eval(expr_py, {"__builtins__": {}}, env)  # our own generated text


def _lin_text(cx: str, v: str) -> str:
    return v if cx == "1" else (f"-{v}" if cx == "-1" else f"{cx}*{v}")


def _affine_cond(ctx: _Ctx) -> _Cond:
    """``[Σ c_i v_i CMP P + k]`` (the shapes of the brief: ``[x <= a]``, ``[2*x - y <= a + 0.3]``)."""
    coefs = ("1", "2", "-1", "0.5")
    if len(ctx.variables) == 2:
        shape = ctx.pick(("x", "y", "xy"))
    else:
        shape = "x"
    cx = ctx.pick(coefs) if "x" in shape else "0"
    cy = ctx.pick(coefs) if "y" in shape else "0"
    parts = []
    if cx != "0":
        parts.append(_lin_text(cx, "x"))
    if cy != "0":
        t = _lin_text(cy, "y")
        parts.append(t if not parts else (f"- {t[1:]}" if t.startswith("-") else f"+ {t}"))
    lhs = " ".join(parts)
    p = ctx.pick(ctx.names)
    k = ctx.pick(OFFSETS)
    rhs = p if k == "0" else (f"{p} - {k[1:]}" if k.startswith("-") else f"{p} + {k}")
    cmp = ctx.pick(("<=", ">=", "<", ">"))
    fx, fy, c = float(cx), float(cy), ctx.pvals[p] + float(k)
    return _Cond(lhs, cmp, rhs, lambda x, y: fx * x + fy * y - c, ((fx, fy, c),), ("lin", cx, cy, p, k))


def _scaled_cond(ctx: _Ctx) -> _Cond:
    """``[P*v CMP k]``: the completed diffeomorphism divides by the parameter (``Diffeo.nonzero``),
    so the delta's Jacobian 1/|P| is exercised; P's default is positive, never 0."""
    v = ctx.var()
    p = ctx.pick(ctx.names)
    k = ctx.pick(("0.3", "0.15", "-0.2", "0.55"))
    cmp = ctx.pick(("<=", ">="))
    pv, kv = ctx.pvals[p], float(k)
    if v == "x":
        g, line = (lambda x, y: pv * x - kv), (pv, 0.0, kv)
    else:
        g, line = (lambda x, y: pv * y - kv), (0.0, pv, kv)
    return _Cond(f"{p}*{v}", cmp, k, g, (line,), ("scaled", v, p, k))


# Declared diffeomorphisms (LANGUAGE.md §6): Ψ̂ and its inverse; zero set of π₀Ψ̂ at parameter c.
DIFFEOS = {
    "sh": ("diffeo sh(x, y; c) = (x + y - c, y) inverse (u, v) = (u - v + c, v)",
           lambda c: ((1.0, 1.0, c),), lambda c: (lambda x, y: x + y - c)),
    "rot": ("diffeo rot(x, y; c) = (x - y - c, x + y) inverse (u, v) = ((u + v + c) / 2, (v - u - c) / 2)",
            lambda c: ((1.0, -1.0, c),), lambda c: (lambda x, y: x - y - c)),
    "cub": ("diffeo cub(x, y; c) = (y - x^3 - c, x) inverse (u, v) = (v, u + v^3 + c)",
            lambda c: (), lambda c: (lambda x, y: y - x ** 3 - c)),
}


def _declared_cond(ctx: _Ctx) -> tuple[str, _Cond]:
    """``NAME(x, y; P)`` for a declared diffeo (two variables only): the condition text of an
    ``ifge0`` and its zero set."""
    name = ctx.pick(tuple(DIFFEOS))
    decl, lines, g = DIFFEOS[name]
    p = ctx.pick(ctx.names)
    c = ctx.pvals[p]
    ctx.diffeos[name] = decl
    cond = _Cond(name, "", p, g(c), lines(c), ("diffeo", name, p) if name == "cub" else ("lin", name, p))
    if name == "sh":
        cond.key = ("lin", "1", "1", p, "0")
    ctx.conds.append(cond)
    return f"{name}(x, y; {p})", cond


def _nonlinear_cond(ctx: _Ctx) -> _Cond:
    """``[v^2 <= P + k]``, ``[y >= x^2 + P + k]`` or the disk ``[x^2 + y^2 <= P + k]``."""
    shapes = ("square", "parabola", "disk") if len(ctx.variables) == 2 else ("square",)
    shape = ctx.pick(shapes)
    p = ctx.pick(ctx.names)
    k = ctx.pick(("0.3", "0", "0.55", "-0.2"))
    off = "" if k == "0" else (f" - {k[1:]}" if k.startswith("-") else f" + {k}")
    r = ctx.pvals[p] + float(k)
    if shape == "square":
        v = ctx.var()
        cmp = ctx.pick(("<=", ">="))
        lines = ((1.0, 0.0, math.sqrt(r)), (1.0, 0.0, -math.sqrt(r))) if r > 0 else ()
        if v == "y":
            lines = tuple((0.0, 1.0, c) for _, _, c in lines)
            g = (lambda x, y: y * y - r)
        else:
            g = (lambda x, y: x * x - r)
        return _Cond(f"{v}^2", cmp, f"{p}{off}", g, lines, ("sq", v, p, k))
    if shape == "parabola":
        cmp = ctx.pick((">=", "<="))
        return _Cond("y", cmp, f"x^2 + {p}{off}", lambda x, y: y - x * x - r, (), ("par", p, k))
    return _Cond("x^2 + y^2", "<=", f"{p}{off}", lambda x, y: x * x + y * y - r, (), ("disk", p, k))


def _cond(ctx: _Ctx) -> _Cond:
    kind = ctx.draw(ctx.st.integers(0, 5))
    c = _nonlinear_cond(ctx) if kind == 3 else _scaled_cond(ctx) if kind == 4 else _affine_cond(ctx)
    ctx.conds.append(c)
    return c


def _smooth(ctx: _Ctx) -> str:
    """A smooth factor: polynomial, exp, sin, cos or sqrt of affine/quadratic terms (sqrt's
    argument positive on every box: all boxes lie in [-1, 2] and parameters are positive)."""
    v = ctx.var()
    w = ctx.var()
    p = ctx.pick(ctx.names)
    k = ctx.pick(("0.5", "1.5", "2", "0.25"))
    forms = (
        f"({v} + {k})",
        f"({p}*{v} + {k})",
        f"{v}^2",
        f"({v}*{w} - {p})",
        f"exp({k}*{v} - {p})",
        f"sin({v} + {p}*{w})",
        f"cos({p}*{v} - {k})",
        f"sqrt({v} + 1.5)",
        f"sqrt({v}*{v} + {p})",
        f"{p}",
        f"log({v} + 2)",
        f"atan({v}*{w} + {p})",
        f"tanh({p}*{v})",
        f"1 / ({v} + {p} + 1.5)",
        f"({v} + {p})^3",
        f"({w} + 1.5)^1.5",
        f"exp(min({v}, {p}))",
        f"sqrt(max({v}, {p}) + 1.5)",
        f"abs({v} - {p})",
    )
    form = ctx.pick(forms[:ctx.n_smooth])
    if form in forms[16:]:
        # min, max and abs are conditionals: their zero set v = p counts like any other (a kink
        # on a jump's zero set is a coincidence of Def. 7.2, even if its delta has zero weight)
        pv = ctx.pvals[p]
        line = (1.0, 0.0, pv) if v == "x" else (0.0, 1.0, pv)
        key = ("lin", "1", "0", p, "0") if v == "x" else ("lin", "0", "1", p, "0")
        g = (lambda x, y: x - pv) if v == "x" else (lambda x, y: y - pv)
        ctx.conds.append(_Cond(v, ">=", p, g, (line,), key))
    return form


def _kink_cond(ctx: _Ctx) -> str:
    """A condition with a kink inside (issue 18; split by the desugarer at the kink): the window
    ``[abs(v - P) <= k]`` (zero sets v = P and v = P ± k), ``[max(v, c) >= P]`` (v = c and v = P)
    or, in two variables, ``[min(x, y) >= P]`` (x = y, x = P, y = P).  Each zero set is registered,
    so the program stays generic (no two coincide, none through a corner)."""
    p = ctx.pick(ctx.names)
    pv = ctx.pvals[p]
    shapes = ("abs", "max", "min") if len(ctx.variables) == 2 else ("abs", "max")
    shape = ctx.pick(shapes)

    def vertical(v, c, key):
        line = (1.0, 0.0, c) if v == "x" else (0.0, 1.0, c)
        g = (lambda x, y: x - c) if v == "x" else (lambda x, y: y - c)
        ctx.conds.append(_Cond(v, ">=", str(c), g, (line,), key))

    if shape == "abs":
        v, k = ctx.var(), ctx.pick(("0.2", "0.35"))
        for c, tag in ((pv, "0"), (pv + float(k), k), (pv - float(k), "-" + k)):
            vertical(v, c, ("kink", v, p, tag))
        return f"[abs({v} - {p}) <= {k}]"
    if shape == "max":
        v, c = ctx.var(), ctx.pick(("0.45", "0.65"))
        vertical(v, float(c), ("kink", v, c))
        vertical(v, pv, ("kink", v, p, "0"))
        return f"[max({v}, {c}) >= {p}]"
    ctx.conds.append(_Cond("x", ">=", "y", lambda x, y: x - y, ((1.0, -1.0, 0.0),), ("kink", "diag")))
    vertical("x", pv, ("kink", "x", p, "0"))
    vertical("y", pv, ("kink", "y", p, "0"))
    return f"[min(x, y) >= {p}]"


def _factor(ctx: _Ctx) -> str:
    if ctx.kinks and ctx.draw(ctx.st.integers(0, 3)) == 0:
        return _kink_cond(ctx)
    kind = ctx.draw(ctx.st.integers(0, 9 if len(ctx.variables) == 2 else 8))
    if kind == 8:  # a conditional on parameters only (ifge0 with a variable-free condition)
        p, q = ctx.pick(ctx.names), ctx.pick(ctx.names)
        rhs = ctx.pick(("0.5", q)) if p != q else "0.5"
        hypothesis_assume(abs(ctx.pvals[p] - (0.5 if rhs == "0.5" else ctx.pvals[q])) > 1e-6)
        return f"(if {p} >= {rhs} then {_smooth(ctx)} else {ctx.pick(('0', _smooth(ctx)))})"
    if kind == 9:  # a declared diffeo (two variables)
        cond, _ = _declared_cond(ctx)
        return f"(ifge0 {cond} then {_smooth(ctx)} else {ctx.pick(('0', '1', _smooth(ctx)))})"
    if kind == 6:  # nested conditionals: ifge0 inside a branch (their zero sets multiply)
        c1, c2 = _cond(ctx), _cond(ctx)
        inner = f"(if {c2.lhs} {c2.cmp} {c2.rhs} then {_smooth(ctx)} else {ctx.pick(('0', _smooth(ctx)))})"
        return f"(if {c1.lhs} {c1.cmp} {c1.rhs} then {inner} else {ctx.pick(('1', _smooth(ctx)))})"
    if kind == 7:  # a chained bracket: a window between two parallel jumps
        c = _affine_cond(ctx)
        k = ctx.pick(("0.35", "0.6"))
        hi = _Cond(c.lhs, "<=", f"{c.rhs} + {k}", None, (), c.key + ("hi", k))
        fx, fy, cc = c.lines[0]
        lo_g, dk = c.g, float(k)
        hi.g = lambda x, y: lo_g(x, y) - dk
        hi.lines = ((fx, fy, cc + dk),)
        ctx.conds += [c, hi]
        return f"[{c.rhs} <= {c.lhs} <= {c.rhs} + {k}]"
    if kind <= 1:
        return _smooth(ctx)
    if kind <= 3:
        c = _cond(ctx)
        return f"[{c.lhs} {c.cmp} {c.rhs}]"
    if kind == 4:
        c = _cond(ctx) if ctx.draw(ctx.st.booleans()) else _affine_cond_registered(ctx)
        then = _smooth(ctx)
        orelse = ctx.pick(("0", "1", "0.5", _smooth(ctx)))
        return f"(if {c.lhs} {c.cmp} {c.rhs} then {then} else {orelse})"
    c = _affine_cond_registered(ctx)  # min/max of (lhs, rhs): the zero set lhs = rhs
    return f"{ctx.pick(('min', 'max'))}({c.lhs}, {c.rhs})"


def _affine_cond_registered(ctx: _Ctx) -> _Cond:
    c = _affine_cond(ctx)
    ctx.conds.append(c)
    return c


def _box(ctx: _Ctx, v: str, params: list[str]) -> tuple[str, str, float, float]:
    kind = ctx.draw(ctx.st.integers(0, 4))
    if kind == 0:
        return "0", "1", 0.0, 1.0
    if kind == 1:
        return "-1", "1", -1.0, 1.0
    if kind == 2:
        return "0", "2", 0.0, 2.0
    p = ctx.pick(params)
    if kind == 3:
        return "0", f"{p} + 1", 0.0, ctx.pvals[p] + 1
    return f"{p} - 1", "1", ctx.pvals[p] - 1, 1.0


def _norm_line(line):
    cx, cy, c = line
    n = math.hypot(cx, cy)
    cx, cy, c = cx / n, cy / n, c / n
    if cx < -1e-12 or (abs(cx) <= 1e-12 and cy < 0):
        cx, cy, c = -cx, -cy, -c
    return cx, cy, c


def hypothesis_assume(cond: bool) -> None:
    hypothesis, _ = _hypothesis()
    hypothesis.assume(cond)


def _generic(ctx: _Ctx, boxes) -> bool:
    """No two zero sets (nor a zero set and a face of the box) coincide at the defaults, and no
    zero set passes through a corner of the box."""
    keys = [c.key for c in ctx.conds]
    if len(set(keys)) != len(keys):
        return False
    lines = []
    for i, (lo, hi) in enumerate(boxes):
        e = (1.0, 0.0) if i == 0 else (0.0, 1.0)
        lines += [(("box",), (*e, lo)), (("box",), (*e, hi))]
    for j, c in enumerate(ctx.conds):
        lines += [((j,), ln) for ln in c.lines]
    normed = [(tag, _norm_line(ln)) for tag, ln in lines]
    for i in range(len(normed)):
        for j in range(i + 1, len(normed)):
            if normed[i][0] == normed[j][0] == ("box",):
                continue
            if all(abs(a - b) < 1e-6 for a, b in zip(normed[i][1], normed[j][1])):
                return False
    corners = [(lo, 0.0) for lo in boxes[0]] if len(boxes) == 1 else \
        [(x, y) for x in boxes[0] for y in boxes[1]]
    for c in ctx.conds:
        for x, y in corners:
            if abs(c.g(x, y)) < 1e-6:
                return False
    return True


def _extract_def(ctx: _Ctx, terms: list[list[str]], variables, params) -> list[str]:
    """Move one factor into ``def g(x: var, …, qa: param, …) = …`` and call it there (and maybe
    once more, in a new summand: two call sites of one def, added, never multiplied), so that
    elaboration, inlining and the Monte Carlo engine's separately compiled defs are exercised."""
    cands = [(i, j) for i, fs in enumerate(terms) for j, f in enumerate(fs) if not re.search(r"\bs\b", f)]
    if not cands:
        return []
    i, j = ctx.pick(cands)
    body = terms[i][j]
    used = [p for p in params if re.search(rf"\b{p}\b", body)]
    for p in used:
        body = re.sub(rf"\b{p}\b", f"q{p}", body)
    args = ", ".join([f"{v}: var" for v in variables] + [f"q{p}: param" for p in used])
    call = f"g({', '.join([*variables, *used])})"
    terms[i][j] = call
    if ctx.draw(ctx.st.booleans()):
        terms.append([call, _smooth(ctx)])
    return [f"def g({args}) = {body}"]


def programs(max_summands: int = 3, max_factors: int = 3, max_conds: int = 4, max_params: int = 3,
             light: bool = False, kinks: bool = False):
    """A hypothesis strategy of :class:`FuzzProgram` (well-typed, transverse at the defaults).

    ``max_conds`` bounds the number of zero sets per program and ``max_params`` the parameters
    (each one is a derivative to compute): both bound the exact engine's work.  ``light`` keeps
    to polynomials, exp, sin, cos and sqrt (sympy integrates atan, log and fractional powers over
    regions slowly: the fast property test uses it).  ``kinks`` adds conditions with ``abs``, ``min``
    or ``max`` inside (:func:`_kink_cond`); without it the strategy draws exactly as before."""
    hypothesis, st = _hypothesis()

    @st.composite
    def program(draw):
        nvars = draw(st.integers(1, 2))
        variables = ("x", "y")[:nvars]
        npar = draw(st.integers(1, max_params))
        params = list(PARAMS[:npar])
        defaults = draw(st.lists(st.sampled_from(GENERIC), min_size=npar, max_size=npar, unique=True))
        pvals = {p: float(d) for p, d in zip(params, defaults)}
        ctx = _Ctx(draw, st, variables, pvals)
        if light:
            ctx.n_smooth = 10
        ctx.kinks = kinks
        boxes_txt, boxes = [], []
        for v in variables:
            lo, hi, flo, fhi = _box(ctx, v, params)
            boxes_txt.append(f"[{lo}, {hi}]")
            boxes.append((flo, fhi))
        let = None
        if draw(st.integers(0, 3)) == 3:  # let s = <positive variable-free term> in …
            p, q = params[0], params[-1]
            bound = ctx.pick((f"2*{p}", f"{p} + 0.5*{q}", f"{p}*{q} + 0.1"))
            ctx.pvals["s"] = ctx.ev(bound.replace("^", "**"))
            ctx.names.append("s")
            let = bound
        terms = []
        for _ in range(draw(st.integers(1, max_summands))):
            terms.append([_factor(ctx) for _ in range(draw(st.integers(1, max_factors)))])
        defs = _extract_def(ctx, terms, variables, params) if draw(st.integers(0, 2)) == 2 else []
        summands = [ctx.pick(("", "0.7 * ", "-1.3 * ", "2 * ")) + " * ".join(fs) for fs in terms]
        body = " + ".join(summands)
        body = body.replace("+ -", "- ")
        hypothesis.assume(len(ctx.conds) <= max_conds)
        hypothesis.assume(_generic(ctx, boxes))
        if let is not None:
            body = f"let s = {let} in {body}"
        decl = ", ".join(f"{p} = {d}" for p, d in zip(params, defaults))
        text = (f"param {decl}\n" + "".join(f"{d}\n" for d in [*ctx.diffeos.values(), *defs]) +
                f"int ({', '.join(boxes_txt)})\n  {body}\nd({', '.join(variables)})\n")
        return FuzzProgram(text, tuple(zip(params, defaults)))

    return program()
