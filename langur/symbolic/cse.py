"""Generated numeric code that evaluates each repeated subexpression once (issue 15: exact ``deriv``
of every example in a second).

sympy's code printers write an expression as one Python expression, so a subtree that occurs k
times in the sympy tree (the stylization kernel's barycentric coordinates and colour differences,
§10.3.1, in every term of a partial derivative's weight) is evaluated k times at every call: the
vectorized weight of a stylize/quadratic partial derivative is ~12,000 characters over ~110
distinct repeated subexpressions, and the quadrature calls it ~125 times.

:func:`evaluated_once` rewrites the generated function's returned expression so that the first
occurrence of each repeated subexpression, in Python's evaluation order, binds its value
(``(_langur_cse0 := …)``) and every later occurrence reads it.  The function computes the same
values, raises the same exception at the same operation, and differs only in not repeating the
operations of the later occurrences:

* Python evaluates an expression of the kinds accepted here (arithmetic, unary operators, calls,
  attribute reads, single comparisons, lists and tuples) completely, left to right, each operand
  before its operator, the function before its arguments: the first occurrence of a subtree in
  the text is evaluated, and completed, before any later one starts; the binding happens there.
  Lazy forms (``a if c else b``, ``and``/``or``, chained comparisons, lambdas, comprehensions)
  are refused: there an occurrence may not be evaluated at all.
* A later occurrence is the same operations on the same values (the same names, read-only in the
  function; the same constants) of the ``math`` and ``numpy`` functions and Python's arithmetic,
  which are deterministic and have no side effects (the code printers' output without functions of
  their own implementation, ``_imp_``, which :func:`~langur.symbolic.text.shared_lambdify` never
  sends here): the same value, bit for bit — and it cannot raise, since the first occurrence did
  not.  Generated code neither mutates a value nor asks for an object's identity.
* Subtrees without an argument (numbers only) are left alone: Python folds them at compilation
  as before.
"""

from __future__ import annotations

import ast

from langur import gcpause

#: The prefix of the names bound to repeated subexpressions.
PREFIX = "_langur_cse"


class _Refused(Exception):
    """A node this rewriting does not handle (lazy evaluation, or an unknown kind)."""


def evaluated_once(source: str, args: list[str]):
    """The module AST of ``source`` (``def NAME(args):`` and one ``return EXPR``, as lambdify writes it)
    with its returned expression rewritten (module doc), or None when nothing repeats or the code is
    not of the kinds handled (then the caller compiles ``source`` as it is)."""
    try:
        with gcpause.paused():  # (~10⁴ AST nodes, no cycles: no collection of the engine's large heap meanwhile)
            return _rewritten(source, args)
    except (_Refused, SyntaxError, RecursionError, ValueError):
        return None


def _rewritten(source: str, args: list[str]):
    """:func:`evaluated_once`'s work (raising :class:`_Refused` where it does not apply)."""
    tree = ast.parse(source)
    (fn,) = tree.body
    (ret,) = fn.body
    if not isinstance(fn, ast.FunctionDef) or not isinstance(ret, ast.Return) or ret.value is None:
        return None
    rewritten = _Rewriter(set(args)).run(ret.value)
    if rewritten is None:
        return None
    ret.value = rewritten
    return tree


class _Rewriter:
    def __init__(self, args: set[str]):
        self.args = args
        self.ids: dict = {}  # structural key -> number
        self.count: list[int] = []  # occurrences, by number
        self.varying: list[bool] = []  # whether the subtree mentions an argument, by number
        self.names: dict[int, str] = {}

    def run(self, expr):
        self._key(expr)
        if not any(n >= 2 and v for n, v in zip(self.count, self.varying)):
            return None
        return self._rebuild(expr)

    def _key(self, node) -> int:
        """A number per distinct subtree (structurally: kinds, operators, names, constants with their
        types), kept on the node as ``_langur_cse``; counts the occurrences."""
        t = type(node)
        key = self._key
        if t is ast.BinOp:
            a, b = key(node.left), key(node.right)
            k = (1, type(node.op), a, b)
            varying = self.varying[a] or self.varying[b]
        elif t is ast.Name:
            if node.id.startswith(PREFIX):
                raise _Refused()
            k = (2, node.id)
            varying = node.id in self.args
        elif t is ast.Constant:
            k = (3, type(node.value), repr(node.value))
            varying = False
        elif t is ast.UnaryOp:
            a = key(node.operand)
            k = (4, type(node.op), a)
            varying = self.varying[a]
        elif t is ast.Call:
            if any(type(a) is ast.Starred for a in node.args) or any(kw.arg is None for kw in node.keywords):
                raise _Refused()
            parts = [key(node.func), *[key(a) for a in node.args]]
            named = tuple((kw.arg, key(kw.value)) for kw in node.keywords)
            k = (5, tuple(parts), named)
            varying = any(self.varying[a] for a in parts) or any(self.varying[a] for _, a in named)
        elif t is ast.Attribute:
            a = key(node.value)
            k = (6, a, node.attr)
            varying = self.varying[a]
        elif t is ast.Compare:
            if len(node.ops) != 1:
                raise _Refused()  # a chain stops at its first false comparison
            a, b = key(node.left), key(node.comparators[0])
            k = (7, type(node.ops[0]), a, b)
            varying = self.varying[a] or self.varying[b]
        elif t is ast.List or t is ast.Tuple:
            if any(type(a) is ast.Starred for a in node.elts):
                raise _Refused()
            parts = [key(a) for a in node.elts]
            k = (8, t, tuple(parts))
            varying = any(self.varying[a] for a in parts)
        else:
            raise _Refused()  # IfExp, BoolOp, Lambda, comprehensions, subscripts, …
        i = self.ids.get(k)
        if i is None:
            i = self.ids[k] = len(self.count)
            self.count.append(0)
            self.varying.append(varying)
        node._langur_cse = i
        self.count[i] += 1
        return i

    def _rebuild(self, node):
        i = node._langur_cse
        t = type(node)
        if t is ast.Name or t is ast.Constant or t is ast.Attribute or self.count[i] < 2 or not self.varying[i]:
            return self._children(node)
        name = self.names.get(i)
        if name is not None:  # a later occurrence: its value
            return ast.copy_location(ast.Name(id=name, ctx=ast.Load()), node)
        name = self.names[i] = f"{PREFIX}{len(self.names)}"
        target = ast.copy_location(ast.Name(id=name, ctx=ast.Store()), node)
        return ast.copy_location(ast.NamedExpr(target=target, value=self._children(node)), node)

    def _children(self, node):
        t = type(node)
        if t is ast.BinOp:
            node.left = self._rebuild(node.left)
            node.right = self._rebuild(node.right)
        elif t is ast.UnaryOp:
            node.operand = self._rebuild(node.operand)
        elif t is ast.Compare:
            node.left = self._rebuild(node.left)
            node.comparators = [self._rebuild(node.comparators[0])]
        elif t is ast.Call:
            node.func = self._rebuild(node.func)
            node.args = [self._rebuild(a) for a in node.args]
            for kw in node.keywords:
                kw.value = self._rebuild(kw.value)
        elif t is ast.List or t is ast.Tuple:
            node.elts = [self._rebuild(a) for a in node.elts]
        return node
