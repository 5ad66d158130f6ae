"""Mutation check of the differential campaign (after QuickChick's ``MutateCheck``; issue 13).

Each *mutant* is the Monte Carlo engine (§9) with one derivative rule of Fig. 8 deliberately
broken; a campaign that compares it with the (unbroken) exact engine must find a discrepancy —
the mutant is *killed* — or the campaign is blind to that rule.  A mutant is an engine of the
protocol of :mod:`langur.engines` (``--engine langur.fuzz.mutants:drop_delta`` runs a campaign
against it), so exactly one engine is broken at a time and nothing in the engines knows about
mutants: while a mutant answers, :func:`broken` swaps one case of the operational compiler
(:func:`langur.operational.compile.compile_subterm`) or one method of its site sampler
(:class:`langur.operational.sample.SiteSampler`) for the broken rule, and the compiled-program
cache is emptied before and after (no broken unit outlives the answer).

The mutants (:data:`MUTANTS`):

* ``drop_delta`` — the diffeomorphic conditional without its delta term δ(π₀Ψ̂)·D_γπ₀Ψ̂·γ'·(⟦s⟧−⟦r⟧);
* ``flip_dpsi`` — the sign of D_γ π₀Ψ̂ flipped;
* ``drop_jacobian`` — the zero set's points weighted 1 instead of |det DΨ̂_b⁻¹(0, u')| (§8);
* ``swap_jump`` — ⟦r⟧ − ⟦s⟧ for the jump instead of ⟦s⟧ − ⟦r⟧;
* ``one_branch`` — only the first inverse branch of Ψ̂ (a two-root zero set loses a root);
* ``drop_let_chain`` — ⦇let z = t in s⦈ binds γ'[z ↦ 0] instead of ⦇t⦈ (the chain rule dropped).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np

from .. import operational
from ..core import IfDiffeo, Let
from ..engines.builtin import MonteCarloEngine
from ..operational import compile as comp
from ..operational import dual, point, sample
from .compare import ProgramResult, compare_engine

_COMPILE = comp.compile_subterm  # the unbroken compiler, each mutant's fallback for every other case


def _ifdiffeo(jump_sign: float):
    """Fig. 8's diffeomorphic conditional with the jump ``jump_sign·(⟦s⟧ − ⟦r⟧)`` (0: no delta)."""

    def case(t, ctx):
        if not isinstance(t, IfDiffeo):
            return _COMPILE(t, ctx)
        slot = len(ctx.slots)
        ctx.slots.append(("site", None, ()))
        fc = comp.compile_subterm(t.psi.forward[0], comp.Context([], ctx.local, ctx.sharing))
        fs, fr = comp.compile_subterm(t.then, ctx), comp.compile_subterm(t.orelse, ctx)

        def ifdiffeo(pt, lk):
            c, _ = fc(pt.values(), lk)
            m = c >= 0
            s, ds = fs(pt, lk)
            r, dr = fr(pt, lk)
            d = dual.select(m, ds, dr)
            if pt.mode == point.DELTA and jump_sign:
                gid = lk.base + (slot if lk.offsets is None else lk.offsets[slot])
                if gid in pt.sites:
                    jump = np.where(pt.site == gid, jump_sign * (s - r), 0.0)
                    d = jump if d is None else d + jump
            return np.where(m, s, r), d
        return ifdiffeo
    return case


def _let_without_chain(t, ctx):
    if not isinstance(t, Let):
        return _COMPILE(t, ctx)
    fb, fbody = comp.compile_subterm(t.bound, ctx), comp.compile_subterm(t.body, ctx.bind(t.name))

    def let(pt, lk):
        v, _ = fb(pt, lk)
        return fbody(pt.bind(t.name, v, None), lk)  # broken: ⦇t⦈ dropped
    return let


_DPSI = sample.SiteSampler.dpsi
_MAP = sample.SiteSampler.branch_points
_BRANCHES = sample.SiteSampler.branches


