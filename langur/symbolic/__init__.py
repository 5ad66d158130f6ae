"""Exact (sympy) machinery behind ``langur.denote`` and ``langur.ddenote``."""
