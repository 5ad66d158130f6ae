"""The linter's verdicts do not depend on a condition's scale (paper Def. 7.2, §7.3.1): a
condition multiplied by a positive constant is the same condition, and a variable scaled by 10^k
with its box (∫ f(x/s) dx over [0, s]) has the same zero sets relative to the box.

``[x >= a]·[x >= b]`` (examples/degenerate/equal_params.lgr) has coincident zero sets when a = b:
X304.  Its orientation test (are both conditions ≥ 0 on the same side?) read the sign of ∇f·∇g
against an absolute 10⁻⁹: with ``(x − b)/10¹³`` or ``x/10⁶`` in place of x the product is 10⁻¹³ or
10⁻¹², taken for 0, and the warning was lost.  Now it is read against the size of its terms
(:func:`langur.sympy_bridge.magnitude`).
"""

import pytest

from langur import transversality as tv
from langur.frontend import load_text

BASE = "param a = 0.3, b = 0.6\nint ([0, 1]) [x >= a] * [x >= b] d(x)\n"
SCALED = [
    "param a = 0.3, b = 0.6\nint ([0, 1]) [x >= a] * [(1 / 10000000000000) * (x - b) >= 0] d(x)\n",
    "param a = 0.3, b = 0.6\nint ([0, 1]) [x >= a] * [10000000000000 * (x - b) >= 0] d(x)\n",
    "param a = 0.3, b = 0.6\nint ([0, 1000000]) [x / 1000000 >= a] * [x / 1000000 >= b] d(x)\n",
    "param a = 0.3, b = 0.6\nint ([0, 10000000000000]) [x / 10000000000000 >= a] * [x / 10000000000000 >= b] d(x)\n",
    "param a = 0.3, b = 0.6\nint ([0, 1 / 1000000]) [x * 1000000 >= a] * [x * 1000000 >= b] d(x)\n",
]


def _codes(text: str) -> list[str]:
    loaded = load_text(text, "t.lgr")
    return sorted(f.code for f in tv.check_loaded(loaded, at=loaded.param_values({}), sources={"t.lgr": text}))


def test_the_unscaled_program_has_its_warning():
    assert _codes(BASE) == ["X304"]


@pytest.mark.parametrize("text", SCALED, ids=["cond/1e13", "cond*1e13", "x/1e6", "x/1e13", "x*1e6"])
def test_a_scaled_program_has_the_same_warning(text):
    assert _codes(text) == _codes(BASE)
