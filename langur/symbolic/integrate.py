"""The exact integrator of the symbolic engine (paper §6.3, §7.3 Theorem 7.1, §8; LANGUAGE.md §3–§4).

    integrate_pieces(pieces, variables, box, at, *, timeout=20.0) -> Integral
    integrate_delta_pieces(pieces, variables, box, at, *, timeout=20.0) -> Integral

``pieces`` are summed.  Each piece is integrated exactly by :mod:`langur.symbolic.regions`
(regions from the conditions, sympy only on smooth integrands with plain bounds, every sympy call
time-boxed), and every piece is also integrated by the independent adaptive quadrature of
:mod:`langur.symbolic.quadrature`.  A closed form that disagrees with its quadrature (relative +
absolute tolerance ~1e-7) is judged by an interval enclosure of the piece's integral
(:mod:`langur.symbolic.quadrature.enclosed`, a proof): kept, with a note, when the enclosure holds
it and excludes the quadrature (a peak between quad's samples); otherwise an internal inconsistency:
the quadrature is reported instead, with a note, and the result's ``inconsistent`` lists what
disagreed.  A piece without a closed form (no elementary antiderivative, unsolvable condition, time
limit) falls back to its quadrature: the result's ``method`` is then ``Method.QUADRATURE``, ``expr``
is None, ``error`` the quadrature's error estimate, ``proved`` the bound an enclosure proves (None:
none; a quadrature outside its enclosure is replaced by the enclosure's midpoint), and the notes
keep the exact part.

Notes convention (for the CLI): the first note is one of
``"closed form valid for all parameter values"`` or
``"closed form valid in the parameter cell containing the evaluation point: C1; C2; …"`` where
each ``Ci`` is a sympy relation between parameters (decisions taken at the evaluation point while
ordering bounds, deciding signs or Piecewise branches); with ``" (and with the same real roots)"``
appended when roots were ordered numerically.  Further notes explain assumptions (e.g. the sign
of a Jacobian sampled at the evaluation point).  With ``Method.QUADRATURE`` the notes are
``"no closed form for k of n pieces; …"``, one reason per piece that fell back, then
``"exact part (<the cell note above>): <expr>"`` when some pieces had closed forms (not within
:func:`untidied`: no text for people is wanted there).

Delta pieces go through :mod:`langur.symbolic.delta` (change of variables, then the same region
machinery over ``u'``).  Errors: :class:`~langur.symbolic.quadrature.UndefinedIntegral` (a
``ValueError``) when the integral does not exist: quadrature's own diagnostics say it diverges,
or the integrand is undefined (NaN) on part of the region (the quadrature runs first, so a closed
form is never returned for such an integral); ``ValueError`` when a delta piece's zero set cannot
be bounded.
"""

from __future__ import annotations

import math
import time
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator, Sequence

import sympy as sp

from langur import failures
from langur.implicit import ImplicitRootFn
from langur.memo import remember as _remember
from langur.symbolic import delta, offbox, quadrature, regions, walks
from langur.symbolic.context import Cond, Context, Unsupported
from langur.symbolic.nounits import units_unloaded
from langur.symbolic.pieces import DeltaPiece, Integral, Method, Piece
from langur.symbolic.quadrature import UndefinedIntegral, enclosed
from langur.symbolic.text import shared_sstr, shared_sstrs
from langur.timebox import Deadline

RTOL = 1e-7
ATOL = 1e-7
CELL_PREFIX = "closed form valid in the parameter cell containing the evaluation point: "
ALL_PARAMS = "closed form valid for all parameter values"


class IntegrationMismatch(RuntimeError):
    """A closed form disagrees with the independent quadrature: an internal error."""

    def __init__(self, closed: float, quad: float, error: float, expr=None, what: str = ""):
        self.closed = closed
        self.quad = quad
        self.error = error
        self.expr = expr
        super().__init__(
            f"internal error: closed form {closed!r} disagrees with quadrature {quad!r} "
            f"(± {error:.2g}){' for ' + what if what else ''}: {expr}")


