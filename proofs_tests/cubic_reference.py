"""The separable cubic's independent reference for the fold tests (issue 18; test_folds_issue18.py,
test_folds3d_issue18.py): g(t) = t³ − t and L(c) = |{z ∈ [−1, 1] : g(z) ≥ c}|, the length of the
set where the cubic is above c, from its trigonometric roots (no engine involved)."""

from __future__ import annotations

import math

M = 2 / (3 * math.sqrt(3))  # the largest value of g on [-1, 1], at -1/√3
T = 1 / math.sqrt(3)  # the turning points of g are ±T


def g(t):
    return t**3 - t


def L(c):
    """|{z ∈ [−1, 1] : z³ − z ≥ c}| from the trigonometric roots of z³ − z − c."""
    if c <= -M:
        return 2.0
    if c >= M:
        return 0.0
    th = math.acos(max(-1.0, min(1.0, c / M))) / 3
    r0 = 2 * T * math.cos(th)
    r1, r2 = 2 * T * math.cos(th - 2 * math.pi / 3), 2 * T * math.cos(th + 2 * math.pi / 3)
    r1, r2 = max(r1, r2), min(r1, r2)
    return (r1 - max(r2, -1.0)) + max(0.0, 1.0 - r0)
