"""The implicit root ``x*`` of :class:`langur.core.ImplicitRoot` as a sympy function (paper §7.2:
a point of an inverse branch Ψ̂⁻¹ with no closed form; issue 18).

``ImplicitRootFn(Lambda(x, f), target, lo, hi, -1, 0)`` is the one ``x`` in ``[lo, hi]`` with
``f(x) = target``, ``f`` strictly monotone on ``[lo, hi]`` (an inverse branch of a condition
between two of its turning points, :mod:`langur.syntax.turning`); with an index k ≥ 0 and a
bound n it is the k-th sign change of ``f − target`` on ``[lo, hi]`` (a turning point that moves
with the parameters).  It stays symbolic in the exact engine's closed forms; its derivative is
the implicit function theorem's,

    ∂x*/∂s = (∂target/∂s − ∂f/∂s(x*)) / ∂f/∂x(x*),

so every derivative (and the Jacobian dx*/du₀ = 1/f'(x*) of the delta's change of variables) is
exact in terms of ``x*``; ``evalf`` finds ``x*`` to the requested precision
(:mod:`langur.implicit.evalf`), and ``lambdify`` calls a solver in doubles on the compiled ``f``
(:mod:`langur.implicit.lambdified`).
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.str import StrPrinter

from langur.implicit.equations import LENIENT, NODES
from langur.implicit.evalf import evalf_root
from langur.implicit.lambdified import indexed_key, lambdified_root
from langur.memo import make_room, remember


class ImplicitRootFn(sp.Function):
    """``x*(target; θ)``: ``ImplicitRootFn(Lambda(x, f), target, lo, hi, index, of)`` is the root of
    ``f(x; θ) = target`` in ``[lo, hi]`` (``index`` = −1, ``f`` monotone there), or the ``index``-th
    sign change of ``f − target`` there (:class:`langur.core.ImplicitRoot`)."""

    nargs = 6
    is_real = True

    @property
    def is_number(self) -> bool:  # the bound variable of the Lambda is not a free symbol
        return not self._free()

    @property
    def free_symbols(self) -> set:
        """sympy's free symbols of the root (its arguments', the equation's without its bound
        variable), a new set each time as sympy gives it (callers may change it); found once per
        root (:meth:`_free`)."""
        return set(self._free())

    def _free(self) -> frozenset:
        """The free symbols, walked once per root: sympy asks for them at every assumption query
        and ``evalf`` of an expression holding the root (``is_number``), each time a walk of the
        equation and of the roots nested in its bracket (issue 15, exact13t)."""
        known = self.__dict__.get("_langur_free")
        if known is None:
            known = self.__dict__["_langur_free"] = frozenset(super().free_symbols)
        return known

    @classmethod
    def eval(cls, lam, target, lo, hi, index, of):
        return None  # stays symbolic: it has no closed form (that is why it exists)

    def _eval_derivative(self, s):
        """The implicit function theorem's derivative (module doc), built once per root and
        symbol (:data:`_DERIVATIVES`): sympy's ``solve`` and the Jacobians differentiate the same
        roots again and again, and each build asks sympy's assumptions of the root."""
        try:
            known = _DERIVATIVES.get((self, s))
        except TypeError:  # (an unhashable symbol: built again)
            known = None
        if known is None:
            lam, target = self.args[:2]
            (x,), f = lam.variables, lam.expr
            at = {x: self}
            known = (sp.diff(target, s) - sp.diff(f, s).xreplace(at)) / sp.diff(f, x).xreplace(at)
            remember(_DERIVATIVES, (self, s), known, PRINTED, at_once=True)
        return known

    def _eval_evalf(self, prec):
        if self._free():
            return None
        return evalf_root(self.args, prec)

    #: ``lambdify``'s implementation (:func:`langur.implicit.lambdified.lambdified_root`).
    _imp_ = staticmethod(lambdified_root)

    def _code(self, printer):
        """``lambdify``'s text: the equation as a Python ``lambda`` of the root's variable and the
        equation's other symbols, whose values follow the bracket."""
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        free = sorted(f.free_symbols - {x}, key=str)
        params = ", ".join(printer._print(s) for s in (x, *free))
        args = ", ".join(printer._print(a) for a in (target, lo, hi))
        values = "".join(f", {printer._print(s)}" for s in free)
        if index >= 0:  # certified by the exact engine's own enclosures: the equation named by a key
            return f"ImplicitRootFn({indexed_key(lam, free)!r}, {args}, {int(index)}, {int(of)}{values})"
        return (f"ImplicitRootFn((lambda {params}: {printer._print(f)}), {args}, {int(index)}, {int(of)}"
                f"{values})")

    _pythoncode = _mpmathcode = _numpycode = _lambdacode = _code

    def _latex(self, printer, exp=None):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = r"\operatorname{root}" if index < 0 else rf"\operatorname{{sign\,change}}_{{{int(index)}}}"
        out = (rf"{which}_{{{printer.doprint(x)} \in [{printer.doprint(lo)}, {printer.doprint(hi)}]}}"
               rf"\left({printer.doprint(f)} = {printer.doprint(target)}\right)")
        return out if exp is None else rf"\left({out}\right)^{{{exp}}}"

    def _sympystr(self, printer):
        """``root(x: f = target in [lo, hi])`` (``sign_change_k(…; at most n)`` for an indexed
        root); by sympy's own ``StrPrinter`` with its settings, remembered (:data:`_PRINTED`): sympy's
        ``solve`` prints an equation holding roots again and again (each nested root once more)."""
        if type(printer) is not StrPrinter:
            return self._text(printer)
        try:
            # (a Float is printed stripped below the top level: the level's side of 1 is part of it)
            key = (self, tuple(sorted(printer._settings.items())), getattr(printer, "_print_level", 0) > 0)
            known = _PRINTED.get(key)
        except TypeError:  # a setting that cannot be hashed: printed again
            return self._text(printer)
        if known is None:
            make_room(_PRINTED, PRINTED, at_once=True)
            known = _PRINTED[key] = self._text(printer)
        return known

    def _text(self, printer):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = "root" if index < 0 else f"sign_change_{int(index)}"
        bound = "" if index < 0 else f"; at most {int(of)}"
        return (f"{which}({printer.doprint(x)}: {printer.doprint(f)} = {printer.doprint(target)} "
                f"in [{printer.doprint(lo)}, {printer.doprint(hi)}]{bound})")