def _at(at: dict) -> dict:
    out = {}
    for k, v in at.items():
        if isinstance(v, sp.Basic):
            out[k] = v
        elif isinstance(v, int):
            out[k] = sp.Integer(v)
        else:
            out[k] = sp.Float(float(v), 30)
    return out


def _value(expr, ctx: Context) -> float:
    z = ctx.exact_value(expr)
    if abs(z.imag) > 1e-9 * max(1.0, abs(z.real)):
        raise Unsupported(f"closed form is not real at the evaluation point: {z}")
    return z.real


def _agree(closed: float, quad: float, err: float) -> bool:
    if not (math.isfinite(closed) and math.isfinite(quad)):
        return False
    tol = max(ATOL + RTOL * abs(quad), 10.0 * err)
    return abs(closed - quad) <= tol


#: Seconds sympy's simplify may spend on a closed form (cosmetic: the form found is kept).
TIDY_SECONDS = 1.0
#: Simplified forms by closed form (the same one comes back for the value and the checks).
_TIDIED: dict = {}


#: Whether closed forms are simplified for people to read (:func:`untidied` turns it off).
_TIDYING: ContextVar[bool] = ContextVar("tidying", default=True)


def for_reading() -> bool:
    """Whether closed forms are wanted in a form for people (False within :func:`untidied`)."""
    return _TIDYING.get()


@contextmanager
def untidied() -> Iterator[None]:
    """Within the block closed forms are neither simplified nor printed for reading (``langur
    fuzz`` compares values: sympy's simplify would cost it up to :data:`TIDY_SECONDS` per closed
    form, printing a large one seconds)."""
    token = _TIDYING.set(False)
    try:
        yield
    finally:
        _TIDYING.reset(token)


def _tidy(expr, ctx: Context):
    """A simpler equal form (checked at the evaluation point): sympy's simplify within
    :data:`TIDY_SECONDS`, or, for Piecewise conditions that are not polynomial, the Piecewise folded
    (:func:`_nonpolynomial_conditions`: the same form whatever the machine's load)."""
    if not _TIDYING.get() or walks.size(expr, 1000) >= 1000 or sp.count_ops(expr) > 300 \
            or len(expr.atoms(sp.Max, sp.Min)) > 2 or expr.has(ImplicitRootFn):
        # (size first: count_ops takes seconds on a large form.)  sympy's simplify is slow on
        # Max/Min and rarely helps there; it has no rule for an implicit root, whose values it
        # computes again and again (a second of root finding for an unchanged form: turning.lgr)
        return expr
    s = _TIDIED.get(expr)
    if s is None:
        if _nonpolynomial_conditions(expr):
            # sympy's simplify would solve inequalities in √a or log(a + 1) for these conditions
            # (continuous domains, periodicity): about a CPU second for a sum of two such Piecewise
            # (quadratic_one_root.lgr), so near the cap that whether it finished — and the printed
            # form — depended on the machine's load.  Folding the Piecewise is cheap and the same
            # on every machine (2·Piecewise((−1/(2·|√a|), …)) → Piecewise((−1/|√a|, …))).
            s = sp.piecewise_fold(expr)
        else:
            try:
                s = ctx.deadline.run(lambda: sp.simplify(expr), cap=TIDY_SECONDS)
            except Exception:  # noqa: BLE001 - simplification is cosmetic; TimeoutError included
                return expr
        _remember(_TIDIED, expr, s, 512)
    try:
        a, b = _value(expr, ctx), _value(s, ctx)
    except (Unsupported, TypeError, ValueError):
        return expr
    if abs(a - b) <= 1e-12 * (1 + abs(a)) and sp.count_ops(s) <= sp.count_ops(expr):
        return s
    return expr


def _nonpolynomial_conditions(expr) -> bool:
    """Whether a condition of a Piecewise in ``expr`` relates expressions that are not polynomials
    in their symbols (``sqrt(a) <= 1``, ``log(a + 1) >= 0``): the closed forms :func:`_tidy` leaves
    to :func:`sympy.piecewise_fold` instead of sympy's simplify."""
    for pw in expr.atoms(sp.Piecewise):
        for _, cond in pw.args:
            if not isinstance(cond, sp.Basic):
                continue
            for rel in cond.atoms(sp.core.relational.Relational):
                d = rel.lhs - rel.rhs
                if not d.is_polynomial(*d.free_symbols):
                    return True
    return False


