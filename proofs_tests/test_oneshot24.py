"""One-shot start-up, fifth round (issue 15): what the instruction count leaves out — memory touched.

* ``langur.operational.pcg64.Stream`` draws ``numpy.random.default_rng(seed)``'s doubles without
  importing ``numpy.random`` (nine compiled modules and OpenSSL): compared here with numpy's own
  generator draw for draw — seeds at the edges of SeedSequence's 32-bit words, shapes across the
  block's rows and lanes, successive calls, the hand-over to numpy's generator (``Stream.numpy``,
  and a call beyond ``MOST_DRAWS``), and every design of ``operational.sample``;
* the one-shot process imports neither ``numpy.random`` nor ``json`` nor ``hashlib`` (OpenSSL: the
  front end keys modules by their bytes, the parser compares the grammar's text), and imports numpy before the
  front end (at a shallow depth of nested imports: ``commands/_common``'s comment says why).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from langur.operational import pcg64
from langur.operational.pcg64 import Stream, numpy_generator, seeded
from langur.operational.sample import design

ROOT = Path(__file__).resolve().parents[1]

SEEDS = [0, 1, 2, 7, 42, 1234, 2**31 - 1, 2**32 - 1, 2**32, 2**32 + 1, 2**63, 2**64 - 1, 98765432109876543210,
         2**128 + 3]
SHAPES = [(10000, 1), (10000, 2), (1,), (2,), (15,), (16,), (17,), (255,), (256,), (257,), (3, 5, 2), (1000, 3),
          (4, 0), 5]


@pytest.mark.parametrize("seed", SEEDS)
def test_the_seeded_state_is_numpys(seed):
    state = np.random.default_rng(seed).bit_generator.state["state"]
    assert seeded(seed) == (state["state"], state["inc"])


@pytest.mark.parametrize("seed", SEEDS)
def test_the_draws_are_numpys_bit_for_bit_call_after_call(seed):
    ours, theirs = Stream(seed), np.random.default_rng(seed)
    for shape in SHAPES:
        a, b = ours.random(shape), theirs.random(shape)
        assert a.shape == b.shape and a.dtype == b.dtype == np.float64
        assert np.array_equal(a, b), (seed, shape)
        assert a.tobytes() == b.tobytes()


def test_random_draws_of_random_sizes_against_numpy():
    sizes = np.random.default_rng(2024).integers(1, 3000, size=40)
    for seed, n in enumerate(sizes):
        ours, theirs = Stream(seed), np.random.default_rng(seed)
        for _ in range(3):
            assert np.array_equal(ours.random(int(n)), theirs.random(int(n)))


def test_the_hand_over_to_numpys_generator_continues_the_stream():
    ours, theirs = Stream(5), np.random.default_rng(5)
    assert np.array_equal(ours.random(300), theirs.random(300))
    gen = ours.numpy()
    assert isinstance(gen, np.random.Generator) and ours.numpy() is gen and numpy_generator(ours) is gen
    assert gen.bit_generator.seed_seq.entropy == 5  # (what scipy's Sobol spawns its generators from)
    assert np.array_equal(gen.random(7), theirs.random(7))
    assert np.array_equal(ours.random((20, 2)), theirs.random((20, 2)))  # (drawn by numpy's from now on)
    assert np.array_equal(gen.integers(0, 10**9, size=5), theirs.integers(0, 10**9, size=5))
    g = np.random.default_rng(1)
    assert numpy_generator(g) is g


def test_a_large_call_is_drawn_by_numpy_with_the_same_numbers():
    n = pcg64.MOST_DRAWS + 1
    ours, theirs = Stream(3), np.random.default_rng(3)
    assert np.array_equal(ours.random(10), theirs.random(10))
    assert np.array_equal(ours.random(n), theirs.random(n))
    assert ours._numpy is not None  # handed over
    assert np.array_equal(ours.random(4), theirs.random(4))
    ours, theirs = Stream(4), np.random.default_rng(4)  # many calls adding up to more
    for _ in range(pcg64.MOST_DRAWS // 30000 + 1):
        assert np.array_equal(ours.random((10000, 3)), theirs.random((10000, 3)))
    assert ours._numpy is not None


def test_a_negative_seed_is_refused_as_numpy_refuses_it():
    with pytest.raises(ValueError):
        np.random.default_rng(-1)
    with pytest.raises(ValueError):
        Stream(-1)


@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
@pytest.mark.parametrize("m", [1, 2, 3])
def test_every_design_is_the_same_from_either_generator(method, m):
    for seed in (0, 9):
        ours, theirs = Stream(seed), np.random.default_rng(seed)
        for samples in (10000, 37):
            a, b = design(ours, m, samples, method), design(theirs, m, samples, method)
            assert a.method == b.method and a.groups == b.groups
            assert np.array_equal(a.points, b.points), (method, m, seed, samples)


ONE_SHOT = """
import sys
from langur.cli import main
status = main(sys.argv[1:])
names = list(sys.modules)
imported = [m for m in ("numpy.random", "json", "secrets", "hashlib") if m in sys.modules]
import json
print(json.dumps({"status": status, "imported": imported,
                  "numpy_first": names.index("numpy") < names.index("langur.frontend")}))
"""


def test_the_one_shot_process_imports_no_numpy_random_nor_json():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-P", "-c", ONE_SHOT, "eval", "examples/fig1.lgr", "--engine", "mc"],
                         capture_output=True, text=True, env=env, cwd=ROOT, timeout=120, check=True).stdout
    lines = out.strip().splitlines()
    assert json.loads(lines[-1]) == {"status": 0, "imported": [], "numpy_first": True}
    # the number is the one numpy's generator gives (the engine with default_rng(0), in this process)
    from langur import frontend
    from langur.operational import estimate

    loaded = frontend.load_bytes((ROOT / "examples/fig1.lgr").read_bytes(), "examples/fig1.lgr")
    params = loaded.param_values({})
    ours = estimate.estimate_value(loaded, params, samples=10000, seed=0)
    real = np.random.default_rng
    try:  # the same estimate with numpy's generator in Stream's place
        estimate.Stream = real
        theirs = estimate.estimate_value(loaded, params, samples=10000, seed=0, cache=estimate.CompileCache())
    finally:
        estimate.Stream = Stream
    assert (ours.value, ours.stderr) == (theirs.value, theirs.stderr)
    assert f"{ours.value:.4f} ± {ours.stderr:.4f}" in lines[1]
