"""The Potto and Teg adapters of examples/adapters/ (issue 17, docs/engines.md "Potto and Teg").

The peers are the user's installs, never shipped: their tests run where ``LANGUR_PEERS`` names a
folder holding checkouts of ``potto`` and ``teg`` (or they are importable), and skip with the reason
otherwise.  The adapters themselves are always tested to load and to decline, with a reason and
without a traceback, when their peer is missing.  Expected values are worked by hand (each
program's header in examples/adapters/programs/ shows the work).
"""

from __future__ import annotations

import importlib.util
import math
import os
import sys

import pytest
from paths import EXAMPLES

from langur.cli import main
from langur.engines import Answer, Declined, EngineFailure
from langur.frontend import load_text

ADAPTERS = EXAMPLES / "adapters"
PROGRAMS = ADAPTERS / "programs"
PEERS = os.environ.get("LANGUR_PEERS")
if PEERS and PEERS not in sys.path:
    sys.path.insert(0, PEERS)


def _adapter(name, tag=""):
    spec = importlib.util.spec_from_file_location(f"langur_adapter_{name}{tag}", ADAPTERS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # (its dataclasses look their module up)
    spec.loader.exec_module(module)
    return module


potto = _adapter("potto_engine")
teg = _adapter("teg_engine")
needs_potto = pytest.mark.skipif(bool(potto.MISSING), reason=potto.MISSING or "")
needs_teg = pytest.mark.skipif(bool(teg.MISSING), reason=teg.MISSING or "")


def _program(name):
    return load_text((PROGRAMS / f"{name}.lgr").read_text()).program


@pytest.fixture
def small_potto(monkeypatch):
    """Potto with fewer samples (it evaluates in pure Python): 8 batches of 25."""
    monkeypatch.setattr(potto, "BATCHES", 8)
    monkeypatch.setattr(potto, "SAMPLES", 25)
    return potto.make()


def _agrees(answer, truth, sigmas):
    return isinstance(answer, Answer) and abs(answer.value - truth) <= sigmas * answer.error + 1e-9


# --- always: without the peers ---------------------------------------------------------------

@pytest.mark.parametrize("name,peer", [("potto_engine", "potto"), ("teg_engine", "teg")])
def test_an_adapter_without_its_peer_declines_with_the_reason(monkeypatch, name, peer):
    monkeypatch.setitem(sys.modules, peer, None)  # `import potto` raises ImportError, as where it is absent
    module = _adapter(name, "_without_peer")
    assert module.MISSING and "PYTHONPATH" in module.MISSING
    engine = module.make()
    for answer in (engine.value(_program("step"), {"a": 0.5}),
                   engine.derivative(_program("step"), {"a": 0.5}, {"a": 1.0})):
        assert isinstance(answer, Declined) and "not importable" in answer.reason


@pytest.mark.parametrize("name,peer", [("potto_engine", "potto"), ("teg_engine", "teg")])
def test_the_cli_reports_a_missing_peer_as_declined_without_a_traceback(monkeypatch, capsys, name, peer):
    monkeypatch.setitem(sys.modules, peer, None)
    monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.syspath_prepend(str(ADAPTERS))
    try:
        status = main(["eval", str(PROGRAMS / "step.lgr"), "--engine", f"{name}:make"])
    finally:
        sys.modules.pop(name, None)  # (the next test imports it with its peer)
    out, err = capsys.readouterr()
    assert status == 0 and "declined: " in out and "not importable" in out
    assert "Traceback" not in out + err


# --- Potto ---------------------------------------------------------------------------------

@needs_potto
def test_potto_agrees_on_a_moving_jump(small_potto):
    # d/da ∫₀¹ [x ≤ a] = 1; ∫₀¹ [2x ≥ a]·x = 1/2 − a²/8 = 0.48 at a = 0.4
    assert _agrees(small_potto.derivative(_program("step"), {"a": 0.5}, {"a": 1.0}), 1.0, 5)
    assert _agrees(small_potto.value(_program("scaled_step"), {"a": 0.4}), 0.48, 5)


@needs_potto
def test_potto_is_right_on_a_quadratic_with_one_root_in_the_domain(small_potto):
    # ∫₀¹ [x² ≥ a] = 1 − √a, derivative −1/(2√a) = −1 at a = 1/4 (the root √a only)
    assert _agrees(small_potto.derivative(_program("quadratic_one_root"), {"a": 0.25}, {"a": 1.0}), -1.0, 5)


@needs_potto
def test_pottos_chain_rule_for_sqrt_is_wrong(small_potto):
    # d/da ∫₀¹ √(x + a) = √(1 + a) − √a = 0.5622 at a = 0.37; Potto's Sqrt.deriv is
    # 1/(2·√(u')) instead of u'/(2·√u): here u' = 1, so 1/2 everywhere
    program = load_text("param a = 0.37\nint ([0, 1]) sqrt(x + a) d(x)\n").program
    d = small_potto.derivative(program, {"a": 0.37}, {"a": 1.0})
    assert isinstance(d, Answer) and not _agrees(d, math.sqrt(1.37) - math.sqrt(0.37), 5)
    # where u' = 0 it divides by zero: a failure of the engine, not a refusal
    with pytest.raises(EngineFailure, match="ZeroDivisionError"):
        small_potto.derivative(load_text("param a = 0.37\nint ([0, 1]) [x <= a] * sqrt(x + 1) d(x)\n").program,
                               {"a": 0.37}, {"a": 1.0})


@needs_potto
def test_potto_weighs_a_condition_on_the_second_variable_by_its_jacobian(small_potto, monkeypatch):
    # ∫∫_{[0,1]²} [y > b] = 1 − b, derivative −1 at b = 0.61. Potto weighs the delta by
    # 1/|∂Ψ₀/∂t₀|: the adapter puts y (the variable the condition is solved for) first; with x
    # first Potto divided by ∂(y − b)/∂x = 0 (a mistake of ours the campaign found).
    monkeypatch.setattr(potto, "BATCHES", 4)
    monkeypatch.setattr(potto, "SAMPLES", 8)  # per level: 64 points a batch in two variables
    program = load_text("param b = 0.61\nint ([0, 1], [0, 1]) [y > b] d(x, y)\n").program
    assert _agrees(small_potto.derivative(program, {"b": 0.61}, {"b": 1.0}), -1.0, 5)


@needs_potto
def test_potto_declines_what_it_cannot_express(small_potto):
    assert isinstance(small_potto.value(_program("sin_weight"), {"a": 0.5}), Declined)  # no sin in Potto
    # a disk: its inverse branches exist only where a guard holds, in two variables
    assert isinstance(small_potto.derivative(_program("disk"), {"r": 0.5}, {"r": 1.0}), Declined)


@needs_potto
def test_deriv_finds_pottos_missing_root(capsys, monkeypatch):
    # ∫₋₁¹ [x² ≥ a] = 2 − 2√a: derivative −1/√a = −2 at a = 1/4, one delta at each root ±√a.
    # Potto's diffeomorphism has one inverse (√(u + a)): it sees one root and answers −1.
    monkeypatch.syspath_prepend(str(ADAPTERS))
    monkeypatch.delitem(sys.modules, "potto_engine", raising=False)
    module = __import__("potto_engine")
    monkeypatch.setattr(module, "BATCHES", 8)
    monkeypatch.setattr(module, "SAMPLES", 25)
    status = main(["deriv", str(PROGRAMS / "quadratic.lgr"), "--engine", "potto_engine:make", "--no-theorem"])
    out = capsys.readouterr().out
    assert status == 1 and "exact       : -2 " in out
    assert "potto       : -1 " in out and "DISAGREES" in out


# --- Teg -----------------------------------------------------------------------------------

@needs_teg
def test_teg_agrees_on_affine_jumps():
    engine = teg.make()
    assert _agrees(engine.derivative(_program("step"), {"a": 0.5}, {"a": 1.0}), 1.0, 1)
    # d/da ∫₀¹ [a ≤ x ≤ 2a]·eˣ = 2e^(2a) − e^a at a = 0.3
    d = engine.derivative(_program("two_jumps"), {"a": 0.3}, {"a": 1.0})
    assert _agrees(d, 2 * math.exp(0.6) - math.exp(0.3), 1)
    # ∫∫ [x + y ≤ a] = a²/2 = 0.18 at a = 0.6 (trapezoidal in two variables: the estimate holds it)
    assert _agrees(engine.value(_program("triangle2d"), {"a": 0.6}), 0.18, 1)


@needs_teg
def test_teg_integrates_a_curved_jump_but_declines_its_derivative():
    engine = teg.make()
    assert _agrees(engine.value(_program("quadratic"), {"a": 0.25}), 1.0, 1)  # 2 − 2√a
    d = engine.derivative(_program("quadratic"), {"a": 0.25}, {"a": 1.0})
    assert isinstance(d, Declined) and "affine" in d.reason


@needs_teg
def test_deriv_finds_tegs_zero_for_a_squared_jump(capsys, monkeypatch):
    monkeypatch.syspath_prepend(str(ADAPTERS))
    monkeypatch.delitem(sys.modules, "teg_engine", raising=False)
    status = main(["deriv", str(PROGRAMS / "squared_step.lgr"), "--engine", "teg_engine:make"])
    out = capsys.readouterr().out
    assert status == 1
    assert "D⟦p⟧        : 1 " in out  # the rewrite's derivative, by hand: d/dt t = 1
    assert "teg         : 0 " in out and "DISAGREES" in out