#: The text of the cell's relations by relation: the same relations (a polygon's vertices inside
#: the other half-planes) come back for the value, each partial derivative and the checks, and
#: sympy prints a large one with its terms sorted (a tenth of a second each; the shared printer's
#: text is the same, each subtree the relations share printed once).
_RELATION_TEXTS: dict = {}


def _relation_texts(rels) -> list[str]:
    """Each relation's text; those not known yet printed by one shared printer (the relations of a
    polygon's cell share its vertices, each in the relations with every other line)."""
    new = [rel for rel in dict.fromkeys(rels) if rel not in _RELATION_TEXTS]
    for rel, text in zip(new, shared_sstrs(new)):
        _remember(_RELATION_TEXTS, rel, text, 4096)
    return [_RELATION_TEXTS.get(rel) or shared_sstr(rel) for rel in rels]


def _relation_text(rel) -> str:
    return _relation_texts((rel,))[0]


def _finish(exacts, quads, fallbacks, ctx: Context, what: str, converged=None, prove=None) -> Integral:
    """Combine per-piece closed forms (None where missing) with per-piece quadratures (a piece
    whose quadrature did not converge was cross-checked only roughly: so is the sum); ``prove``
    (:func:`_prover`'s, or None: no proofs) encloses a piece that has only its quadrature."""
    notes = []
    cell = "; ".join(_relation_texts(ctx.cell))
    first = (CELL_PREFIX + cell) if cell else ALL_PARAMS
    if ctx.generic:
        first += " (and with the same real roots)"
    check = sum(q for q, _ in quads)
    if all(e is not None for e in exacts):
        expr = sp.Add(*exacts) if exacts else sp.Integer(0)
        value = _value(expr, ctx) if exacts else 0.0
        err = sum(e for _, e in quads)
        if all(converged or [True]) and not _agree(value, check, err):
            ctx.inconsistent.append(str(IntegrationMismatch(value, check, err, expr, what)))
            return _quadrature_only(quads, ctx, what)
        expr = _tidy(expr, ctx)
        notes.append(first)
        notes.extend(dict.fromkeys(ctx.notes))
        return Integral(expr, value, Method.CLOSED_FORM, 0.0, check if exacts else None, notes, everywhere=not cell,
                        inconsistent=tuple(ctx.inconsistent), cell=tuple(ctx.cell), generic=ctx.generic)
    value = 0.0
    error = 0.0
    proved: float | None = 0.0  # a proved bound on the quadratures' error (None: not proved)
    exact_part = []
    for i, (e, (q, qe)) in enumerate(zip(exacts, quads)):
        if e is not None:
            value += _value(e, ctx)
            exact_part.append(e)
            continue
        enc = prove(i, qe, enclosed.CELLS) if prove is not None else None
        if enc is not None and not (enc.confirms(q, qe) or enc.dimensions > 1 and enc.holds(q, qe)):
            # a closer look (:data:`~.enclosed.CELLS_REFUTED` cells): where quadrature is refuted, or on one
            # variable, where the rule's remainder makes more cells pay (on more, a curved boundary's cells
            # narrow as h³: 3,000 cells take 2 CPU s to prove implicit2d ≤ 2e-4, not 1e-10 — not worth it
            # at every point of a render; bench/history/2026-11-29.md#proof33
            enc = prove(i, qe, enclosed.CELLS_REFUTED) or enc
        if enc is not None and not enc.holds(q, qe):  # quadrature missed mass: the proof is the answer
            q = (enc.lo + enc.hi) / 2
            qe = enc.distance(q)
            ctx.notes.append(f"{what[:-1]} {i}: quadrature gave {quads[i][0]:.10g} ± {quads[i][1]:.2g}, outside its "
                             f"interval enclosure [{enc.lo:.10g}, {enc.hi:.10g}] (outward-rounded interval arithmetic "
                             f"over {enc.cells} cells: a proof), so it missed mass between its samples: the "
                             "enclosure's midpoint is reported, its half-width the error bound")
        value += q
        error += qe
        proved = None if enc is None or proved is None else proved + enc.distance(q)
    notes.append(f"no closed form for {sum(e is None for e in exacts)} of {len(exacts)} "
                 f"{what}; adaptive quadrature at the evaluation point")
    notes.extend(dict.fromkeys(w for w in fallbacks if w))
    if ctx.estimated and (proved is None or proved > error):  # (a proof within the estimate backs it)
        notes.append(quadrature.ESTIMATE)
    if exact_part and for_reading():  # (untidied: not printed, a tenth of a second per large part)
        notes.append(f"exact part ({first}): {sp.Add(*exact_part)}")
    notes.extend(dict.fromkeys(ctx.notes))
    return Integral(None, value, Method.QUADRATURE, error, check, notes, inconsistent=tuple(ctx.inconsistent),
                    proved=proved)


