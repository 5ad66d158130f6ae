"""`langur fuzz --out DIR` (issue 13, "counterexamples people can use"): each disagreement is
written as a shrunk `.lgr` file whose comment header holds both engines' numbers; the file loads
with the front end as it is, and re-running it gives the numbers of its header."""

from langur.cli import main
from langur.engines.builtin import MonteCarloEngine
from langur.frontend import load_text
from langur.fuzz import compare, counterexamples, mutants
from langur.syntax.parser import parse_module


def _size(text: str) -> int:
    return counterexamples._size(parse_module(text).program.body)


def test_out_writes_each_disagreement_shrunk_with_both_engines_numbers(capsys, tmp_path):
    # the Monte Carlo engine without its delta term (a mutant of Fig. 8) disagrees on every jump
    out = tmp_path / "found"
    status = main(["fuzz", "--engine", "langur.fuzz.mutants:drop_delta", "--examples", "3", "--seed", "1",
                   "--samples", "2000", "--workers", "0", "--no-shrink", "--out", str(out),
                   "--hypothesis-dir", str(tmp_path / "h")])
    printed = capsys.readouterr().out
    assert status == 1 and "DISCREPANCY" in printed
    files = sorted(out.iterdir())
    assert files and all(f.suffix == ".lgr" and f"wrote {f}" in printed for f in files)
    for f in files:
        text = f.read_text()
        assert text.startswith("# langur fuzz: discrepancy")
        rows = counterexamples.header_rows(text)
        assert any(not ok for *_, ok in rows)
        # the original is in the header, commented; the program itself is no larger
        original = "\n".join(line[4:] for line in text.splitlines() if line.startswith("#   ")) + "\n"
        if "# shrunk from:" in text:
            assert _size(text) < _size(original)
        # the file loads as it is, and re-running it gives the header's numbers (same seed, samples)
        assert load_text(text).program is not None
        again = compare.compare_engine(text, mutants.drop_delta())  # the engine --engine resolved
        assert again.status == "discrepancy"
        assert [(r.quantity, r.wrt, r.exact, r.error, r.engine, r.mc, r.stderr, r.ok) for r in again.rows] == rows
        # and the unbroken engine agrees on it: the counterexample is the mutant's doing
        assert compare.compare_engine(text, MonteCarloEngine()).status == "agree"


def test_the_counterexample_shrinker_keeps_the_failure_and_removes_the_rest():
    # a fake unit that fails on every program with a comparison `<=`: a sum of factors and a def
    # shrinks to the bracket alone, the unused def and parameter dropped
    text = ("param a = 0.37, b = 0.61\ndef g(x: var, qb: param) = x * qb + 1\n"
            "int ([0, 1])\n  (x + 0.5) * [x <= a] + 0.7 * g(x, b)\nd(x)\n")

    def unit(t):
        r = compare.ProgramResult(t, "discrepancy" if "<=" in t else "agree")
        return r

    runs = []
    small = counterexamples.shrink(unit(text), lambda t: runs.append(t) or unit(t))
    assert small.text == "param a = 0.37\nint ([0, 1])\n  [x <= a]\nd(x)\n"
    assert len(runs) <= counterexamples.BUDGET
    assert counterexamples.shrink(unit(text), unit, budget=0).text == text
