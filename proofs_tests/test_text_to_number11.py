"""Loading cheaper at n = 1 and n = 10 (issue 15, branch front11): the parser's lexer and driver and
the table of small integer Fractions, against independent references.

* ``syntax/lalr.py``'s lexer matches the one-character literal terminals (``(``, ``+``, …) as one
  character class and names a token by its text (parse24: literals and keywords by a dict instead of
  lark's ``UnlessCallback``, ``NAME`` and ``NUMBER`` by their first character): every token that reaches a callback is lark's own lexer's token — type, text,
  offsets, lines and columns, ends included — on every ``.lgr`` file of the repository and on texts
  made to stress the lexer (CRLF, tabs, form feeds, comments, Unicode comparisons, ``..`` beside
  numbers, names that begin or extend a keyword, the soft keyword ``d``).
* The driver treats ``name -> NAME`` as a unit rule (its callback would return the token itself):
  the callback is no longer called for a name, and the trees with their spans are lark's (since
  parse26 every such rule is folded into the generated table: ``tables.fold_units``).
* The end of the input is reduced outside the token loop: a text that ends early is still handed
  to lark (:data:`lalr.FAILED`), whose diagnostic is the one reported.
* ``core.INT_FRACTIONS``: ``Fraction(i)`` for 0 … 127, read by the parser's integer literals, a
  loop's index constants (``core.index_const``) and the desugarer; equal to the constructor's
  values, and the loaded programs equal (attributes included) to those built with the constructor.
"""

from __future__ import annotations

import dataclasses
import random
import re
from fractions import Fraction

import pytest
from paths import REPO

from langur import core
from langur.diagnostics import LangurError, Span
from langur.syntax import builder, chains, lalr, larkload, parser, tables


def _is_token(x) -> bool:
    """A token: the driver's (a tuple of ``lalr.TOKEN``'s fields, parse25) or lark's own."""
    return isinstance(x, larkload.Token) or (type(x) is tuple and len(x) == len(lalr.TOKEN) and type(x[0]) is str)


FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)

_SLOTS = ("type", "value", "start_pos", "end_pos", "line", "column", "end_line", "end_column")


def _token(t) -> tuple:
    if type(t) is tuple:  # the driver's
        fields = dict(zip(lalr.TOKEN, t))
        return (fields["value"],) + tuple(fields[k] for k in _SLOTS)
    return (t.value,) + tuple(getattr(t, k) for k in _SLOTS)


def _recorded(text: str, start: str, lark: bool) -> tuple:
    """The tokens every callback receives, in order, and the result (as nested tuples with spans)
    or the diagnostics: by the driver (``lark`` false: its data as shipped, read without lark) or by
    lark's own parser, both with each rule's callback (its whole wrapper chain) wrapped to record
    its arguments (every token shifted reaches one), but for the rules whose callback gives back
    its one child, which the driver's table no longer reduces by (``tables.fold_units``, parse26)."""
    seen: list[tuple] = []
    with parser._LOCK:
        lk = parser._parser()
        callbacks = lk.parser.parser.parser.callbacks
        saved = dict(callbacks)
        try:
            data = lalr.load()
            assert data is not None
            rules = data["rules"]  # (the driver's table calls no rule giving back its one child: parse26)
            folded = {(rules[i][0], tuple(rules[i][1])) for i in tables.identity_rules(rules)}
            for rule, f in saved.items():
                if (rule.origin.name, tuple(s.name for s in rule.expansion)) in folded:
                    continue
                def wrapped(c, f=f):
                    seen.extend(_token(x) for x in c if _is_token(x))
                    return f(c)
                callbacks[rule] = wrapped
            parser._BUILDER.path = "t.lgr"
            try:
                if lark:
                    out = ("ok", _tree(lk.parse(text, start=start)))
                else:
                    ours = []
                    for f in lalr.callbacks(data, parser._BUILDER):
                        def wrapped(c, f=f):
                            seen.extend(_token(x) for x in c if _is_token(x))
                            return f(c)
                        ours.append(wrapped)
                    driver = lalr.driver(data, ours)
                    assert driver is not None
                    got = driver(text, start)
                    out = ("failed",) if got is lalr.FAILED else ("ok", _tree(got))
            except LangurError as e:
                out = ("error", [d.format() for d in e.diagnostics])
            except Exception as e:  # noqa: BLE001 - lark's syntax errors: compared by kind only
                out = ("failed",) if type(e).__name__.startswith("Unexpected") else ("raised", repr(e))
        finally:
            callbacks.clear()
            callbacks.update(saved)
    return seen, out