def _quadrature_only(quads, ctx: Context, what: str) -> Integral:
    """The quadratures alone, when the closed forms' sum disagrees with them (an engine bug)."""
    value, error = sum(q for q, _ in quads), sum(e for _, e in quads)
    notes = [f"the closed form of the {what} disagreed with the quadrature cross-check, an internal "
             "inconsistency of the exact engine (please report it): the quadrature is reported"]
    if ctx.estimated:
        notes.append(quadrature.ESTIMATE)
    return Integral(None, value, Method.QUADRATURE, error, value, notes + list(dict.fromkeys(ctx.notes)),
                    inconsistent=tuple(ctx.inconsistent))


def _setup(variables, box, at, timeout, cell=()):
    at = _at(dict(at))
    ctx = Context(at, Deadline(timeout), frozenset(at))
    for rel in cell:  # decisions taken before integrating (parameter-only conditionals)
        ctx.record_relation(rel)
    boxd = {v: (sp.sympify(lo), sp.sympify(hi)) for v, (lo, hi) in zip(variables, box)}
    return ctx, boxd


def _beyond_doubles(expr, ctx: Context) -> sp.Float | None:
    """``expr``'s value at the point (15 digits) when it is a finite real number too large for a
    double (``1e200**2/2``), else None (a pole, ∞, or no value within the call's budget)."""
    try:
        v = ctx.deadline.run(lambda: sp.sympify(expr).xreplace(ctx.at).evalf(15), 1.0)
    except (TimeoutError, TypeError, ValueError, ArithmeticError):
        return None
    return v if isinstance(v, sp.Float) and v.is_finite else None


class NoFloat(tuple):
    """A piece's quadrature ``(∞, ∞)`` stopped by :class:`~.quadrature.BeyondRange` (``exc``): its
    integrand's values are too large for a float, so only a closed form can give its value, and it
    is not cross-checked (bench/history/2026-11-29.md#overflow33."""

    def __new__(cls, exc: quadrature.BeyondRange):
        out = super().__new__(cls, (math.inf, math.inf))
        out.exc = exc
        return out


#: Agreement asked of a closed form whose quadrature did not converge (its error bound is not
#: reliable: ∫₀^½ dx/(x log²x) = 1/log 2 = 1.4427 against quad's 1.4389 ± 1.6e-5).
ROUGH = 1e-2


def _exact_piece(problems, uvars, ubox: dict, ctx: Context, quad: tuple[float, float], what,
                 converged: bool = True):
    """Closed form of one piece (sum over its regular problems) cross-checked, or the reason."""
    total = sp.Integer(0)
    for conds, weight in problems:
        total += regions.integrate_region(conds, weight, uvars, ubox, ctx)
    val = _value(total, ctx)
    if not math.isfinite(val):
        huge = _beyond_doubles(total, ctx)
        if huge is not None:
            raise quadrature.BeyondRange(f"{what}'s closed form {total} is {huge:.6g} at the evaluation point: a "
                                         "finite number too large for a float (beyond ±1.8e308), which this "
                                         "engine's values are")
        raise Unsupported(f"the closed form {total} is singular at the evaluation point")
    if isinstance(quad, NoFloat):
        ctx.notes.append(f"{what}: the closed form is not cross-checked: {quad.exc}")
    elif not converged:
        if abs(val - quad[0]) > ROUGH * max(1.0, abs(quad[0])) + 10 * quad[1]:
            raise Unsupported(f"the closed form {total} is {val:.6g}, quadrature (which did not converge) "
                              f"{quad[0]:.6g}: neither is trusted")
        ctx.notes.append(f"{what}: the closed form is cross-checked only to {ROUGH:.0%} (quadrature did not "
                         "converge)")
    elif not _agree(val, *quad):
        raise IntegrationMismatch(val, quad[0], quad[1], total, what)
    return total


