"""``numpy.random.default_rng(seed)``'s uniform draws without importing ``numpy.random`` (issue 15, start-up).

The Monte Carlo engine's designs draw from ``default_rng(seed)``: numpy's PCG64 (PCG-XSL-RR 128/64,
O'Neill 2014) seeded through its ``SeedSequence``, read by ``Generator.random`` as
``(next64 >> 11) · 2⁻⁵³``.  Importing ``numpy.random`` loads nine compiled modules (and OpenSSL,
``secrets`` → ``hmac`` → ``_hashlib``) and decompresses their docstrings: a one-shot
``langur eval FILE --engine mc`` spent ≈ 16 M instructions, 280 page faults and 2 MB of memory on it
beyond what the draws need.  :class:`Stream` computes the same numbers — the seed sequence's hash
in 32-bit words, the 128-bit linear congruential steps as a block of jumps on uint64 arrays — bit
for bit.  Anything else (the ``qmc`` design's scrambling, a call of more than :data:`MOST_DRAWS`)
goes to numpy's own generator (:meth:`Stream.numpy`), continued from the same state.
``proofs_tests/test_oneshot24.py`` compares the two streams draw for draw.
"""

from __future__ import annotations

import math

import numpy as np

M32 = 0xFFFF_FFFF
M64 = 0xFFFF_FFFF_FFFF_FFFF
M128 = (1 << 128) - 1
#: PCG's default 128-bit multiplier (numpy's ``PCG_DEFAULT_MULTIPLIER_128``).
MULTIPLIER = 0x2360ED051FC65DA44385DF649FCCF645

# SeedSequence's constants (numpy/random/bit_generator.pyx, after Melissa O'Neill's seed_seq_fe).
POOL_SIZE = 4
INIT_A, MULT_A = 0x43B0D7E5, 0x931E8875
INIT_B, MULT_B = 0x8B51F9DD, 0x58F38DED
MIX_MULT_L, MIX_MULT_R = 0xCA01F9DD, 0x4973F715
XSHIFT = 16

#: Most draws a stream computes here: beyond them it hands over to numpy's generator
#: (:meth:`Stream.numpy`), whose compiled loop outruns these array operations once its import is paid
#: for (measured: ≈ 37 µs per thousand draws here, 3 µs there, and ≈ 9 ms of CPU for the import of
#: ``numpy.random``: the crossover is near 2.5·10⁵ draws).
MOST_DRAWS = 100_000


def _words(seed: int) -> list[int]:
    """``SeedSequence``'s entropy words: the integer's 32-bit digits, least significant first."""
    if seed < 0:
        raise ValueError("expected non-negative integer")
    words = [seed & M32] if seed == 0 else []
    while seed > 0:
        words.append(seed & M32)
        seed >>= 32
    return words


def _pool(entropy: list[int]) -> list[int]:
    """``SeedSequence.mix_entropy``: the four pool words."""
    h = INIT_A

    def hashmix(value: int) -> int:
        nonlocal h
        value ^= h
        h = (h * MULT_A) & M32
        value = (value * h) & M32
        return value ^ (value >> XSHIFT)

    def mix(x: int, y: int) -> int:
        r = (MIX_MULT_L * x - MIX_MULT_R * y) & M32
        return r ^ (r >> XSHIFT)

    pool = [hashmix(entropy[i] if i < len(entropy) else 0) for i in range(POOL_SIZE)]
    for src in range(POOL_SIZE):
        for dst in range(POOL_SIZE):
            if src != dst:
                pool[dst] = mix(pool[dst], hashmix(pool[src]))
    for src in range(POOL_SIZE, len(entropy)):
        for dst in range(POOL_SIZE):
            pool[dst] = mix(pool[dst], hashmix(entropy[src]))
    return pool


def _generate(pool: list[int], n_words: int) -> list[int]:
    """``SeedSequence.generate_state(n_words, np.uint32)``."""
    h = INIT_B
    out = []
    for i in range(n_words):
        value = pool[i % POOL_SIZE] ^ h
        h = (h * MULT_B) & M32
        value = (value * h) & M32
        out.append(value ^ (value >> XSHIFT))
    return out


def seeded(seed: int) -> tuple[int, int]:
    """PCG64's ``(state, increment)`` after ``PCG64(SeedSequence(seed))``: the sequence's eight
    words read as four little-endian 64-bit words ``s₀ s₁ i₀ i₁``, then ``pcg_setseq_128_srandom_r``."""
    w = _generate(_pool(_words(int(seed))), 8)
    s0, s1, i0, i1 = (w[2 * k] | (w[2 * k + 1] << 32) for k in range(4))
    inc = ((((i0 << 64) | i1) << 1) | 1) & M128
    state = inc  # 0 · a + inc: the first step from state 0
    state = (state + ((s0 << 64) | s1)) & M128
    return (state * MULTIPLIER + inc) & M128, inc


_32 = np.uint64(32)