def _tree(x):
    if isinstance(x, Span):
        return ("Span", x.path, x.line, x.col, x.end_line, x.end_col)
    if isinstance(x, chains.Reduced):
        return ("R", _tree(x.node), x.line, x.col, x.end_line, x.end_col, x.depth)
    if _is_token(x):
        return ("Token",) + _token(x)
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__name__,) + tuple((f.name, _tree(getattr(x, f.name))) for f in dataclasses.fields(x))
    if isinstance(x, (list, tuple)):
        return (type(x).__name__,) + tuple(_tree(v) for v in x)
    if hasattr(x, "data") and hasattr(x, "children"):  # a lark Tree of a rule without a callback
        return ("Tree", str(x.data), _tree(list(x.children)))
    return (type(x).__name__, x)


_STRESS = [
    "param a = 1\r\nint ([-1, 1]) [x + a - 1 >= 0] * x d(x)\r\n",
    "param a = 1\n\n\t# sum in prod let\n\fint ([0, 1])\t[x ≤ a] * [x ≥ 0.5] * [x<=1] * [x>=0] d(x)  # end",
    "int ([0, 1]) (sum i in 1..3: x + .5 + 1. + 2.5E+2 + 1e-3 + i) d(x)",
    "int ([0, 1]) (sum i in 1 .. 3 : x ^ -i) + (prod j in 0..1: x+j) d(x)",
    "param ins, i, d2, sums, prods, lets, iff, then_, elsewhere, notx, var1, as_, d_\n"
    "int ([0, 1]) ins + i + d2 + sums + prods + lets + iff + then_ + elsewhere + notx + var1 + as_ + d_ * x d(x)",
    "int d * 2 d(d)",
    "def f(t: var, c: param) = let z = t * c in z - 1\nparam a = 2\n"
    "int ([0, 2]) f(x, a) * [x >= a/3 & x < 1] * [x < 0.5 | x > 1.5] + cross((x, 1, 0), (0, 1, x)).z d(x)",
    "diffeo polar(r, t; c) = (r * c, t) inverse (u, v) = (u / c, v)\nparam c = 2\n"
    "int ([1, 2], [0, 1]) ifge0 polar(r, t; c) then 1 else 0 d(r, t)",
    "from m import f as g, h\nparam a = -3\nint ([0, 1]) if not x > a then g(x) else h(x) d(x)",
    "int ([0, 1]) if x < 1 then (ifge0 x - 0.5 then 1 else 0) else 2 d(x)",
    "",
    "# a comment only, no line break",
    "\n\n\r\n  \t",
    # syntax errors: handed to lark, its tokens up to the error the same
    "int ([0, 1]) x + (1 d(x)",
    "int ([0, 1]) x ..  d(x)",
    "param a = 1\nint ([0, 1]) let in = 2 in x d(x)",
    "param a = 1\nint ([0, 1]) x d(x) junk",
    "int ([0, 1]) x + @ d(x)",
    "int",
    "int ([0, 1]) x d(x",
]


@pytest.mark.parametrize("text", _STRESS)
def test_tokens_and_trees_are_larks_on_stress_texts(text):
    ours, theirs = _recorded(text, "start", False), _recorded(text, "start", True)
    if ours[1] == ("failed",):
        assert theirs[1] == ("failed",)  # lark reports it: the driver's tokens before are a prefix of lark's
        assert theirs[0][: len(ours[0])] == ours[0]
    else:
        assert ours == theirs


def test_tokens_and_trees_are_larks_on_every_file():
    assert len(FILES) > 30
    parsed = 0
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        ours, theirs = _recorded(text, "start", False), _recorded(text, "start", True)
        if ours[1] == ("failed",):
            assert theirs[1] == ("failed",), path
            continue
        assert ours == theirs, path
        parsed += 1
        assert ours[0], path  # (not vacuous: tokens were seen)
    assert parsed >= len(FILES) - 5