class QuadratureUnreliable(ValueError):
    """No closed form, and quadrature did not converge: no value with an error bound to trust."""


def _check_defined(quads, what: str) -> None:
    """A piece whose quadrature is NaN or infinite is undefined — unless its quadrature stopped
    because its values are beyond the doubles (:class:`NoFloat`: its closed form decides)."""
    for i, (q, _) in enumerate(quads):
        if not math.isfinite(q) and not isinstance(quads[i], NoFloat):
            raise UndefinedIntegral(f"{what} {i}: the integrand is undefined ({q}) on part of the region at "
                                    "the evaluation point (a primitive applied outside its domain, or a "
                                    "zero set where the condition's derivative vanishes)")


#: Seconds (wall clock) this process has spent looking for closed forms (``symbolic``: regions,
#: sympy's antiderivatives, the cross-check) and in the independent quadrature (``quadrature``);
#: ``langur fuzz --profile`` reads them per program.
SPENT = {"symbolic": 0.0, "quadrature": 0.0}


@contextmanager
def _spending(what: str) -> Iterator[None]:
    start = time.monotonic()
    try:
        yield
    finally:
        SPENT[what] += time.monotonic() - start


#: Why a piece has no closed form when only its value was asked for (``symbolic=False``).
VALUE_ONLY = "value only: quadrature (no closed form sought)"


def _exact_pieces(*args, **kwargs):
    """:func:`_closed_forms`, its time added to ``SPENT["symbolic"]``."""
    with _spending("symbolic"):
        return _closed_forms(*args, **kwargs)


def _closed_forms(make_problems, n: int, quads, ctx: Context, what: str, converged=None,
                  symbolic: bool = True, prove=None):
    """Closed forms per piece (None where there is none) and the reasons for the fallbacks; a piece
    whose quadrature did not converge must have a closed form (:class:`QuadratureUnreliable`).
    Without ``symbolic`` only such pieces are integrated symbolically (a value is all that is
    wanted, and a converged quadrature gives it with its error bound).  A closed form that
    disagrees with its quadrature is kept when ``prove`` encloses the piece's integral around it
    and away from the quadrature (:func:`_judged`; ``quads[i]`` becomes the closed form's value
    and its distance to the enclosure's ends)."""
    exacts, why = [], []
    converged = converged or [True] * n
    for i in range(n):
        if not symbolic and converged[i]:
            exacts.append(None)
            why.append(f"{what} {i}: {VALUE_ONLY}")
            continue
        try:
            if ctx.deadline.remaining() <= 0:  # the call's one budget is spent (issue 15): quadrature
                raise TimeoutError("time limit")  # (a piece's region work need not ask the deadline)
            problems, uvars, ubox = make_problems(i)
            exacts.append(_exact_piece(problems, uvars, ubox, ctx, quads[i], f"{what} {i}", converged[i]))
            why.append("")
        except IntegrationMismatch as exc:  # one of the two is wrong: a proof decides, if there is one
            enc = _judged(exc, prove(i, abs(exc.closed - exc.quad) / 4, enclosed.CELLS_REFUTED) if prove else None,
                          ctx, f"{what} {i}")
            if enc is not None:
                exacts.append(exc.expr)
                why.append("")
                quads[i] = (exc.closed, enc.distance(exc.closed))
            else:  # an engine bug, or undecided: the quadrature stands, and says so
                exacts.append(None)
                why.append(f"{what} {i}: {exc}")
                ctx.inconsistent.append(str(exc))
        except quadrature.BeyondRange:  # a closed form whose value is no double: no other value is better
            raise
        except (Unsupported, TimeoutError) as exc:
            exacts.append(None)
            why.append(f"{what} {i}: {exc or 'time limit'}")
        except Exception as exc:  # noqa: BLE001 - sympy fails in many ways; quadrature still holds
            exacts.append(None)
            why.append(f"{what} {i}: {failures.why(exc)}")
        if exacts[-1] is None and isinstance(quads[i], NoFloat):
            raise quads[i].exc  # (its own words: the integrand's values are too large for a float)
        if exacts[-1] is None and not converged[i]:
            raise QuadratureUnreliable(f"{what} {i} has no closed form ({why[-1].split(': ', 1)[-1]}) and its "
                                       "quadrature did not converge (scipy), so no value has an error bound "
                                       "to trust")
    return exacts, why


