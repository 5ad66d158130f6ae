"""The public strategies (`langur.strategies`, issue 13): every drawn program is well-typed (the
front end loads and type-checks it), prints and parses back to the same AST, every listed feature
is actually drawn (counted by looking at the ASTs and at the core the front end makes, not at
what the generator says it did), a deliberately failing property shrinks to a small program, the
same seed gives the same programs, and without hypothesis the import says how to get it."""

import subprocess
import sys
from collections import Counter

from hypothesis import HealthCheck, find, given, seed, settings

from langur import strategies as ls
from langur.core import IfDiffeo, subterms
from langur.fuzz import coverage
from langur.syntax import surface as S
from langur.syntax.parser import parse_module

FAST = settings(max_examples=150, derandomize=True, database=None, deadline=None,
                suppress_health_check=[HealthCheck.too_slow])


def _nodes(t):
    """Every surface node under ``t`` (terms, items, intervals), ``t`` included."""
    stack, out = [t], []
    while stack:
        u = stack.pop()
        if isinstance(u, tuple):
            stack.extend(u)
        elif hasattr(u, "__dataclass_fields__"):
            out.append(u)
            stack.extend(getattr(u, f) for f in u.__dataclass_fields__ if f not in ("span", "name_span"))
    return out


@FAST
@given(ls.programs())
def test_every_drawn_program_loads_type_checks_and_round_trips(g):
    loaded = g.load()  # raises LangurError on any parse, elaboration or type error
    assert loaded.program is not None and set(loaded.params) == {p for p, _ in g.params}
    again = parse_module(g.text, "main.lgr")
    assert (again.items, again.program) == (g.module.items, g.module.program)


@settings(FAST, max_examples=40)
@given(g=ls.programs(modules=True, max_summands=2))
def test_programs_with_modules_load_from_their_files(g, tmp_path_factory):
    loaded = g.load(str(tmp_path_factory.mktemp("m")))
    assert loaded.program is not None
    for name, m in g.libraries:
        assert parse_module(ls.render(m), f"{name}.lgr").items == m.items


def _sample(n=300, sd=4, **shape):
    """The first ``n`` programs hypothesis draws with seed ``sd``."""
    out = []

    @seed(sd)
    @settings(max_examples=n, database=None, deadline=None, suppress_health_check=list(HealthCheck))
    @given(ls.programs(**shape))
    def collect(g):
        out.append(g)

    collect()
    return out


def _conditions(m: S.ModuleS):
    """(lhs, rhs) of every comparison in the module's program (brackets and `if`)."""
    for u in _nodes((m.program, *[i for i in m.items if isinstance(i, S.DefDecl)])):
        if isinstance(u, S.Iverson):
            yield from zip(u.terms, u.terms[1:])
        elif isinstance(u, S.IfCmp):
            yield u.left, u.right


def _names(t):
    return {u.name for u in _nodes(t) if isinstance(u, S.Name)}


def _features(g: ls.Generated, core: bool = True) -> set[str]:
    m, params = g.module, {p for p, _ in g.params} | {"s"}
    variables = {v.name for v in m.program.variables}
    found = {f"{len(variables)} variables"}
    for lhs, rhs in _conditions(m):
        vs, ps = _names((lhs, rhs)) & variables, _names((lhs, rhs)) & params
        squares = {v for u in _nodes(lhs) if isinstance(u, S.BinOp) and u.op == "^" and u.right == S.Num(2)
                   and len(_names(u.left) & variables) == 1 for v in _names(u.left) & variables}
        if any(isinstance(u, S.BinOp) and u.op == "*" and _names(u.left) and _names(u.left) <= params
               and _names(u.right) and _names(u.right) <= variables for u in _nodes(lhs)):
            found.add("parameter coefficient")
        if isinstance(lhs, S.Name) and lhs.name in variables and _names(rhs) & variables - {lhs.name}:
            found.add("graph")
        if isinstance(lhs, S.Apply) and lhs.name in ("exp", "log", "atan", "tanh", "sqrt") and vs:
            found.add(f"monotone {lhs.name}")
        if len(squares & variables) >= 2 and vs == squares & variables:
            found.add("circle")
        if isinstance(lhs, S.Apply) and lhs.name in ("abs", "min", "max"):
            found.add("kink condition")
        if not vs and ps:
            found.add("condition on parameters")
    for u in _nodes(m.program.body):
        if isinstance(u, S.IfCmp) and any(isinstance(b, (S.IfCmp, S.IfGe0S)) for b in (u.then, u.orelse)):
            found.add("nested conditional")
        if isinstance(u, S.Iverson) and len(u.ops) == 2:
            found.add("window")
    if isinstance(m.program.body, S.LetIn) and not _names(m.program.body.bound) - params:
        found.add("let of a parameter term")
    if any(_names((i.lo, i.hi)) & params for i in m.program.domain):
        found.add("parametric bound")
    for item in m.items:
        if isinstance(item, S.DiffeoDecl):
            found.add(f"declared {item.name.name}")
        elif isinstance(item, S.DefDecl):
            found.add("def")
        elif isinstance(item, S.ImportItem):
            found.add("module")
    # what the front end made of it (Fig. 8's completion kinds)
    for t in subterms(g.load().program.body) if core else ():
        if isinstance(t, IfDiffeo):
            found.add(coverage.completion_kind(t.psi))
    return found


