"""Rule coverage of a campaign (issue 13, after PLT Redex's covered-cases): the CI profile — a
small seeded campaign in worker processes — applies every rule of Fig. 6, 7, 8 (in both engines),
11 and 12; the generator's programs meet every kind of diffeomorphism completion."""

from collections import Counter

from langur import exact, fuzz
from langur.core import IfDiffeo, subterms
from langur.frontend import load_text
from langur.fuzz import coverage

#: The CI profile: a seeded campaign small enough for the suite.
CI = dict(examples=6, seed=8, samples=2000, timeout=60.0, workers=2, shrink=False)


def test_the_ci_profile_applies_every_rule(tmp_path):
    s = fuzz.run_fuzz(storage=str(tmp_path), **CI)
    assert not s.failed, [(r.status, r.reason) for r in s.results if r.failed]
    rows = [(f, r, n) for f, r, n in s.coverage() if f != "completion"]
    never = [(f, r) for f, r, n in rows if n == 0]
    assert not never, f"rules never applied by the CI profile: {never}"
    # the counts are the units' own: a program counted once per rule application in it
    assert dict(((f, r), n) for f, r, n in s.coverage())[("Fig. 11", "program")] == \
        sum(1 for r in s.results if r.status not in ("load_error", "timeout"))


def test_the_generator_meets_every_completion_kind():
    # 40 programs of seed 0, loaded only (the front end completes the conditions): the kind of
    # every diffeomorphic conditional Fig. 8 would meet in them
    kinds = Counter()
    for text in fuzz.generated(40, 0):
        for t in subterms(load_text(text).program.body):
            if isinstance(t, IfDiffeo):
                kinds[coverage.completion_kind(t.psi)] += 1
    assert set(kinds) == set(coverage.COMPLETIONS), kinds


def test_recording_counts_each_rule_and_unwraps_afterwards():
    text = "param a = 0.37\nint ([0, 1]) let s = 2*a in [x <= s] * x d(x)\n"
    coverage.reset()
    with coverage.recording():
        loaded = load_text(text)

        exact.exact_deriv(loaded.program, {"a": 0.37}, {"a": 1}, check=False)
    c = coverage.counts()
    assert c[("Fig. 11", "program")] == 1 and c[("Fig. 6", "let")] == 1
    assert c[("Fig. 8 exact", "let")] >= 1 and c[("Fig. 8 exact", "diffeomorphic conditional")] >= 1
    assert c[("completion", "completed, one inverse branch")] >= 1
    coverage.reset()
    load_text(text)  # unwrapped: nothing counted
    assert not coverage.counts()
