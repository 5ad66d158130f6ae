"""Walks of sympy expression trees that visit each distinct subtree once (paper §6.3, Def. 6.2: the
closed forms decided at the evaluation point, :mod:`langur.symbolic.local`; issue 15: exact
``deriv`` of every example in a second).

The integrands and closed forms of large problems (the stylization kernel's, §10.3.1; the
ray-traced triangle's, §10.2) are trees of 10⁵–10⁶ nodes over 10³–10⁴ distinct subtrees, and
sympy's own walks (``free_symbols``, ``has``, ``atoms``, ``xreplace``, ``count_ops``) visit every
occurrence.  Here: a polynomial's degree and whether symbols occur (:func:`degree`,
:func:`mentions`), sizes (:func:`size`, :func:`tree_size`), searches (:func:`any_node`,
:func:`atoms_of`, :func:`has_any`), :func:`free_symbols`, and exact values at the evaluation point
(:func:`shared_xreplace`, :func:`rational_form`, :func:`exact_at`).
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

import sympy as sp

from langur.memo import remember


def degree(e, vs: frozenset, memo: dict | None = None, seen: dict | None = None) -> int | None:
    """Total degree of ``e`` as a polynomial in the symbols ``vs`` (coefficients any expressions
    free of them), or None when it is not one.  Linear in the size of the tree (memoized; ``seen``
    memoizes :func:`mentions`)."""
    memo = {} if memo is None else memo
    seen = {} if seen is None else seen
    if e in memo:
        return memo[e]
    if not e.args:
        out = 1 if e in vs else 0
    elif not mentions(e, vs, seen):
        out = 0
    elif isinstance(e, sp.Add):
        ds = [degree(a, vs, memo, seen) for a in e.args]
        out = None if None in ds else max(ds)
    elif isinstance(e, sp.Mul):
        ds = [degree(a, vs, memo, seen) for a in e.args]
        out = None if None in ds else sum(ds)
    elif isinstance(e, sp.Pow) and e.exp.is_Integer and e.exp >= 0:
        d = degree(e.base, vs, memo, seen)
        out = None if d is None else d * int(e.exp)
    else:
        out = None
    memo[e] = out
    return out


def mentions(e, vs, memo: dict) -> bool:
    """Whether ``e`` has one of the symbols ``vs`` free (``e.free_symbols & vs``), memoized by
    subtree in ``memo`` (asking ``free_symbols`` of every node walks each node's subtree again)."""
    hit = memo.get(e)
    if hit is None:
        if e.is_Symbol:
            hit = e in vs
        elif not e.args:
            hit = bool(e.free_symbols & vs)
        elif not _plain_free_symbols(type(e)):
            hit = bool(e.free_symbols & vs)
        else:
            hit = any(mentions(a, vs, memo) for a in e.args)
        memo[e] = hit
    return hit


#: Limits up to which :func:`size` counts node by node; beyond, it sums over distinct subtrees.
WALKED_SIZE = 4096

#: :func:`tree_size` of the trees :func:`size` measured beyond :data:`WALKED_SIZE`, by expression
#: (equal trees have the same size); at most :data:`FREE` kept (the oldest dropped).
_SIZES: dict = {}


def size(e, limit: int) -> int:
    """Number of nodes of the tree ``e``, counted up to ``limit`` (cheaper than ``count_ops``):
    ``min(number of nodes, limit)``.  A large limit (the closed forms printed or not, 10⁵ nodes) is
    checked by summing the sizes of the distinct subtrees (:func:`tree_size`) rather than visiting
    10⁵ nodes; that sum is remembered by expression, :data:`_SIZES`: the same closed forms and
    integrands are measured again by each choice of method)."""
    if limit > WALKED_SIZE:
        n = _SIZES.get(e)
        if n is None:
            n = remember(_SIZES, e, tree_size(e), FREE)
        return min(n, limit)
    n, stack = 0, [e]
    while stack and n < limit:
        node = stack.pop()
        n += 1
        stack.extend(node.args)
    return n


def tree_size(e, sizes: dict | None = None) -> int:
    """Number of nodes of the tree ``e`` (a subtree counted each time it occurs), each distinct
    subtree object visited once (``sizes``: the sizes found so far by object id, for the caller's
    trees that are alive meanwhile; shared between calls on trees sharing subtrees)."""
    sizes = {} if sizes is None else sizes
    if id(e) in sizes:
        return sizes[id(e)]
    stack = [(e, False)]
    while stack:
        node, done = stack.pop()
        if done:
            sizes[id(node)] = 1 + sum(sizes[id(a)] for a in node.args)
        elif id(node) not in sizes:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if id(a) not in sizes)
    return sizes[id(e)]


def any_node(e, holds) -> bool:
    """Whether ``holds(node)`` for a node of ``e``, each distinct subtree visited once (sympy's
    ``has`` walks the tree with its repeats: seconds for a local closed form of 10⁶ nodes over 10⁴
    distinct ones, the stylization kernel's ⟦p⟧)."""
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if holds(node):
            return True
        for a in node.args:
            if id(a) not in seen:
                seen.add(id(a))
                stack.append(a)
    return False


def atoms_of(e, types) -> set:
    """``e.atoms(*types)`` for classes ``types`` (nodes of those classes, a set), each distinct
    subtree visited once: sympy's ``atoms`` walks the tree with its repeats (the integrands and
    closed forms of a stylize or ray-traced partial derivative share their subtrees: a walk of
    10⁵ nodes over 10³ distinct ones, every time one is compiled or printed)."""
    out: set = set()
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, types):
            out.add(node)
        for a in (node.args if isinstance(node, sp.Basic) else node):  # (sympy's traversal: args, or iterables)
            if id(a) not in seen and (isinstance(a, sp.Basic) or _iterable(a)):
                seen.add(id(a))
                stack.append(a)
    return out


