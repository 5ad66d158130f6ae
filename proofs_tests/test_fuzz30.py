"""`langur fuzz --wide`, fuzz30's additions (langur/strategies/variants.py): negative parameter
defaults, programs without parameters, a def called with other parameter terms at a second site.
Each is drawn; wide programs with negative defaults keep every primitive inside its domain (the Monte
Carlo value is finite); the def's zero sets are registered again at the second site's terms; one
program of each kind has its value and derivative computed by hand, which both engines must give.
Without `--wide` seed 1's thousand programs are those main drew (digest computed on main at
147990f).  `langur fuzz --help` names every wide construct; the mutants reach no private attribute of the
Monte Carlo engine."""

import ast
import hashlib
import math
import re
from fractions import Fraction as F
from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, find, given, settings
from hypothesis import strategies as st
from hypothesis.errors import NoSuchExample
from scipy.integrate import quad
from test_fuzz28 import by_hand_in_both_engines

from langur import operational
from langur import strategies as ls
from langur.cli import main
from langur.fuzz import compare
from langur.fuzz.campaign import generated
from langur.fuzz.generate import hypothesis_home
from langur.strategies import conditions as C
from langur.strategies import terms as T
from langur.strategies import variants as V
from langur.strategies import wide as W
from langur.syntax import surface as S
from langur.syntax.parser import parse_module

ROOT = Path(__file__).resolve().parents[1]
FIND = settings(max_examples=3000, database=None, deadline=None, suppress_health_check=list(HealthCheck))
FAST = settings(max_examples=60, derandomize=True, database=None, deadline=None,
                suppress_health_check=list(HealthCheck))


def _digest(texts) -> str:
    return hashlib.sha256("\x00".join(texts).encode()).hexdigest()


def test_without_wide_seed_1s_thousand_programs_are_main_s(tmp_path):
    # `langur fuzz --seed 1 --examples 1000`'s programs, digest computed on main at 147990f
    with hypothesis_home(str(tmp_path)):
        assert _digest(generated(1000, 1)) == "2b2fb6b3bd5dfb1f2551da1e405d461ecab7b9f146c29780e9cde406a6f6e719"


def _calls(text: str) -> set[str]:
    """The distinct calls of ``g`` in the program (after its ``int``)."""
    return set(re.findall(r"\bg\((?:[^()]|\([^()]*\))*\)", text.split("\nint", 1)[-1]))


