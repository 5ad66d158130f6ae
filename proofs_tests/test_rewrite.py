"""The transverse rewrite of paper §7.3.2 (``langur.lint.rewrite``), ``check --fix`` and ``deriv``
on programs that are not transverse (issue 9, part B).

For each non-transverse program: the rewrite has the same value ⟦p⟧ as the original (exact
engine, at several parameter points), is transverse (``check`` has no X301 for it), and its
derivative denotation matches central finite differences of the *original* value, which the
original's own ⦇p⦈ does not.
"""

import json
import math
from dataclasses import dataclass

import pytest
from paths import DEGENERATE

from langur import frontend
from langur.cli import main
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.lint.fix import FixError, check_writable, fix
from langur.lint.rewrite import transverse
from langur.symbolic.quadrature import UndefinedIntegral
from langur.transversality import check_program

CASES = [
    # (name, program, parameter, points); comments: the value by hand
    ("exp_of_jump", "param a = 0.5\nint ([0, 1]) exp(-2 * [x >= a]) d(x)\n", "a", [0.3, 0.5, 0.7]),  # a + (1 − a)e⁻²
    ("square_of_sum", "param a = 0.5\nint ([0, 1]) (x + [x >= a])^2 d(x)\n", "a", [0.25, 0.5, 0.75]),
    ("sqrt_of_product", "param a = 0.5\nint ([0, 1]) sqrt(x * [x >= a]) d(x)\n", "a", [0.3, 0.5, 0.8]),
    ("coincident", (DEGENERATE / "coincident.lgr").read_text(), "a", [0.2, 0.5, 0.9]),  # 1 − a
    ("nested", (DEGENERATE / "nested.lgr").read_text(), "a", [0.2, 0.5, 0.9]),  # 1 − a
    ("cube", "param a = 0.5\nint ([0, 1]) x * [x >= a]^3 d(x)\n", "a", [0.3, 0.6]),  # (1 − a²)/2
    # Teg issue 25: ½([x < a] − [x < t])² = ½·|t − a|, both jumps squared
    ("teg25", "param a = 0.3, t = 0.6\nint ([0, 1]) 0.5 * ([x < a] - [x < t])^2 d(x)\n", "t", [0.6, 0.8]),
    # the same zero set written twice, scaled: [x + y ≥ c]·[2x + 2y − 2c ≥ 0]
    ("scaled_2d", "param c = 1\nint ([0, 1], [0, 1]) [x + y >= c] * [2*x + 2*y - 2*c >= 0] d(x, y)\n", "c",
     [0.5, 1.5]),  # (V = 1 − c²/2, then (2 − c)²/2: V'' jumps at c = 1)
    ("sin_of_2d_jump", "param a = 0.25\nint ([0, 1], [0, 1]) sin([y < x + a]) * (1 + x) d(x, y)\n", "a",
     [0.1, 0.25]),
]


def _load(text):
    return frontend.load_text(text, "case.lgr")


@pytest.mark.parametrize("name, text, param, points", CASES, ids=[c[0] for c in CASES])
def test_rewrite_keeps_the_value_and_is_transverse(name, text, param, points):
    loaded = _load(text)
    rw = transverse(loaded.program)
    assert rw.changed and not rw.left
    before = [f.code for f in check_program(loaded.program, loaded.params)]
    after = check_program(rw.program, loaded.params)
    assert "X301" in before and not [f for f in after if f.code == "X301" or f.severity == "error"], after
    defaults = loaded.param_values()
    for v in points:
        at = {**defaults, param: v}
        old, new = denote_program(loaded.program, at), denote_program(rw.program, at)
        assert abs(old.value - new.value) <= 1e-9 + old.error + new.error, (v, old.value, new.value)


@pytest.mark.parametrize("name, text, param, points", CASES, ids=[c[0] for c in CASES])
def test_rewrite_differentiates_like_finite_differences(name, text, param, points):
    loaded = _load(text)
    rw = transverse(loaded.program)
    defaults = loaded.param_values()
    h = 1e-4
    wrong = 0
    for v in points:
        at = {**defaults, param: v}
        plus = denote_program(loaded.program, {**at, param: v + h})
        minus = denote_program(loaded.program, {**at, param: v - h})
        fd = (plus.value - minus.value) / (2 * h)  # the value is smooth in the parameter here: O(h²)
        slack = 1e-6 + (plus.error + minus.error) / (2 * h)
        d = ddenote_program(rw.program, at, {param: 1})
        assert abs(d.value - fd) <= slack + d.error, (v, d.value, fd)
        try:
            orig = ddenote_program(loaded.program, at, {param: 1})
        except UndefinedIntegral:
            wrong += 1  # ⦇p⦈ as written does not exist (test_sqrt_of_product_as_written_is_undefined)
            continue
        wrong += abs(orig.value - fd) > 1e-3
    assert wrong  # the program as written has a ⦇p⦈ that is not its derivative


def test_sqrt_of_product_as_written_is_undefined():
    # ⦇sqrt(x·[x ≥ a])⦈ = (x·⦇[x ≥ a]⦈)/(2·sqrt(x·[x ≥ a])): the delta δ(x − a) sits where the square
    # root's argument is 0 on one side, so its weight x/(2·sqrt(0)) is infinite at x = a — no integral
    # (the engine says so since integ30 checks ⦇p⦈'s delta terms); the rewrite's ⦇p⦈ is √a·(−1)
    loaded = _load(CASES[2][1])
    with pytest.raises(UndefinedIntegral, match="delta term"):
        ddenote_program(loaded.program, {"a": 0.5}, {"a": 1})
    d = ddenote_program(transverse(loaded.program).program, {"a": 0.5}, {"a": 1})
    assert abs(d.value + math.sqrt(0.5)) < 1e-9


