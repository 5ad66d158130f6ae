"""Whether an integrand is integrable on its region (the analysis: :mod:`.zerosets`, moved here whole
before it is split into modules with one job each)."""

from .zerosets import (
    DIRECTIONS,
    GRID,
    TIME_LIMIT,
    ZERO_FREE_DEGREE,
    Blowup,
    Divergent,
    Region,
    Undecidable,
    Verdict,
    blowups,
    decide,
    divergence,
    finite_on_box,
    growth,
    piece_blowups,
    pole_bases,
    sites,
)

__all__ = ["DIRECTIONS", "GRID", "TIME_LIMIT", "ZERO_FREE_DEGREE", "Blowup", "Divergent", "Region", "Undecidable",
           "Verdict", "blowups", "decide", "divergence", "finite_on_box", "growth", "piece_blowups", "pole_bases",
           "sites"]
