"""Using `langur.strategies` from another test suite (docs/strategies.md): run it with
``pytest examples/strategies_example.py``.

Two properties of the kind a tool built on Langur would check: a serializer (here Langur's own
`langur-core` JSON format, docs/engines.md) gives every well-typed program back unchanged, and a
Monte Carlo estimator (here Langur's) returns a finite value with a standard error on each.
"""

import math

from hypothesis import given, settings

from langur import core_json, operational
from langur import strategies as ls


@settings(max_examples=25, deadline=None)
@given(ls.programs(max_variables=2, light=True))
def test_core_json_gives_every_program_back(g):
    loaded = g.load()                             # the front end: a type-checked core program
    params = loaded.param_values()
    program, again = core_json.loads(core_json.dumps(loaded.program, params))
    assert program == loaded.program and again == params


@settings(max_examples=10, deadline=None)
@given(ls.programs(max_variables=2, max_summands=1, light=True))
def test_the_estimate_is_finite(g):
    loaded = g.load()
    at = {p: float(v) for p, v in loaded.param_values().items()}
    est = operational.estimate_value(loaded, at, samples=500, seed=0)
    assert math.isfinite(est.value) and est.stderr >= 0, g.text   # g.text: the `.lgr` source
