"""The Potto and Teg adapters of examples/adapters/ (issue 17, docs/engines.md "Potto and Teg").

The peers are the user's installs, never shipped: their tests run where ``LANGUR_PEERS`` names a
folder holding checkouts of ``potto`` and ``teg`` (or they are importable), and skip with the reason
otherwise.  The adapters themselves are always tested to load and to decline, with a reason, when
their peer is missing.
"""

from __future__ import annotations

import importlib.util
import os
import sys

import pytest
from paths import EXAMPLES

from langur.cli import main
from langur.engines import Answer, Declined
from langur.frontend import load_text

ADAPTERS = EXAMPLES / "adapters"
PEERS = os.environ.get("LANGUR_PEERS")
if PEERS and PEERS not in sys.path:
    sys.path.insert(0, PEERS)


def _adapter(name):
    spec = importlib.util.spec_from_file_location(f"langur_adapter_{name}", ADAPTERS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # (its dataclasses look their module up)
    spec.loader.exec_module(module)
    return module


potto = _adapter("potto_engine")
teg = _adapter("teg_engine")
needs_potto = pytest.mark.skipif(bool(potto.MISSING), reason=potto.MISSING or "")
needs_teg = pytest.mark.skipif(bool(teg.MISSING), reason=teg.MISSING or "")

FIG1 = "param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)\n"
# ∫₋₁¹ [x² ≥ a] = 2 − 2√a for 0 < a < 1: the derivative −1/√a = −2 at a = 1/4, a delta at each root ±√a
QUADRATIC = "param a = 0.25\nint ([-1, 1]) [x^2 - a >= 0] d(x)\n"
CIRCLE = "param r = 0.5\nint ([-1, 1], [-1, 1]) [r^2 - x^2 - y^2 >= 0] d(x, y)\n"
# ∫₀¹ [x < t]² = t: derivative 1 (not transverse as written: X301; the rewrite [x < t] has it)
SQUARED = "param t = 0.5\nint ([0, 1]) [x < t] * [x < t] d(x)\n"


def _program(text):
    return load_text(text).program


@pytest.mark.parametrize("module", [potto, teg], ids=["potto", "teg"])
def test_an_adapter_without_its_peer_declines_with_the_reason(module):
    engine = module.make()
    answer = engine.value(_program(FIG1), {"theta": 0.5})
    if module.MISSING:
        assert isinstance(answer, Declined) and "PYTHONPATH" in answer.reason
    else:  # the peer is here: it answers ∫₀¹[x ≤ 1/2] = 1/2
        assert isinstance(answer, Answer) and abs(answer.value - 0.5) <= 5 * answer.error + 0.01


@needs_potto
def test_potto_agrees_on_fig1_and_misses_one_root_of_a_quadratic():
    engine = potto.make()
    d = engine.derivative(_program(FIG1), {"theta": 0.5}, {"theta": 1.0})
    assert isinstance(d, Answer) and abs(d.value - 1.0) <= 5 * d.error + 1e-9
    d = engine.derivative(_program(QUADRATIC), {"a": 0.25}, {"a": 1.0})
    # Potto's diffeomorphism has one inverse: it sees the root +√a only, so −1 instead of −2
    assert isinstance(d, Answer) and abs(d.value - (-1.0)) <= 5 * d.error + 1e-9
    assert isinstance(engine.derivative(_program(CIRCLE), {"r": 0.5}, {"r": 1.0}), Declined)


@needs_teg
def test_teg_agrees_on_fig1_and_declines_a_curved_boundary():
    engine = teg.make()
    d = engine.derivative(_program(FIG1), {"theta": 0.5}, {"theta": 1.0})
    assert isinstance(d, Answer) and abs(d.value - 1.0) <= d.error + 1e-6
    assert isinstance(engine.derivative(_program(QUADRATIC), {"a": 0.25}, {"a": 1.0}), Declined)


@needs_teg
def test_deriv_finds_tegs_zero_for_a_squared_jump(tmp_path, capsys, monkeypatch):
    monkeypatch.syspath_prepend(str(ADAPTERS))
    f = tmp_path / "squared.lgr"
    f.write_text(SQUARED)
    status = main(["deriv", str(f), "--wrt", "t", "--engine", "teg_engine:make"])
    out = capsys.readouterr().out
    assert status == 1
    assert "D⟦p⟧        : 1 " in out  # the rewrite's derivative, by hand: d/dt t = 1
    assert "teg         : 0 " in out and "DISAGREES" in out


@needs_potto
def test_deriv_finds_pottos_missing_root(tmp_path, capsys, monkeypatch):
    monkeypatch.syspath_prepend(str(ADAPTERS))
    f = tmp_path / "quadratic.lgr"
    f.write_text(QUADRATIC)
    status = main(["deriv", str(f), "--wrt", "a", "--engine", "potto_engine:make", "--no-theorem"])
    out = capsys.readouterr().out
    assert status == 1 and "potto       : -1 " in out and "DISAGREES" in out
