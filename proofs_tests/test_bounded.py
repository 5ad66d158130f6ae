"""``langur.lint.bounded``: where it lets the commands skip the integrability analysis, that
analysis (``langur.lint.singular``, with sympy) and the empty-domain check find nothing."""

from pathlib import Path

import pytest

from langur import frontend
from langur.lint import bounded, singular
from langur.lint.emptydomain import empty_domain_findings

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(p for p in (ROOT / "examples").rglob("*.lgr"))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_skipping_the_analysis_loses_nothing(path):
    loaded = frontend.load(str(path))
    if loaded.program is None or any(v is None for v in loaded.params.values()):
        return
    point = loaded.param_values()
    if not bounded.nothing_to_find(loaded.program, point):
        return
    res = singular.value_integrability(loaded.program, point)
    assert res.blowups == [] and res.note is None
    assert empty_domain_findings(loaded.program, point) == []


def test_unbounded_or_empty_is_left_to_the_analysis():
    def prog(text):
        return frontend.load_text(text).program

    assert bounded.nothing_to_find(prog("int ([0, 1]) exp(x) * [x <= 0.5] d(x)"), {})
    assert not bounded.nothing_to_find(prog("int ([0, 1]) 1 / x d(x)"), {})  # blows up at 0
    assert not bounded.nothing_to_find(prog("int ([0, 1]) log(x) d(x)"), {})
    assert not bounded.nothing_to_find(prog("int ([1, 0]) x d(x)"), {})  # X314: empty interval
    assert not bounded.nothing_to_find(prog("param a = 1\nint ([0, a]) x d(x)"), {"a": 1})  # parametric box