def test_tokens_are_larks_on_random_spacings():
    """The example files' tokens joined by random runs of white space and comments (lines and
    columns move) and with random one-character literals swapped in."""
    rng = random.Random(11)
    runs = [" ", "", "\t", "\n", "\r\n", "\f", " # c in sum\n", "#\n\n", "\n\t\t"]
    pieces = re.compile(r"\s+|#[^\n]*")
    texts = [p.read_text(encoding="utf-8") for p in FILES]
    checked = 0
    for _ in range(120):
        words = [w for w in pieces.split(rng.choice(texts)) if w]
        if rng.random() < 0.3 and words:
            words[rng.randrange(len(words))] = rng.choice(list("()[],;:=+-*/^&|<>.") + ["..", "<=", "≥"])
        text = "".join(w + rng.choice(runs) for w in words)
        ours, theirs = _recorded(text, "start", False), _recorded(text, "start", True)
        if ours[1] == ("failed",):
            assert theirs[1] == ("failed",)
            assert theirs[0][: len(ours[0])] == ours[0]
        else:
            assert ours == theirs, text
            checked += 1
    assert checked >= 30


def test_one_character_literals_are_one_class_read_as_lark_reads_them():
    """The driver's pattern has the character class, and its table of texts gives each one-character
    literal the terminal lark's own lexer gives it (alone, and before a digit, a dot and a name)."""
    with parser._LOCK:
        lk = parser._parser()
    data = lalr.load()
    assert data is not None
    pattern, literals = lalr.glued(data["scanner"]), data["scanner"]["literals"]
    assert isinstance(pattern, re.Pattern)
    singles = {text: name for text, name in literals.items() if len(text) == 1 and not text.isalnum()}
    klass = re.search(r"\|\[((?:\\.|[^]\\])+)\]\)", pattern.pattern)  # (the alternatives' one class)
    assert klass is not None and set(re.findall(r"\\?(.)", klass.group(1))) == set(singles) - {"≤", "≥"}
    assert len(singles) >= 15 and set(singles) >= set("()[],;:=+-*/^&|<>.")
    for ch, name in singles.items():
        for after in ("", "1", ".", "x", " ", "="):
            first = next(iter(lk.lex(ch + after)))
            if first.type in ("DOTDOT", "NUMBER", "GE", "LE") and len(first) > 1:  # a longer terminal first
                assert (ch + after).startswith(str(first))
                continue
            assert (first.type, str(first)) == (name, ch)


def test_name_is_a_unit_rule_for_names():
    """The driver calls ``name``'s callback only for ``d`` (made a NAME), never for a NAME: lark calls
    it for both (so the count differs, and the trees do not)."""
    calls = []
    original = builder.Builder.name

    def counted(self, c):
        calls.append(c[0][0])  # (a token's type: lalr.TOKEN)
        return original(self, c)

    text = "param a = 1\nint ([0, 1]) d * a + x * [x >= a - 1] d(x, d)"
    builder.Builder.name = counted
    try:
        with parser._LOCK:
            parser._PARSER = parser._DRIVER = None  # (the driver rebuilt with the counting callback)
            parser._parser()
        fast = _tree(parser.parse_module(text))
        fast_calls = list(calls)
        calls.clear()
        parser.FAST = False
        slow = _tree(parser.parse_module(text))
    finally:
        parser.FAST = True
        builder.Builder.name = original
        with parser._LOCK:
            parser._PARSER = parser._DRIVER = None
            parser._parser()
    assert fast == slow
    assert set(fast_calls) == {"D"} and len(fast_calls) == 2  # the two d's used as names
    assert calls.count("NAME") >= 6 and calls.count("D") == 2


def test_int_fractions_are_the_constructors():
    assert len(core.INT_FRACTIONS) == 128
    for i, f in enumerate(core.INT_FRACTIONS):
        assert type(f) is Fraction and f == Fraction(i) and (f.numerator, f.denominator) == (i, 1)


def test_integer_literals_read_off_the_table_with_the_same_values():
    for i in [0, 1, 2, 9, 10, 99, 127, 128, 255, 1000, 10**20]:
        text = f"int ([0, 1]) x * {i} + 0{i} d(x)"
        m = parser.parse_module(text)
        a, b = m.program.body.left.right.value, m.program.body.right.value
        assert a == b == Fraction(int(str(i))) and type(a) is Fraction
        if i < 128:  # (new: the table's objects, not new Fractions)
            assert a is core.INT_FRACTIONS[i] and b is core.INT_FRACTIONS[i]