def _judged(exc: IntegrationMismatch, enc: enclosed.Enclosed | None, ctx: Context, what: str):
    """``enc`` when it proves the closed form right and the quadrature wrong (the closed form
    inside the enclosure, the quadrature outside it by more than its error estimate), else None;
    a note says which was kept and why."""
    if enc is None:
        return None
    inside, outside = enc.holds(exc.closed), not enc.holds(exc.quad, exc.error)
    where = (f"the interval enclosure [{enc.lo:.10g}, {enc.hi:.10g}] of its integral (outward-rounded "
             f"interval arithmetic over {enc.cells} cells: a proof)")
    if inside and outside:
        ctx.notes.append(f"{what}: closed form kept ({exc.closed:.10g}): the quadrature cross-check gave "
                         f"{exc.quad:.10g} ± {exc.error:.2g}, outside {where}, which holds the closed form: "
                         "quadrature missed mass between its samples")
        return enc
    if not inside and not outside:
        ctx.notes.append(f"{what}: the closed form {exc.closed:.10g} is outside {where}, which holds the "
                         f"quadrature {exc.quad:.10g}: the closed form is wrong, the quadrature kept")
    return None


def _quads(quad_one, items, ctx: Context):
    """Each piece's quadrature ``(value, error)`` and whether it converged (its notes go to ctx);
    its time is added to ``SPENT["quadrature"]``."""
    with _spending("quadrature"):
        return _quadratures(quad_one, items, ctx)


def _quadratures(quad_one, items, ctx: Context):
    quads, converged = [], []
    for item in items:
        notes: list[str] = []
        problems: list[quadrature.NumProblem] = []
        try:
            quads.append(quad_one(item, notes, problems))
        except quadrature.BeyondRange as exc:  # no float quadrature: only a closed form gives the value
            quads.append(NoFloat(exc))  # (a piece that did not converge: _closed_forms requires one)
            converged.append(False)
            ctx.notes.extend(notes)
            continue
        converged.append(all(p.converged for p in problems))
        ctx.estimated = ctx.estimated or any(p.wide for p in problems)
        ctx.notes.extend(notes)
    return quads, converged


@units_unloaded()  # sympy's simplify without its import of physical units (nounits.py)
def integrate_pieces(pieces: Sequence[Piece], variables, box, at, *, timeout: float = 20.0,
                     cell: Sequence[sp.Rel] = (), symbolic: bool = True, proofs: bool = True) -> Integral:
    """Σ ∫_box Π[conditions]·weight (regular part of a denotation or derivative denotation);
    ``cell``: relations on the parameters the pieces were built on (the closed form holds there);
    without ``symbolic``, the value by quadrature (closed forms only where it did not converge);
    with ``symbolic`` and ``proofs``, a quadrature's error is proved where interval enclosures can
    (:func:`_prover`), and a closed form disagreeing with its quadrature judged by one."""
    variables = tuple(variables)
    ctx, boxd = _setup(variables, box, at, timeout, cell)
    # (each piece's quadrature as it is on the box near the point: 0 where it vanishes there, offbox.py)
    quads, converged = _quads(lambda pc, *out: (0.0, 0.0) if pc is None else
                              quadrature.quad_pieces([pc], variables, box, ctx.at, *out),
                              offbox.reduced(pieces, boxd, ctx.at), ctx)
    _check_defined(quads, "piece")
    ctx.deadline = Deadline(timeout)  # the time limit is for the symbolic work

    def problems(i):
        pc = pieces[i]
        conds = [Cond(sp.sympify(c.expr), psi=c.psi) for c in pc.conditions]
        return [(conds, sp.sympify(pc.weight))], list(variables), boxd

    # (not within :func:`untidied`: ``langur fuzz`` compares values under a per-program time limit, which
    # the proofs' tenths of a second per quadrature piece would change; bench/history/2026-11-29.md#exact32
    prove = _prover(pieces, variables, box, ctx) if symbolic and proofs and for_reading() else None
    exacts, why = _exact_pieces(problems, len(pieces), quads, ctx, "piece", converged, symbolic, prove)
    return _finish(exacts, quads, why, ctx, "pieces", converged, prove)


