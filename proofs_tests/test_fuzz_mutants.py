"""Mutation check (issue 13, after QuickChick's MutateCheck): each deliberately broken derivative
rule of the Monte Carlo engine (langur.fuzz.mutants) is killed by a bounded seeded campaign, i.e.
the campaign finds a discrepancy against the exact engine, on a program where the unbroken
engine agrees (so the kill is the broken rule's doing, not noise)."""

import pytest

from langur import fuzz
from langur.engines.builtin import MonteCarloEngine
from langur.fuzz import mutants
from langur.fuzz.compare import compare_engine

SEED, SAMPLES = 8, 4000
SHAPE = dict(light=True, max_summands=1, max_factors=2, max_params=1)
#: The bounded campaign: the first 8 programs of seed 8 (small programs: one parameter, one summand
#: of at most two factors, at most two variables; the eighth has the `let` whose chain rule
#: `drop_let_chain` drops).
CAMPAIGN = ((8, 8),)


@pytest.fixture(scope="module")
def kills():
    texts = [t for seed, n in CAMPAIGN for t in fuzz.generated(16, seed, **SHAPE)[:n]]
    return mutants.mutation_check(texts, samples=SAMPLES, seed=SEED)


def test_every_mutant_is_killed_and_the_killer_is_named(kills):
    survivors = [m for m, k in kills.items() if k is None]
    assert not survivors, f"mutants not killed by the campaign: {survivors}"
    for m, k in kills.items():
        print(f"{m}: killed by program {k.index} of the campaign {CAMPAIGN}:\n{k.text}")
        bad = [r for r in k.result.rows if not r.ok]
        assert bad and all(r.quantity in ("value", "derivative") for r in bad)
    assert set(kills) == {"drop_delta", "flip_dpsi", "drop_jacobian", "swap_jump", "one_branch",
                          "drop_let_chain"}


def test_the_unbroken_engine_agrees_where_each_mutant_was_killed(kills):
    mc = MonteCarloEngine(samples=SAMPLES, seed=SEED)
    for k in {k.text: k for k in kills.values()}.values():
        r = compare_engine(k.text, mc)
        assert r.status == "agree", (k.mutant, k.text, [(w.quantity, w.exact, w.mc) for w in r.rows])


def test_a_mutant_is_an_engine_and_leaves_the_engine_unbroken_afterwards():
    text = "param a = 0.37\nint ([-1, 1]) [x^2 <= a] d(x)\n"  # d/da (2√a) = 1/√a, two roots
    broken = compare_engine(text, mutants.one_branch())
    assert broken.status == "discrepancy"
    d = [r for r in broken.rows if r.quantity == "derivative"][0]
    assert d.exact == pytest.approx(0.37 ** -0.5) and d.mc == pytest.approx(d.exact / 2)  # one root of two
    assert compare_engine(text, MonteCarloEngine()).status == "agree"