def test_index_constants_equal_the_constructors_attributes_included():
    for v in [-5, -1, 0, 1, 10, 58, 109, 127, 128, 1000, 2**70]:
        ours, ref = core.index_const(v), core.Const(Fraction(v))
        assert ours == ref and core.kept_attributes(ours) == core.kept_attributes(ref), v
        assert type(ours.value) is Fraction and ours.value == v


def _fresh_reference(n: int, taken: set[str]) -> tuple[str, ...]:
    """``affine.fresh_inputs`` as written before the table (the names built each time)."""
    for prefix in ("u", "u_", "w", "w_", "v_", "_u"):
        names = tuple(f"{prefix}{i}" for i in range(n))
        if not taken.intersection(names):
            return names
    k = 0
    while any(f"_u{k}_{i}" in taken for i in range(n)):
        k += 1
    return tuple(f"_u{k}_{i}" for i in range(n))


def test_fresh_inputs_are_the_names_built_each_time():
    from langur.syntax import affine

    rng = random.Random(5)
    pool = [f"{p}{i}" for p in ("u", "u_", "w", "w_", "v_", "_u", "_u0_", "_u1_") for i in range(12)] + ["x", "a"]
    for _ in range(400):
        n = rng.randrange(0, 12)
        taken = set(rng.sample(pool, rng.randrange(0, 40)))
        assert affine.fresh_inputs(n, taken) == _fresh_reference(n, taken), (n, sorted(taken))


def test_single_variable_completions_are_sympys_order_and_the_load_is_unchanged():
    """A one-term solution skips the sort (``affine._atoms``): the completed Ψ̂ of ``±x + c`` and of
    conditions with several terms equal the ones the sorted path gives (the sort run here on the
    same terms), and a domain's completions load as the constructor builds them."""
    from langur.core import Const, Var, sub
    from langur.syntax import affine

    for terms in [(("u0", "v", Fraction(1)),), (("u0", "v", Fraction(-1)),), (("u0", "v", Fraction(1, 2)),),
                  (("u0", "v", Fraction(1)), ("a", "p", Fraction(-1))), (("u0", "v", Fraction(0)),)]:
        affine._atoms.cache_clear()
        ours = affine._atoms(terms)
        ref = []
        for name, kind, c in sorted((t for t in terms if t[2]), key=affine._sort_key):
            atom = Var(name) if kind == "v" else core.Param(name)
            ref.append(atom if c == 1 else core.Mul(Const(c), atom))
        assert ours == tuple(ref)
    for lo, hi in [(-1, 1), (0, Fraction(1, 3)), (Fraction(-5, 2), 7)]:
        for cond in (sub(Var("x"), Const(Fraction(lo))), sub(Const(Fraction(hi)), Var("x"))):
            affine._solve.cache_clear()
            affine._atoms.cache_clear()
            psi = affine.complete(cond, ("x",))
            (branch,) = psi.branches
            # Ψ̂⁻¹(u0) solves cond = u0 for x: cond(Ψ̂⁻¹(u0)) = u0 at a few rational points
            for u in (Fraction(0), Fraction(3, 7), Fraction(-2)):
                x = _value(branch.components[0], {"u0": u})
                assert _value(cond, {"x": x}) == u
            assert psi.inputs == ("u0",) and psi.variables == ("x",)


def _value(t, env):
    """The exact value of a small affine core term (an independent evaluator)."""
    from langur.core import Add, Const, Mul, Pow, Var

    if isinstance(t, Const):
        return t.value
    if isinstance(t, Var):
        return env[t.name]
    if isinstance(t, Add):
        return _value(t.left, env) + _value(t.right, env)
    if isinstance(t, Mul):
        return _value(t.left, env) * _value(t.right, env)
    if isinstance(t, Pow):
        return _value(t.base, env) ** t.exponent
    raise TypeError(type(t).__name__)


def test_consts_of_the_table_have_the_constructors_attributes():
    """``Const`` of an ``INT_FRACTIONS`` entry skips the size tests (new): its attributes are those of
    a ``Const`` of a Fraction made apart (not from the table), for every entry."""
    for i, f in enumerate(core.INT_FRACTIONS):
        apart = Fraction(i * 3, 3)  # (a distinct object of the same value)
        assert apart is not f
        ours, ref = core.Const(f), core.Const(apart)
        assert core.kept_attributes(ours) == core.kept_attributes(ref) and ours.small is f