def _prover(pieces: Sequence[Piece], variables, box, ctx: Context):
    """``prove(i, target, cells)``: piece i's integral enclosed (:mod:`.quadrature.enclosed`: a
    proof, or None), independent of both the closed form and the quadrature; its time is
    quadrature's (``SPENT``).  Delta pieces have none: their integrand over the zero set comes
    from the closed form's own change of variables, so enclosing it would prove nothing
    independent about a disagreement."""
    def prove(i: int, target: float, cells: int):
        pc = pieces[i]
        with _spending("quadrature"):
            try:
                return ctx.deadline.run(lambda: enclosed.enclose_integral(
                    [c.expr for c in pc.conditions], pc.weight, variables, box, ctx.at, target=target, cells=cells),
                    cap=enclosed.seconds(cells))
            except TimeoutError:  # (:func:`~.quadrature.enclosed.seconds`: no proof)
                return None
    return prove


@units_unloaded()
def integrate_delta_pieces(pieces: Sequence[DeltaPiece], variables, box, at, *,
                           timeout: float = 20.0, cell: Sequence[sp.Rel] = (), symbolic: bool = True) -> Integral:
    """Σ ∫_box h·δ(π₀Ψ̂) through the change of variables ``u = Ψ̂(x)`` over every inverse branch:
    ∫ h(Ψ̂_b⁻¹(0,u'))·|det DΨ̂_b⁻¹(0,u')| du' on the guards (LANGUAGE.md §4); ``symbolic`` as
    :func:`integrate_pieces`'s."""
    variables = tuple(variables)
    for i, pc in enumerate(pieces):
        infinite = delta.infinite_on_zero_set(pc.psi)
        if infinite is not None:
            raise UndefinedIntegral(f"delta piece {i}: its Ψ̂⁻¹ is infinite on the zero set ({infinite} at "
                                    f"{pc.psi.inputs[0]} = 0): Ψ̂ is no diffeomorphism there (Def. 3.4), so "
                                    "δ(π₀Ψ̂) is not defined through it")
    ctx, boxd = _setup(variables, box, at, timeout, cell)
    uboxes = []
    for i, pc in enumerate(pieces):
        try:
            uboxes.append(delta.u_box(pc.psi, variables, boxd, ctx))
        except Unsupported as exc:
            raise ValueError(f"delta piece {i}: cannot bound the zero set's coordinates: {exc}") from None
    quads, converged = _quads(
        lambda item, *out: (0.0, 0.0) if item[0] is None else
        quadrature.quad_delta_pieces([item[0]], variables, box, ctx.at, [item[1]], *out),
        list(zip(offbox.reduced(pieces, boxd, ctx.at), uboxes)), ctx)
    _check_defined(quads, "delta piece")
    ctx.deadline = Deadline(timeout)  # the time limit is for the symbolic work

    def problems(i):
        uvars = delta.u_prime(pieces[i].psi, variables)
        probs = delta.delta_to_regular(pieces[i], variables, boxd, ctx, uboxes[i])
        return probs, uvars, dict(zip(uvars, uboxes[i]))

    exacts, why = _exact_pieces(problems, len(pieces), quads, ctx, "delta piece", converged, symbolic)
    return _finish(exacts, quads, why, ctx, "delta pieces", converged)