#: :meth:`ImplicitRootFn._sympystr`'s texts by root and printer settings; at most :data:`PRINTED`
#: kept (then forgotten all at once).
_PRINTED: dict = {}
PRINTED = 4096
#: :meth:`ImplicitRootFn._eval_derivative`'s derivatives by root and symbol (at most
#: :data:`PRINTED` kept, then forgotten all at once).
_DERIVATIVES: dict = {}


def implicit_root(equation: sp.Expr, variable: sp.Symbol, target: sp.Expr, lo: sp.Expr, hi: sp.Expr,
                  index: int | None = None, of: int = 0, root=None, lenient: bool = False) -> sp.Expr:
    """``ImplicitRootFn`` of ``equation`` in ``variable`` (bound: replaced by a dummy); ``root``:
    the core :class:`~langur.core.ImplicitRoot` it denotes, whose span (the condition's place in the
    source) is named when evaluating it is refused; ``lenient``: the
    equation mentions other integration variables (see :func:`langur.enclosures.certified_brackets`)."""
    x = sp.Dummy(variable.name, real=True)
    lam = sp.Lambda(x, equation.xreplace({variable: x}))
    if root is not None:
        NODES[x] = root
    if lenient:
        LENIENT.add(x)
    return ImplicitRootFn(lam, target, lo, hi, sp.Integer(-1 if index is None else index), sp.Integer(of))
