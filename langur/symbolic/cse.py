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
    ast.fix_missing_locations(tree)
    return tree


class _Rewriter:
    def __init__(self, args: set[str]):
        self.args = args
        self.ids: dict = {}  # structural key -> number
        self.count: dict[int, int] = {}
        self.node_id: dict[int, int] = {}  # id(node) -> number
        self.varying: set[int] = set()  # numbers of the subtrees that mention an argument
        self.names: dict[int, str] = {}

    def run(self, expr):
        self._key(expr)
        if not any(n >= 2 and i in self.varying for i, n in self.count.items()):
            return None
        return self._rebuild(expr)

    def _key(self, node) -> int:
        """A number per distinct subtree (structurally: kinds, operators, names, constants with their
        types); counts the occurrences."""
        if isinstance(node, ast.Name):
            if node.id.startswith(PREFIX):
                raise _Refused()
            k = ("N", node.id)
        elif isinstance(node, ast.Constant):
            k = ("C", type(node.value), repr(node.value))
        elif isinstance(node, ast.BinOp):
            k = ("B", type(node.op), self._key(node.left), self._key(node.right))
        elif isinstance(node, ast.UnaryOp):
            k = ("U", type(node.op), self._key(node.operand))
        elif isinstance(node, ast.Attribute):
            k = ("A", self._key(node.value), node.attr)
        elif isinstance(node, ast.Compare):
            if len(node.ops) != 1:
                raise _Refused()  # a chain stops at its first false comparison
            k = ("O", type(node.ops[0]), self._key(node.left), self._key(node.comparators[0]))
        elif isinstance(node, ast.Call):
            if any(isinstance(a, ast.Starred) for a in node.args) or any(kw.arg is None for kw in node.keywords):
                raise _Refused()
            k = ("F", self._key(node.func), tuple(self._key(a) for a in node.args),
                 tuple((kw.arg, self._key(kw.value)) for kw in node.keywords))
        elif isinstance(node, (ast.List, ast.Tuple)):
            if any(isinstance(a, ast.Starred) for a in node.elts):
                raise _Refused()
            k = ("L", type(node), tuple(self._key(a) for a in node.elts))
        else:
            raise _Refused()  # IfExp, BoolOp, Lambda, comprehensions, subscripts, …
        i = self.ids.get(k)
        if i is None:
            i = self.ids[k] = len(self.ids)
            if (k[0] == "N" and node.id in self.args) or any(
                    isinstance(part, int) and part in self.varying for part in _parts(k)):
                self.varying.add(i)
        self.node_id[id(node)] = i
        self.count[i] = self.count.get(i, 0) + 1
        return i

    def _rebuild(self, node):
        i = self.node_id[id(node)]
        if isinstance(node, (ast.Name, ast.Constant, ast.Attribute)) or self.count[i] < 2 or i not in self.varying:
            return self._children(node)
        name = self.names.get(i)
        if name is not None:  # a later occurrence: its value
            return ast.Name(id=name, ctx=ast.Load())
        name = self.names[i] = f"{PREFIX}{len(self.names)}"
        return ast.NamedExpr(target=ast.Name(id=name, ctx=ast.Store()), value=self._children(node))

    def _children(self, node):
        if isinstance(node, ast.BinOp):
            node.left = self._rebuild(node.left)
            node.right = self._rebuild(node.right)
        elif isinstance(node, ast.UnaryOp):
            node.operand = self._rebuild(node.operand)
        elif isinstance(node, ast.Compare):
            node.left = self._rebuild(node.left)
            node.comparators = [self._rebuild(node.comparators[0])]
        elif isinstance(node, ast.Call):
            node.func = self._rebuild(node.func)
            node.args = [self._rebuild(a) for a in node.args]
            for kw in node.keywords:
                kw.value = self._rebuild(kw.value)
        elif isinstance(node, (ast.List, ast.Tuple)):
            node.elts = [self._rebuild(a) for a in node.elts]
        return node


def _parts(k: tuple):
    """The numbers of a key's children (nested in tuples for calls and lists)."""
    for part in k[1:]:
        if isinstance(part, tuple):
            yield from _parts((None, *part))
        else:
            yield part