VARIANTS = {
    "negative default": lambda g: any(d < 0 for _, d in g.params),
    "no parameters": lambda g: not g.params and "param" not in g.text,
    "def called with other parameter terms": lambda g: len(_calls(g.text)) > 1,
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_each_variant_is_drawn_only_when_wide(variant):
    g = find(ls.programs(wide=True), VARIANTS[variant], settings=FIND)
    g.load()
    again = parse_module(g.text, "main.lgr")
    assert (again.items, again.program) == (g.module.items, g.module.program)
    with pytest.raises(NoSuchExample):
        find(ls.programs(), VARIANTS[variant], settings=settings(FIND, max_examples=300))


def test_a_wide_campaign_draws_each_variant_with_its_defaults(tmp_path):
    # what `langur fuzz --wide --seed 30 --examples 60` runs (a negative default's text was refused before)
    with hypothesis_home(str(tmp_path)):
        texts = generated(60, 30, wide=True)
    found = {"negative default": 0, "no parameters": 0, "def called with other parameter terms": 0}
    for text in texts:
        m = parse_module(text, "main.lgr")
        decls = [d for i in m.items if isinstance(i, S.ParamItem) for d in i.decls]
        found["negative default"] += any(d.default < 0 for d in decls)
        found["no parameters"] += not decls
        found["def called with other parameter terms"] += len(_calls(text)) > 1
    assert all(found.values()), found


@FAST
@given(ls.programs(wide=True))
def test_negative_defaults_keep_every_primitive_in_its_domain(g):
    assume(any(d < 0 for _, d in g.params))
    loaded = g.load()
    params = {k: float(v) for k, v in loaded.param_values({}).items()}
    assert math.isfinite(operational.estimate_value(loaded, params, samples=256, seed=0).value), g.text


@FAST
@given(st.data())
def test_a_second_call_site_registers_the_bodys_zero_sets_at_its_terms(data):
    env = {"a": 0.37, "b": -0.61, "c": 0.83}
    scope = C.Scope(data.draw, ("x", "y"), dict(env), list(env), wide=True)
    p = data.draw(st.sampled_from(list(env)))
    level = T.offset(T.name(p), F(3, 10))
    factor = S.Iverson((T.add(T.name("x"), T.name("y")), level), ("<=",))
    scope.register(T.sub(T.add(T.name("x"), T.name("y")), level))
    scope.made.append((factor, tuple(scope.zero_sets)))
    before = len(scope.zero_sets)
    call = V.call_elsewhere(scope, factor, [p], list(env))
    assert call is not None and call.name == "g" and call.args[:2] == (T.name("x"), T.name("y"))
    new = T.evaluate(call.args[2], env)
    assert new * env[p] > 0 and new != env[p] and abs(new) <= V.LARGEST  # the sign kept, another value
    (z,) = scope.zero_sets[before:]
    ((normal, c),) = z.planes  # the line x + y = new + 0.3
    assert normal == pytest.approx((1.0, 1.0)) and c == pytest.approx(new + 0.3)


def test_a_second_call_site_whose_zero_set_meets_another_is_not_generic():
    # g(x, a) at a = 0.37 has its jump at x = 0.67; a second site g(x, b), b = 0.52, puts one at x = 0.82,
    # where another factor has its jump: the program is then not generic (the site chosen by hand)
    env = {"a": 0.37, "b": 0.52}
    scope = C.Scope(None, ("x",), dict(env), list(env), wide=True)
    factor = S.Iverson((T.name("x"), T.offset(T.name("a"), F(3, 10))), ("<=",))
    scope.register(T.sub(T.name("x"), T.offset(T.name("a"), F(3, 10))))
    scope.made.append((factor, tuple(scope.zero_sets)))
    scope.register(T.sub(T.name("x"), T.num(F(82, 100))))  # another factor's jump at x = 0.82
    box = [(0.0, 1.0)]
    assert T.generic(scope.zero_sets, box, ("x",))
    # the site g(x, b): x = 0.82 (since fuzz31 a site is drawn as one choice of every parameter's term)
    scope.pick = lambda seq: next(m for m in seq if m["a"] == T.name("b"))
    assert V.call_elsewhere(scope, factor, ["a"], list(env)) == T.call("g", T.name("x"), T.name("b"))
    assert not T.generic(scope.zero_sets, box, ("x",))


# ---------------------------------------------------------------------------------------------
# One program of each kind, by hand, both engines
# ---------------------------------------------------------------------------------------------

A = -0.37
X0 = -0.2 / A  # a*x <= -0.2 with a < 0: x >= -0.2/a
U1, U2 = 0.29 + 0.3, 2 * 0.29 + 0.3


def _sqrt_program() -> tuple[float, float]:
    lo = A + 0.3
    value = quad(lambda x: math.sqrt(x * x - A), lo, 1, epsabs=1e-13)[0]
    regular = quad(lambda x: -0.5 / math.sqrt(x * x - A), lo, 1, epsabs=1e-13)[0]
    return value, regular - math.sqrt(lo * lo - A)  # the lower end moves with a: −f(a + 0.3)


SQRT = _sqrt_program()
HAND = {
    # a negative parametric coefficient: the completion divides by a, the direction flips
    "coefficient": (f"param a = {A}\nint ([0, 1]) [a * x <= -0.2] * (x + 1) d(x)\n",
                    1.5 - (X0 * X0 / 2 + X0), {"a": -(X0 + 1) * 0.2 / A ** 2}),
    # sqrt(x*x + P) with P < 0 written sqrt(x*x - a), a level below the box's middle
    "negative in a domain": (f"param a = {A}\nint ([-1, 1]) [x >= a + 0.3] * sqrt(x * x - a) d(x)\n",
                             SQRT[0], {"a": SQRT[1]}),
    # no parameters: only the value (∫₀¹ (1.67 − x)(x + 1.5) dx)
    "no parameters": ("int ([0, 1], [-1, 1]) [x + y <= 0.37 + 0.3] * (x + 1.5) d(x, y)\n",
                      2.505 + 0.085 - 1 / 3, {}),
    # one def, two call sites with other parameter terms: jumps at a + 0.3 and 2a + 0.3
    "def at two terms": ("param a = 0.29\ndef g(x: var, qa: param) = [x <= qa + 0.3] * (x + 1)\n"
                         "int ([0, 1]) g(x, a) + 0.7 * (g(x, 2 * a) * x) d(x)\n",
                         U1 * U1 / 2 + U1 + 0.7 * (U2 ** 3 / 3 + U2 ** 2 / 2),
                         {"a": (U1 + 1) + 0.7 * (U2 + 1) * U2 * 2}),
}


@pytest.mark.parametrize("kind", sorted(HAND))
def test_each_kind_by_hand_in_both_engines(kind):
    text, value, derivs = HAND[kind]
    by_hand_in_both_engines(text, f"{kind}.lgr", value, derivs, 1e-8, 1e-9)


def test_a_program_without_parameters_is_compared_on_its_value_only():
    text, value, _ = HAND["no parameters"]
    r = compare.compare_text(text, samples=20000, seed=0, timeout=60.0)
    assert r.status == "agree" and [row.quantity for row in r.rows] == ["value"]
    assert r.rows[0].exact == pytest.approx(value, abs=1e-9)


# ---------------------------------------------------------------------------------------------
# The help text, the fuzz modules' reaches
# ---------------------------------------------------------------------------------------------

#: What `langur fuzz --help` calls each wide builder.
HELP = {W.loop: "sum/prod loops", W.logic: "&/|/not", W.let_level: "a let inside a factor",
        W.guarded: "partial primitives under a", W.branch_cut: "atan2's cut", W.primitive: "erf/asin/acos/atanh/tan",
        W.param_ifge0: "ifge0 on any", W.dot_condition: "vectors (dot", W.erf_condition: "erf also in conditions",
        W.variable_ifge0: "ifge0 on any", W.nested_loop: "(nested too)", W.strict_window: "strict chains with pi",
        W.cross_condition: "cross, .z", W.powers: "negative exponents", V.signed: "negative parameter defaults",
        V.bare: "programs without parameters", V.call_elsewhere: "a def called with other parameter terms"}


def test_the_help_names_every_wide_construct(capsys):
    assert set(W.FACTORS) - {W.more} | set(W.MORE) | {V.signed, V.bare, V.call_elsewhere} == set(HELP)
    with pytest.raises(SystemExit):
        main(["fuzz", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    wide = text.split("--wide", 2)[2].split("--profile")[0]
    assert not [w for w in HELP.values() if w not in wide], wide


def test_the_mutants_reach_no_private_attribute():
    tree = ast.parse((ROOT / "langur" / "fuzz" / "mutants.py").read_text())
    reaches = [f"{ast.unparse(n)} (line {n.lineno})" for n in ast.walk(tree)
               if isinstance(n, ast.Attribute) and n.attr.startswith("_") and not n.attr.startswith("__")
               and not (isinstance(n.value, ast.Name) and n.value.id == "self")]
    strings = [f"{n.value!r} (line {n.lineno})" for n in ast.walk(tree)  # setattr(owner, "_name", …)
               if isinstance(n, ast.Constant) and isinstance(n.value, str) and re.fullmatch(r"_[a-z]\w*", n.value)]
    assert not reaches and not strings, reaches + strings
