"""The core language Langur (paper §4; LANGUAGE.md §1), shared by every engine.

    t, s, r ::= c | x | z | t + s | t · s | f(t) | t ^ k
              | ifge0 t then s else r          -- t variable-free
              | ifge0 ⌊Ψ⌋ then s else r        -- Ψ a C¹ diffeomorphism in the variables
              | let z = t in s                 -- t variable-free
    p       ::= int t d(x1, …, xn)

The modules, each importing only those above it in this list:

* :mod:`.attributes` — what a node keeps about itself, computed once when it is built (free
  variables and parameters, size, depth, small exact value, typing's premises; issue 15);
* :mod:`.slots` — term nodes stored in slots, without a ``__dict__`` per node (issue 15);
* :mod:`.sharing` — terms shared after inlining (§9) are DAGs: hashes kept, equality and passes
  (:func:`shared`) once per distinct node;
* :mod:`.terms` — §4.1: the term nodes (``Const`` … ``ImplicitRoot``; ``Diffeo`` with its inverse
  branches, ``InverseBranch``), ``Term``, their :func:`children`;
* :mod:`.shapes` — nodes built from a node of the same shape (a loop's copies, issue 15);
* :mod:`.structural` — small constructors (:func:`const`, :func:`neg`, :func:`product`, …),
  generic traversals (:func:`subterms`, :func:`substitute`, :func:`map_children`, …) and the
  readers of the kept attributes (:func:`free_vars`, :func:`tree_size`, …);
* :mod:`.programs` — §4.2: ``Program`` and the intervals of its domain (``Interval``).

Here: every public name of these modules, as the rest of langur imports them
(``from langur.core import Add``).  Besides its fields, every term node ``t`` has these public
attributes, read only (a node is frozen) and read in place by the passes that visit every node
(one attribute access where a reader function would cost a call per node):

* ``t.shape``: the tuple of what :mod:`.attributes` keeps about its shape, read at the indices
  exported here (``t.shape[SMOOTH]``, :data:`FV` … :data:`DFP`), as the engines, the front end and
  the type system do; elsewhere the readers of :mod:`.structural` (``smooth(t)``,
  ``free_vars(t)``, …) say the same;
* ``t.small`` and ``t.small_all``: what :func:`small_value` and :func:`all_small` return (the
  front end's linear forms and loop template read them);
* two memos written after the node is built, each only by its writer: ``t.typed``, the contexts
  the type system found ``t`` well typed in (:func:`keep_typed`), and ``t.memo``, the engines' dict
  of facts derived from ``t`` (``None`` until :func:`keep_memo` keeps one).

A node's other attribute (``_hash``) is the core's own.  A ``Diffeo`` keeps what the front end
solved to complete it by :func:`keep_solved`, read back by :func:`kept_solved`.
"""

from .attributes import (
    BINDERS,
    CALLS,
    DEPTH,
    DFP,
    FP,
    FV,
    INT_FRACTIONS,
    MINUS_ONE,
    OPS,
    PSI_VARS,
    SCOPED,
    SIZE,
    SMALL,
    SMALL_BITS,
    SMALL_EXPONENT,
    SMOOTH,
    index_power_small,
    int_fraction,
    kept_attributes,
    small_power,
)
from .programs import Interval, Program
from .shapes import (
    index_const,
    like,
    like_binary,
    like_binary_many,
    like_leaf,
    like_power,
    same_shape,
    shape_of,
    shape_with_span,
)
from .sharing import REPR_LIMIT, shared
from .slots import keep_memo, keep_typed
from .structural import (
    all_small,
    const,
    depth,
    diffeo_params,
    diffeo_variables,
    div,
    extend_diffeo,
    free_params,
    free_vars,
    has_calls,
    map_children,
    map_children_kept,
    neg,
    own_root,
    product,
    refusals_located,
    small_value,
    smooth,
    sub,
    substitute,
    substitute_diffeo,
    subterms,
    tree_size,
)
from .terms import (
    PI,
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    TooManyRoots,
    Var,
    children,
    keep_solved,
    kept_solved,
)

__all__ = [
    "BINDERS", "CALLS", "DEPTH", "DFP", "FP", "FV", "OPS", "PSI_VARS", "SCOPED", "SIZE", "SMOOTH",
    "INT_FRACTIONS", "MINUS_ONE", "PI", "REPR_LIMIT", "SMALL", "SMALL_BITS", "SMALL_EXPONENT", "Add", "Call", "Const", "Diffeo",
    "IfDiffeo", "IfGe0", "ImplicitRoot", "Interval", "InverseBranch", "Let", "Mul", "Param", "Pow", "Prim", "Program",
    "Term", "TooManyRoots", "Var", "all_small", "children", "const", "depth", "diffeo_params", "diffeo_variables", "div",
    "extend_diffeo", "free_params", "free_vars", "has_calls", "index_const", "index_power_small", "int_fraction", "keep_memo", "keep_solved", "keep_typed", "kept_attributes",
    "kept_solved", "like",
    "like_binary", "like_binary_many", "like_leaf", "like_power", "map_children", "map_children_kept", "neg", "own_root", "product", "refusals_located", "same_shape",
    "shape_of", "shape_with_span", "shared", "small_power", "small_value", "smooth", "sub", "substitute",
    "substitute_diffeo", "subterms", "tree_size",
]