def _flipped_dpsi(self, x, params, dparams):
    return -_DPSI(self, x, params, dparams)


def _unit_weights(self, inputs, n, params, factor):
    return [(x, np.ones_like(np.asarray(w, dtype=float)), ok) for x, w, ok in _MAP(self, inputs, n, params, factor)]


#: name -> (what is broken, (object, attribute, broken replacement))
MUTANTS: dict[str, tuple[str, tuple]] = {
    "drop_delta": ("the delta term of the diffeomorphic conditional dropped", (comp, "compile_subterm", _ifdiffeo(0.0))),
    "flip_dpsi": ("the sign of D_γ π₀Ψ̂ flipped", (sample.SiteSampler, "dpsi", _flipped_dpsi)),
    "drop_jacobian": ("the Jacobian |det DΨ̂⁻¹| of the zero set's points dropped",
                      (sample.SiteSampler, "branch_points", _unit_weights)),
    "swap_jump": ("s and r swapped in the jump ⟦s⟧ − ⟦r⟧", (comp, "compile_subterm", _ifdiffeo(-1.0))),
    "one_branch": ("only the first inverse branch of Ψ̂ kept",
                   (sample.SiteSampler, "branches", property(lambda self: _BRANCHES.fget(self)[:1]))),
    "drop_let_chain": ("the chain rule of let dropped (γ'[z ↦ 0])", (comp, "compile_subterm", _let_without_chain)),
}


@contextlib.contextmanager
def broken(name: str):
    """The Monte Carlo engine with mutant ``name``'s rule broken while the block runs."""
    _, (owner, attr, replacement) = MUTANTS[name]
    original = vars(owner)[attr]  # (as defined: a property itself, not its value)
    operational.clear_cache()
    setattr(owner, attr, replacement)
    try:
        yield
    finally:
        setattr(owner, attr, original)
        operational.clear_cache()


@dataclass
class MutantEngine(MonteCarloEngine):
    """The Monte Carlo engine with one broken rule (an engine of the protocol, :mod:`langur.engines`)."""

    mutant: str = "drop_delta"

    def __post_init__(self):
        self.name = f"mc-{self.mutant}"

    def value(self, program, params):
        with broken(self.mutant):
            return super().value(program, params)

    def derivative(self, program, params, direction):
        with broken(self.mutant):
            return super().derivative(program, params, direction)


def _factory(name: str):
    return lambda: MutantEngine(mutant=name)


drop_delta, flip_dpsi, drop_jacobian, swap_jump, one_branch, drop_let_chain = (
    _factory(n) for n in MUTANTS)


@dataclass(frozen=True)
class Kill:
    """A mutant killed: the campaign's ``index``-th program ``text`` and the failing comparison."""

    mutant: str
    index: int
    text: str
    result: ProgramResult


def mutation_check(texts, *, samples: int = 4000, seed: int = 0, timeout: float = 20.0,
                   names=None) -> dict[str, Kill | None]:
    """Each mutant (``names``: all of :data:`MUTANTS`) compared with the exact engine on ``texts``
    in order, until the first program that kills it: a discrepancy of the mutant where the
    unbroken Monte Carlo engine (same samples, same seed) agrees — a program where the unbroken
    engine does not agree is no evidence and is skipped.  None: the mutant survived.  The exact
    engine's answers are computed once per program (cached across mutants)."""
    unbroken = MonteCarloEngine(samples=samples, seed=seed)
    baseline: dict[str, bool] = {}
    out: dict[str, Kill | None] = {}
    for name in names or MUTANTS:
        engine = MutantEngine(samples=samples, seed=seed, mutant=name)
        out[name] = None
        for i, text in enumerate(texts):
            if text not in baseline:
                baseline[text] = compare_engine(text, unbroken, timeout=timeout).status == "agree"
            if not baseline[text]:
                continue
            r = compare_engine(text, engine, timeout=timeout)
            if r.status == "discrepancy":
                out[name] = Kill(name, i, text, r)
                break
    return out