class Stream:
    """``numpy.random.default_rng(seed)`` for ``random(size)``: the same doubles, bit for bit."""

    def __init__(self, seed: int):
        self.seed = seed
        self.state, self.inc = seeded(seed)  # the state before the next draw's step
        self.drawn = 0
        self._numpy = None

    def _states(self, n: int) -> tuple:
        """The next ``n`` states' high and low 64 bits (the state is advanced past them), as a block
        of ≈ √n rows of ≈ √n lanes: the first row sᵢ by Python's integers, row r as A_r · sᵢ + C_r
        mod 2¹²⁸ with (A_r, C_r) the jump of r·lanes steps — in uint64, whose products wrap mod 2⁶⁴,
        the high half completed by the carries (the low halves' product's high half from 32-bit
        halves)."""
        lanes = min(n, max(16, math.isqrt(n)))
        first = []
        s, inc = self.state, self.inc
        for _ in range(lanes):
            s = (s * MULTIPLIER + inc) & M128
            first.append(s)
        # the jump of `lanes` steps, s ↦ a·s + c: a = MULTIPLIER^lanes, c = inc · Σ_{j<lanes} MULTIPLIER^j
        # (the geometric sum exactly, modulo (MULTIPLIER − 1)·2¹²⁸ before the division)
        a_step = pow(MULTIPLIER, lanes, 1 << 128)
        modulus = (MULTIPLIER - 1) << 128
        c_step = (((pow(MULTIPLIER, lanes, modulus) - 1) // (MULTIPLIER - 1)) * inc) & M128
        jumps = [(1, 0)]
        for _ in range(-(-n // lanes) - 1):
            a, c = jumps[-1]
            jumps.append(((a * a_step) & M128, (c * a_step + c_step) & M128))
        u64 = np.uint64
        x_lo = np.array([v & M64 for v in first], dtype=u64)[None, :]
        x_hi = np.array([v >> 64 for v in first], dtype=u64)[None, :]
        a_lo = np.array([a & M64 for a, _ in jumps], dtype=u64)[:, None]
        a_hi = np.array([a >> 64 for a, _ in jumps], dtype=u64)[:, None]
        c_lo = np.array([c & M64 for _, c in jumps], dtype=u64)[:, None]
        c_hi = np.array([c >> 64 for _, c in jumps], dtype=u64)[:, None]
        # in place, in five blocks (the memory a draw touches: issue 15, start-up)
        lo = a_lo * x_lo  # mod 2⁶⁴
        lo += c_lo
        hi = a_hi * x_lo
        t, u, v = np.empty_like(hi), np.empty_like(hi), np.empty_like(hi)
        hi += np.less(lo, c_lo, out=t)  # the carry out of the low half
        hi += np.multiply(a_lo, x_hi, out=t)
        hi += c_hi
        # + the high 64 bits of a_lo · x_lo, from four exact 32 × 32-bit products of their halves
        a0, a1, b0, b1 = a_lo & M32, a_lo >> _32, x_lo & M32, x_lo >> _32
        mid = np.multiply(a0, b0, out=t)
        mid >>= _32
        for f, g in ((a0, b1), (a1, b0)):
            p = np.multiply(f, g, out=u)
            hi += np.right_shift(p, _32, out=v)
            p &= M32
            mid += p
        hi += np.multiply(a1, b1, out=u)
        mid >>= _32
        hi += mid
        hi, lo = hi.reshape(-1)[:n], lo.reshape(-1)[:n]
        self.state = (int(hi[-1]) << 64) | int(lo[-1])
        return hi, lo, (t.reshape(-1)[:n], u.reshape(-1)[:n])

    def random(self, size) -> np.ndarray:
        """``Generator.random(size)``: doubles in [0, 1), C order."""
        if self._numpy is not None:
            return self._numpy.random(size)
        shape = (size,) if isinstance(size, int) else tuple(size)
        n = 1
        for k in shape:
            n *= k
        if n == 0:
            return np.empty(shape)
        if self.drawn + n > MOST_DRAWS:
            return self.numpy().random(shape)
        self.drawn += n
        hi, lo, (t, u) = self._states(n)
        x = np.bitwise_xor(hi, lo, out=lo)  # XSL-RR: (hi ⊕ lo) rotated right by hi's top six bits
        rot = np.right_shift(hi, np.uint64(58), out=hi)
        out = np.right_shift(x, rot, out=t)
        rot = np.subtract(np.uint64(64), rot, out=rot)
        rot &= np.uint64(63)
        out |= np.left_shift(x, rot, out=u)
        out >>= np.uint64(11)
        doubles = out.astype(np.float64)
        doubles *= 1.0 / 9007199254740992.0  # 2⁻⁵³
        return doubles.reshape(shape)

    def numpy(self):
        """numpy's ``Generator`` continuing this stream (from then on this stream draws from it)."""
        if self._numpy is None:
            bits = np.random.PCG64(self.seed)  # its SeedSequence(seed) too: scipy's Sobol spawns from it
            bits.state = {"bit_generator": "PCG64", "state": {"state": self.state, "inc": self.inc},
                          "has_uint32": 0, "uinteger": 0}
            self._numpy = np.random.Generator(bits)  # (numpy imports numpy.random here, on first use)
        return self._numpy


def numpy_generator(rng) -> np.random.Generator:
    """numpy's ``Generator`` drawing ``rng``'s stream: ``rng`` itself, or a :class:`Stream`'s
    continuation (for what only numpy's generator does: scipy's scrambled Sobol sequences)."""
    return rng.numpy() if isinstance(rng, Stream) else rng