FEATURES = {"1 variables", "2 variables", "3 variables", "parameter coefficient", "graph", "circle",
            "monotone exp", "monotone log", "monotone atan", "monotone tanh", "monotone sqrt", "kink condition",
            "condition on parameters", "nested conditional", "window", "let of a parameter term",
            "parametric bound", "declared sh", "declared rot", "declared cub", "def", "module",
            *coverage.COMPLETIONS}


def test_each_listed_feature_is_generated():
    counts = Counter(f for g in _sample(500, modules=True) for f in _features(g))
    # (seed 4: every feature at least 3 times; seed 2 never draws tanh: the threshold is not slack)
    rare = {f: counts[f] for f in FEATURES if counts[f] < 2}
    assert not rare, f"features drawn fewer than twice in 500 programs: {rare}\n{counts}"


def _size(t) -> int:
    return len(_nodes(t))


def test_a_failing_property_shrinks_to_a_small_program():
    # the property "no program has a circle" fails; hypothesis's counterexample is one disk
    def has_circle(g):
        return "circle" in _features(g, core=False)

    shrinking = settings(database=None, max_examples=2000, derandomize=True, deadline=None)
    g = find(ls.programs(), has_circle, settings=shrinking)
    m = g.module
    assert len(m.program.variables) == 2 and len(g.params) == 1, g.text
    assert [type(i) for i in m.items] == [S.ParamItem], g.text  # no def, no diffeo, no import
    # small, if not always minimal (hypothesis's shrinker may leave a factor `x + 0.5` or two)
    assert len(list(_conditions(m))) == 1 and _size(m.program.body) <= 20, g.text
    assert not any(isinstance(u, (S.LetIn, S.IfCmp, S.Apply)) for u in _nodes(m.program.body)), g.text
    # and a declared rotation: the declaration, one parameter, two variables, one conditional
    g = find(ls.programs(), lambda g: "declared rot" in _features(g, core=False), settings=shrinking)
    assert len(g.module.program.variables) == 2 and len(g.params) == 1, g.text
    assert [type(i) for i in g.module.items] == [S.ParamItem, S.DiffeoDecl], g.text
    assert _size(g.module.program.body) <= 20 and not list(_conditions(g.module)), g.text


def test_the_same_seed_gives_the_same_programs():
    first, again = ([g.text for g in _sample(40)] for _ in range(2))
    assert first == again

    other = []

    @seed(3)
    @settings(max_examples=40, database=None, deadline=None, suppress_health_check=list(HealthCheck))
    @given(ls.texts())
    def collect(t):
        other.append(t)

    collect()
    assert other != first


@settings(FAST, max_examples=10)
@given(ls.cores(max_variables=1))
def test_cores_are_loaded_programs(loaded):
    assert loaded.program is not None and len(loaded.program.box) == 1


def test_without_hypothesis_the_import_says_how_to_install_it_and_the_core_never_imports_it():
    code = ("import sys; sys.modules['hypothesis'] = None\n"
            "import langur, langur.fuzz, langur.cli, langur.frontend\n"
            "assert 'langur.strategies' not in sys.modules\n"
            "try:\n    import langur.strategies\nexcept ImportError as e:\n    print(e)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "langur.strategies needs hypothesis" in r.stdout and "pip install hypothesis" in r.stdout


def test_the_documented_example_runs():
    # docs/strategies.md points at this file as the runnable example for other test suites
    import importlib.util

    from paths import EXAMPLES

    spec = importlib.util.spec_from_file_location("strategies_example", EXAMPLES / "strategies_example.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    example.test_core_json_gives_every_program_back()
    example.test_the_estimate_is_finite()