def test_exp_of_jump_by_hand():
    # ⟦p⟧ = a + (1 − a)·e⁻², so D⟦p⟧ = 1 − e⁻² = 0.8647; ⦇p⦈ as written gives 2e⁻² = 0.2707
    loaded = _load(CASES[0][1])
    d = ddenote_program(transverse(loaded.program).program, {"a": 0.5}, {"a": 1})
    assert abs(d.value - (1 - math.exp(-2))) < 1e-12


# ----------------------------------------------------------------------------------------------
# check --fix / --diff and deriv (the command line, in process)


@dataclass
class Ran:
    returncode: int
    stdout: str
    stderr: str


@pytest.fixture
def langur(capsys):
    def run(*argv, cwd=None):
        status = main([str(a) for a in argv])
        out = capsys.readouterr()
        return Ran(status, out.out, out.err)

    return run


def test_check_diff_fix_and_in_place(langur, tmp_path):
    src = "# a comment\nparam a = 0.5\nint ([0, 1]) exp(-2 * [x >= a]) d(x)  # the program\n"
    f = tmp_path / "p.lgr"
    f.write_text(src)
    r = langur("check", f, "--diff", cwd=tmp_path)
    assert r.returncode == 1 and "-int ([0, 1]) exp(-2 * [x >= a]) d(x)" in r.stdout
    assert "+int ([0, 1]) (ifge0 x - a then exp(-2) else 1) d(x)  # the program" in r.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.lgr"]  # --diff writes nothing
    r = langur("check", f, "--fix", cwd=tmp_path)
    assert r.returncode == 0, r.stderr  # what remains in the rewrite: nothing
    fixed = tmp_path / "p.fixed.lgr"
    assert f.read_text() == src  # the user's file is untouched
    assert fixed.read_text().startswith("# a comment\nparam a = 0.5\n")  # comments and params kept
    r = langur("check", f, "--fix", cwd=tmp_path)
    assert r.returncode == 2 and "exists" in r.stderr  # never over an existing file
    r = langur("check", f, "--fix", "--in-place", cwd=tmp_path)
    assert r.returncode == 0 and (tmp_path / "p.lgr.bak").read_text() == src
    assert f.read_text() == fixed.read_text()
    r = langur("check", f, "--in-place", cwd=tmp_path)
    assert r.returncode == 2


def test_in_place_refuses_a_file_changed_since_it_was_read(tmp_path):
    f = tmp_path / "p.lgr"
    text = "param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n"
    f.write_text(text)
    fx = fix(text, str(f), frontend.load_text(text, str(f)))
    f.write_text(text + "# edited meanwhile\n")
    with pytest.raises(FixError, match="changed since it was read"):
        check_writable(fx, in_place=True)


def test_fix_of_a_def_prints_the_whole_program(tmp_path):
    # the subterm is in a def's body: patching it would change the def for its other callers
    text = "def e(x: var, a: param) = exp([x >= a])\nparam b = 0.5\nint ([0, 1]) 2 * e(x, b) d(x)\n"
    fx = fix(text, "p.lgr", frontend.load_text(text, "p.lgr"))
    assert fx.whole and "def e" not in fx.after and "ifge0 x - b then exp(1) else 1" in fx.after


@pytest.mark.parametrize("program", ["exp(-2 * [x >= a])", "(x + [x >= a])^2", "sqrt(x * [x >= a])"])
def test_deriv_refuses_a_non_transverse_program(langur, tmp_path, program):
    f = tmp_path / "p.lgr"
    f.write_text(f"param a = 0.5\nint ([0, 1]) {program} d(x)\n")
    r = langur("deriv", f, "--json", cwd=tmp_path)
    assert r.returncode == 1
    out = json.loads(r.stdout)
    assert out["exact"] is None and out["mc"] is None and "X301" in out["undefined"]
    assert "ifge0 x - a" in out["rewrite"]
    r = langur("deriv", f, "--engine", "mc", cwd=tmp_path)
    assert r.returncode == 1 and "not defined" in r.stdout and "X301" in r.stderr


def test_deriv_rewrite_differentiates_the_rewrite(langur, tmp_path):
    f = tmp_path / "p.lgr"
    f.write_text("param a = 0.5\nint ([0, 1]) exp(-2 * [x >= a]) d(x)\n")
    r = langur("deriv", f, "--rewrite", "--json", "--samples", "1000", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert abs(out["exact"]["value"] - (1 - math.exp(-2))) < 1e-12  # D(a + (1 − a)e⁻²)
    assert abs(out["mc"]["value"] - (1 - math.exp(-2))) < 1e-12  # one root, sampled exactly
    assert out["theorem_8_1"]["holds"] and out["rewrite"]


@pytest.mark.parametrize("example", ["coincident.lgr", "nested.lgr"])
def test_degenerate_examples(langur, tmp_path, example):
    r = langur("deriv", DEGENERATE / example, "--json", cwd=tmp_path)
    assert r.returncode == 1 and json.loads(r.stdout)["exact"] is None
    r = langur("deriv", DEGENERATE / example, "--rewrite", "--json", cwd=tmp_path)
    assert r.returncode == 0 and json.loads(r.stdout)["exact"]["value"] == -1.0  # D(1 − a)


def test_fix_of_standard_input_prints_the_program(langur, monkeypatch):
    import io

    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(b"param a = 0.5\nint ([0, 1]) [x >= a]^2 d(x)\n")))
    r = langur("check", "-", "--fix")
    # (a bracket prints as one since fold31: [x - a >= 0], was ifge0 x - a then 1 else 0; an atom is
    # patched in without parentheses since fixfold)
    assert r.returncode == 0 and r.stdout == "param a = 0.5\nint ([0, 1]) [x - a >= 0] d(x)\n"
