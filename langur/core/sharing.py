"""Terms shared after inlining (paper §9: a definition called twice is one subterm reached twice).

A term is then a DAG, and a recursive hash or equality would visit it once per path.  Each node's
hash is computed once and kept; equality compares hashes before fields.  The kept hash is not
pickled (string hashes differ between processes).  :func:`shared` memoizes a pass over such a term
by node identity.  Nothing here names a node class: :mod:`langur.core.terms` and
:mod:`langur.core.programs` apply ``_sharing`` to theirs.
"""

from __future__ import annotations

import functools
import threading

from .attributes import SIZE
from .slots import _keep_hash

_EQUAL = threading.local()


def _sharing(cls, term: bool = False):
    """Give the record class ``cls`` a kept hash, DAG equality, a pickled state without the kept
    attributes and, for a term class (``term``: its nodes are slotted, :mod:`langur.core.slots`,
    keep their size and are pickled by their constructor), a ``repr`` that summarizes a term too
    large to write out."""
    field_hash, field_eq = cls.__hash__, cls.__eq__
    leaf = cls.__name__ in ("Const", "Var", "Param")

    if term:
        def __hash__(self):
            h = self._hash
            if h is None:
                h = field_hash(self)
                _keep_hash(self, h)
            return h
    else:
        def __hash__(self):
            try:
                return self.__dict__["_hash"]
            except KeyError:
                h = field_hash(self)
                object.__setattr__(self, "_hash", h)
                return h

    def __eq__(self, other):
        if self is other:
            return True
        if other.__class__ is not self.__class__:
            return NotImplemented
        if leaf:  # one field to compare: no DAG to guard against
            return field_eq(self, other)
        if hash(self) != hash(other):
            return False
        if (self.shape[SIZE] if term else REPR_LIMIT) < 64:  # small written out: compared as a tree
            return field_eq(self, other)
        # Two DAGs equal node for node: each pair of nodes is compared once (while the outermost
        # comparison runs), not once per path.
        known = getattr(_EQUAL, "pairs", None)
        outer = known is None
        if outer:
            known = _EQUAL.pairs = set()
        try:
            pair = (id(self), id(other))
            if pair in known:
                return True
            equal = field_eq(self, other)
            if equal:
                known.add(pair)
            return equal
        finally:
            if outer:
                _EQUAL.pairs = None

    def __getstate__(self):  # the kept hash, variables and parameters are recomputed
        return {k: v for k, v in self.__dict__.items() if not k.startswith("_")}

    field_repr = cls.__repr__

    def __repr__(self):  # written out, a shared term can have 2^40 nodes
        if term and self.shape[SIZE] > REPR_LIMIT:  # (its tree_size)
            return f"<{cls.__name__}: {self.shape[SIZE]:,} nodes written out>"
        return field_repr(self)

    cls.__hash__, cls.__eq__, cls.__repr__ = __hash__, __eq__, __repr__
    if not term:  # (a term is pickled by its constructor: slots.slotted)
        cls.__getstate__ = __getstate__
    return cls


#: Largest term ``repr`` writes out (nodes); a larger one is summarized.
REPR_LIMIT = 10_000


_SCOPE = threading.local()
_MISSING = object()


def shared(fn):
    """Memoize a recursive pass over terms by the identity of its arguments, while any pass so
    decorated is running (one scope for all of them, opened by the outermost call and dropped when
    it returns): on a term shared after inlining (a DAG), each distinct node is computed once per
    context, not once per path.  The pass must be a function of its arguments: a context that
    changes (a ``let`` binding) is a new argument, never a mutation."""

    @functools.wraps(fn)
    def wrapper(*args):
        tables = getattr(_SCOPE, "tables", None)
        outer = tables is None
        if outer:
            tables = _SCOPE.tables = {}
            _SCOPE.keep = []  # the arguments stay alive, so that their identities stay theirs
        try:
            table = tables.setdefault(wrapper, {})
            key = tuple(map(id, args))
            hit = table.get(key, _MISSING)
            if hit is _MISSING:
                hit = table[key] = fn(*args)
                _SCOPE.keep.append(args)
            return hit
        finally:
            if outer:
                _SCOPE.tables = _SCOPE.keep = None

    return wrapper

