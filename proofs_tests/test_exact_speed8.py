"""The exact engine's shortcuts of issue 15 (eighth pass, exact8) give what the slow paths gave:
sympy's simplify within ``nounits.units_unloaded`` returns what it returns with
``sympy.physics.units`` imported, without importing it; code that wants units inside or after a
block gets the real package; the exact engine's first derivative of an example no longer imports it."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import sympy as sp
from paths import EXAMPLES

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: Expressions whose simplification exercises simplify's branches (powers, exp, trig, Piecewise
#: with relations, a Jacobian of the ray tracer's kind), as text so that a fresh process builds them.
EXPRS = [
    "100/(18*t**2 - 117*t - 245)",
    "(-108*t**3 + 1026*t**2 + 5439*t + 5355)/(360*t**2*zth**2 + 1440*t*zth**2 + 1400*zth**2)",
    "sin(a)**2 + cos(a)**2 + exp(a)*exp(b)",
    "Piecewise((sqrt(2)*exp(-(a/5 - 1/5)**2/2)*exp(-(a/5 - 2/5)**2/2)/(10*pi), (a >= -10) & (a - b <= 0)),"
    " (0, True))",
    "1/(2*sqrt(r**2 - u1**2))",
    "(x**2 - 1)/(x - 1) + log(exp(x))",
]


def _run(code: str) -> str:
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1]


def test_simplify_without_units_is_simplify():
    """In a fresh process, simplify within the block does not import the units package and gives
    the same expressions (srepr) as sympy's simplify with the package imported, here."""
    code = f"""
import json, sys, sympy as sp
from langur.symbolic.nounits import units_unloaded
exprs = {EXPRS!r}
with units_unloaded():
    out = [sp.srepr(sp.simplify(sp.sympify(e))) for e in exprs]
print(json.dumps([out, "sympy.physics.units" in sys.modules]))
"""
    got, imported = json.loads(_run(code))
    assert not imported
    import sympy.physics.units  # noqa: F401 - the reference: simplify as sympy runs it, units imported

    assert got == [sp.srepr(sp.simplify(sp.sympify(e))) for e in EXPRS]


def test_units_wanted_inside_or_after_a_block_are_the_real_ones():
    """Asking the placeholder for any other name imports the real package; after the block a
    Quantity is the real class, and simplify treats quantities as sympy does."""
    code = """
import json, sys, sympy as sp
from langur.symbolic.nounits import units_unloaded
with units_unloaded():
    import sympy.physics.units as u
    inside = str(u.convert_to(3 * u.kilometer, u.meter))
from sympy.physics.units import Quantity, meter, kilometer
from sympy.physics.units.quantities import Quantity as Q2
with units_unloaded():
    simp = str(sp.simplify(kilometer / meter))
print(json.dumps([inside, Quantity is Q2, isinstance(meter, Quantity), simp]))
"""
    inside, same_class, is_quantity, simp = json.loads(_run(code))
    assert inside == "3000*meter"
    assert same_class and is_quantity
    from sympy.physics.units import kilometer, meter

    assert simp == str(sp.simplify(kilometer / meter)) == "1000"


def test_nested_blocks_restore_sys_modules():
    code = """
import json, sys
from langur.symbolic.nounits import units_unloaded, NAME
with units_unloaded():
    a = NAME in sys.modules
    with units_unloaded():
        b = NAME in sys.modules
    c = NAME in sys.modules
print(json.dumps([a, b, c, NAME in sys.modules]))
"""
    assert json.loads(_run(code)) == [True, True, True, False]


def test_exact_derivative_does_not_import_units():
    """disk.lgr's derivative (sympy's solve, integrate and the Jacobian's simplify, the Theorem
    8.1 check): the value is π (d/dr of πr² at r = 1/2), and the units package is not imported."""
    path = os.path.join(EXAMPLES, "adapters", "programs", "disk.lgr")
    code = f"""
import json, sys
from langur.exact import exact_deriv
from langur.frontend import load
p = load({path!r})
at = p.param_values()
r = exact_deriv(p.program, at, {{"r": 1}})
print(json.dumps([r.value, str(r.method), r.theorem_8_1.holds, "sympy.physics.units" in sys.modules, at["r"] * 1.0]))
"""
    value, method, holds, imported, r = json.loads(_run(code))
    assert abs(value - 2 * 3.141592653589793 * r) < 1e-12
    assert method == "closed_form" and holds
    assert not imported


def test_float_with_implicit_roots_put_in_once_is_sympys_evalf():
    """Theorem 8.1's ``_float`` evaluates each implicit root once (50 digits) before the 20-digit
    evaluation: on turning.lgr's local derivative of ⟦p⟧ (implicit roots of x³ − a·x …) it gives
    the float sympy's evalf gives with the roots solved at every precision it asks, at the point
    and at nearby points; and that derivative agrees with a central difference of ⟦p⟧'s values."""
    from langur import theorem
    from langur.denote import denote_program
    from langur.frontend import load
    from langur.implicit import ImplicitRootFn
    from langur.sympy_bridge import at_symbols

    p = load(os.path.join(EXAMPLES, "turning.lgr"))
    at = p.param_values()
    den = denote_program(p.program, at, near=True)
    local = theorem.directional(theorem.localize(den.expr, at_symbols(at)), {"a": 1})
    assert local.has(ImplicitRootFn)
    a0 = float(at["a"])
    for da in (0.0, 1e-3, -7e-4, 2e-3):
        q = {"a": a0 + da}
        want = float(sp.N(local.xreplace(at_symbols(q)), 20))
        assert theorem._float(local, q) == want
    h = 1e-5
    fd = (denote_program(p.program, {"a": a0 + h}).value - denote_program(p.program, {"a": a0 - h}).value) / (2 * h)
    assert abs(theorem._float(local, {"a": a0}) - fd) < 1e-6