def _iterable(a) -> bool:
    """Whether sympy's preorder traversal descends into ``a`` (a non-Basic argument)."""
    return isinstance(a, (tuple, list, set, frozenset))


#: :func:`has_any`'s answers by (expression, classes): equal trees have nodes of the same classes
#: (sympy's equality tells a Float from a rational); at most :data:`FREE` kept (the oldest dropped).
_HAS: dict = {}


def has_any(e, types: tuple) -> bool:
    """``e.has(*types)`` for classes ``types``, each distinct subtree visited once (:func:`any_node`),
    remembered (:data:`_HAS`)."""
    key = (e, types)
    hit = _HAS.get(key)
    if hit is None:
        hit = remember(_HAS, key, any_node(e, lambda node: isinstance(node, types)), FREE)
    return hit


@lru_cache(maxsize=None)
def _plain_free_symbols(cls) -> bool:
    """Whether ``cls``'s free symbols are the union of its arguments' (sympy's ``Basic`` rule)."""
    owner = next(k for k in cls.__mro__ if "free_symbols" in k.__dict__)
    return owner is sp.Basic


#: :func:`free_symbols`' answers by expression (sympy's equality: equal trees have the same free
#: symbols): the same conditions, weights and integrands are asked for again by each step of a
#: decomposition, compilation and quadrature set-up (raytrace ∂t: 1,289 calls, 231 distinct
#: expressions); at most :data:`FREE` kept (the oldest dropped).
_FREE: dict = {}
FREE = 4096


def free_symbols(e) -> set:
    """``e.free_symbols`` for a tree of symbols and numbers under ordinary functions and operators,
    each distinct subtree visited once (sympy recomputes it for every occurrence: seconds for the
    ~10³-node integrands of a stylize partial derivative), remembered by expression (:data:`_FREE`;
    a new set each time, as sympy gives it).  A node with bound symbols (a Lambda, an implicit
    root, an Integral) is asked for its own ``free_symbols``."""
    hit = _FREE.get(e)
    if hit is None:
        hit = remember(_FREE, e, frozenset(_walked_free_symbols(e)), FREE)
    return set(hit)


def _walked_free_symbols(e) -> set:
    """:func:`free_symbols` walked: each distinct subtree visited once."""
    out: set = set()
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if node.is_Symbol:
            out.add(node)
            continue
        if not node.args:
            out |= node.free_symbols
            continue
        if not _plain_free_symbols(type(node)):  # its own rule (bound symbols, ImplicitRootFn)
            out |= node.free_symbols
            continue
        for a in node.args:
            if id(a) not in seen:
                seen.add(id(a))
                stack.append(a)
    return out

# ------------------------------------------------------------------------------------------
# Exact values at the evaluation point.


def shared_xreplace(e, rule: dict, rational: bool | None = None):
    """``e.xreplace(rule)``, the same expression, each distinct subtree rebuilt once (sympy's
    ``xreplace`` rebuilds a subtree every time it occurs: a weight substituted at every point of a
    lattice rule is a tree of thousands of nodes over a few hundred distinct ones).

    When ``e`` and the replacements are real rational forms (:func:`rational_form`; ``rational``:
    that answer when the caller knows it), a rebuilt integer power of a sum is made without sympy's
    evaluation, which gives that same node: for a sum with a symbol in it and an integer exponent
    other than 0 and 1, ``Pow`` evaluates only through ``Add._eval_power``, which rewrites nothing
    without the imaginary unit in the sum — and a real rational form has none, nor can one appear
    by substituting such forms — but first asks whether either term of a two-term sum is
    infinite: a query of sympy's assumptions through the whole new subtree (two thirds of the time
    of the stylization kernel's delta pieces' Newton–Cotes sums, :func:`newton_cotes`)."""
    e = sp.sympify(e)
    if rational is None:
        rational = rational_form(e) and all(rational_form(sp.sympify(r)) for r in rule.values())
    memo: dict = {}

    def go(node):
        if not node.args:  # (atoms are not memoized: equal Floats of other precisions stay as they are)
            return rule.get(node, node)
        hit = memo.get(node)
        if hit is not None:
            return hit
        if node in rule:
            out = rule[node]
        else:
            args = tuple(go(a) if isinstance(a, sp.Basic) else a for a in node.args)
            if all(a is b for a, b in zip(args, node.args)):
                out = node
            elif rational and isinstance(node, sp.Pow) and isinstance(args[0], sp.Add):
                out = sp.Pow(*args, evaluate=False)  # (an Integer exponent, not 0 or 1: unchanged)
            else:
                out = node.func(*args)
        memo[node] = out
        return out

    return go(e)


def rational_form(e) -> bool:
    """Whether ``e`` is built from real symbols and rationals by +, ·, integer powers other than 0
    and 1, and ``Abs`` (no imaginary unit can come out of sympy's evaluation of such a form with
    other such forms substituted), each distinct subtree looked at once."""
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, sp.Symbol):
            if node.is_real is not True:
                return False
        elif isinstance(node, sp.Pow):
            if not (node.exp.is_Integer and node.exp not in (0, 1)):
                return False
            if id(node.base) not in seen:
                seen.add(id(node.base))
                stack.append(node.base)
        elif isinstance(node, (sp.Add, sp.Mul, sp.Abs)):
            for a in node.args:
                if id(a) not in seen:
                    seen.add(id(a))
                    stack.append(a)
        elif not isinstance(node, sp.Rational):
            return False
    return True


def exact_at(e, at: dict):
    """``e`` at the point as a Fraction when it is rational there, else None."""
    z = sp.sympify(e).xreplace(at)
    if isinstance(z, sp.Rational):
        return Fraction(int(z.p), int(z.q))
    return None
