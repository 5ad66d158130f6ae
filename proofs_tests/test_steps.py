"""``langur show --steps`` / ``--typing`` (issue 14): the derivation is recorded from the one
semantics (ddenote's and typesys's ``match``, through langur.observe), on every example."""

from __future__ import annotations

import math

import pytest
from paths import DEGENERATE, EXAMPLES

from langur import observe, steps
from langur.cli import main
from langur.ddenote import ddenote, ddenote_program
from langur.frontend import load

FILES = sorted(p for p in [*EXAMPLES.glob("*.lgr"), *DEGENERATE.glob("*.lgr")])
FIG8 = ("Fig. 8, constant", "Fig. 8, variable", "Fig. 8, parameter", "Fig. 8, sum", "Fig. 8, product",
        "LANGUAGE.md §1, primitive", "LANGUAGE.md §1, constant power", "Fig. 8, conditional",
        "Fig. 8, diffeomorphic conditional", "Fig. 8, let")


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_steps_and_typing_on_every_example(path):
    loaded = load(str(path))
    if loaded.program is None:
        pytest.skip(f"{path.name}: a library module, no program")
    at = loaded.param_values()
    first = next(iter(at))
    trace, nf = steps.derivative_steps(loaded.program, {k: int(k == first) for k in at}, at)
    assert trace and all(s.rule.startswith(FIG8) for s in trace)
    assert trace[0].depth == 1 and trace[0].result is nf  # the root rule produced the normal form
    # the recorded derivation is the semantics' own: the same normal form as without observing
    plain = ddenote(loaded.program.body, {k: int(k == first) for k in at}, at=at, variables=loaded.program.variables)
    assert str(plain) == str(nf)
    assert steps.steps_text(trace) and len(steps.steps_text(trace, full=True)) == len(trace)
    typing, found = steps.typing_steps(loaded.program, loaded.params)
    assert found == [] and typing[0].rule.startswith("Fig. 11, program")
    assert all(s.rule.startswith(("Fig. 6", "Fig. 11", "LANGUAGE.md", "call")) for s in typing)


def test_observer_is_off_unless_asked_and_nests():
    loaded = load(str(EXAMPLES / "fig1.lgr"))
    with observe.observing() as outer:
        observe.rule("outer", None)
        with observe.observing() as inner:
            ddenote(loaded.program.body, {"theta": 1})
        observe.rule("after", None)
    assert [s.rule for s in outer] == ["outer", "after"] and inner
    observe.rule("nobody listens", None)  # no observer: nothing recorded, no error


def test_fig9_derivation_names_the_diffeomorphic_rule_and_sifts_to_the_boundary(capsys):
    loaded = load(str(EXAMPLES / "fig9.lgr"))
    at = loaded.param_values()
    trace, nf = steps.derivative_steps(loaded.program, {"theta": 1}, at)
    diffeo = [s for s in trace if s.rule.startswith("Fig. 8, diffeomorphic") and s.result.deltas]
    assert len(diffeo) == 1 and "theta" in steps._term_text(diffeo[0].term)
    lines = steps.sifting(loaded.program, nf, at)
    # by hand: u0 = θ + x − y, u1 = x; on u0 = 0 the weight 1 + θ + x + y is 1 + 2θ + 2u1, |J| = 1,
    # and ∫_{-1}^{1} (1 + 2u1) du1 = 2 at θ = 0
    assert "Jacobian |det D(Psi^-1)| = 1" in "\n".join(lines)
    assert lines[-1].strip() == "value of delta term 1 at theta = 0: 2"
    res = ddenote_program(loaded.program, at, {"theta": 1})
    assert math.isclose(res.boundary.value, 2.0)
    status = main(["show", str(EXAMPLES / "fig9.lgr"), "--wrt", "theta", "--steps", "--typing"])
    out = capsys.readouterr().out
    assert status == 0
    assert "derivation of ⦇t⦈ rule by rule (Fig. 8):" in out and "typing derivation (Fig. 6, 11):" in out
    assert out.index("derivation of ⦇t⦈") < out.index("derivative ⦇p⦈ (Theorem 7.1") < out.index("sifting")


@pytest.mark.parametrize("name, wrt", [("fig1.lgr", "theta"), ("risk.lgr", "a"), ("triangle.lgr", "px")])
def test_sifting_adds_up_to_the_boundary_part(name, wrt):
    loaded = load(str(EXAMPLES / name))
    at = loaded.param_values()
    direction = {k: int(k == wrt) for k in at}
    _, nf = steps.derivative_steps(loaded.program, direction, at)
    values = [r.value for r in steps.delta_integrals(loaded.program, nf, at)]
    res = ddenote_program(loaded.program, at, direction)  # all delta terms at once
    assert values and math.isclose(sum(values), res.boundary.value, rel_tol=1e-6, abs_tol=1e-9)
    lines = steps.sifting(loaded.program, nf, at)
    assert sum(line.strip().startswith("value of delta term") for line in lines) == len(nf.deltas)


def test_steps_without_a_derivative_is_a_usage_error(capsys):
    assert main(["show", str(EXAMPLES / "fig1.lgr"), "--steps"]) == 2


def test_steps_latex_is_well_formed(capsys):
    from test_show_latex import well_formed

    assert main(["show", str(EXAMPLES / "fig9.lgr"), "--wrt", "theta", "--steps", "--typing", "--latex"]) == 0
    tex = capsys.readouterr().out
    assert well_formed(tex) == [] and "\\text{Fig. 8, diffeomorphic conditional: }" in tex


def test_a_long_derivation_is_cut_and_says_so(monkeypatch):
    loaded = load(str(EXAMPLES / "fig9.lgr"))
    trace, _ = steps.derivative_steps(loaded.program, {"theta": 1}, loaded.param_values())
    monkeypatch.setattr(steps, "MAX_STEPS", 3)
    lines = steps.steps_text(trace, full=True)
    assert len(lines) == 4 and lines[-1] == f"… {len(trace) - 3} more steps not written out (more than 3 lines)"
