"""``langur render FILE --grid px=0:0.99:100,py=0:0.99:100 [--wrt NAME]``: a program over a grid of
two of its parameters, as an image (paper §10.1, Fig. 13).

Each grid point is one evaluation of the program (an image's pixel, its position among the
parameters): the Monte Carlo engine evaluates all of them in one batch
(:func:`langur.operational.batch.estimate_batch`); with ``--exact``, the exact engine too, one
closed form per parameter cell (:func:`langur.exact_batch.exact_batch`), and the two are compared.
With ``--wrt``, the derivative image stands next to standard AD's: the line standard AD misses is
the point.  ``--npz`` keeps the arrays; ``-o`` draws them (the ``plot`` extra).
"""

from __future__ import annotations

import importlib
import math
import sys
import time

import numpy as np

from .. import progress
from ..cli import UsageError, add_common, add_timeout, samples, seed
from ..operational.batch import estimate_batch
from ..operational.sample import METHODS, spread
from . import _common as c
from ._outputs import inputs_of, output_file, picture_file, writing

#: Most grid points per axis, and most samples in all (points × samples per point).
MAX_AXIS = 2000
MAX_TOTAL = 50_000_000


def add_arguments(p):
    p.add_argument("file", metavar="FILE", help="a .lgr file with a program")
    p.add_argument("--grid", required=True, metavar="X=START:STOP:N,Y=START:STOP:N",
                   help="two parameters swept over N evenly spaced values from START to STOP each: "
                   "the first along the image's columns, the second along its rows (row 0 at the top)")
    p.add_argument("--wrt", metavar="NAME", help="also the derivative with respect to this parameter")
    p.add_argument("--dir", action="append", metavar="NAME=VALUE", help="a direction γ' instead of --wrt")
    p.add_argument("-o", "--out", metavar="OUT.png", help="draw the images (needs the plot extra)")
    p.add_argument("--npz", metavar="OUT.npz", help="save the arrays (numpy .npz)")
    p.add_argument("--exact", action="store_true",
                   help="also the exact engine's image (one closed form per parameter cell), compared")
    add_common(p)
    p.add_argument("--samples", type=samples(), default=64, metavar="N",
                   help="Monte Carlo samples per grid point (default 64)")
    p.add_argument("--seed", type=seed, default=0, metavar="S", help="random seed (same seed, same image)")
    p.add_argument("--method", choices=METHODS, default="uniform", help="Monte Carlo design")
    add_timeout(p, "render", "for the whole command, in seconds")


def parse_grid(text: str, declared) -> list[tuple[str, np.ndarray]]:
    """``px=0:0.99:100,py=0:0.99:100`` → [(name, values)]; exactly two distinct declared params."""
    axes = []
    for part in [s.strip() for s in text.split(",") if s.strip()]:
        name, eq, spec = part.partition("=")
        bits = spec.split(":")
        if not eq or len(bits) != 3:
            raise UsageError(f"--grid expects NAME=START:STOP:N, got {part!r}")
        name = name.strip()
        if name not in declared:
            raise UsageError(f"--grid {name}: no such parameter (declared: {', '.join(declared) or 'none'})")
        try:
            start, stop, n = float(bits[0]), float(bits[1]), int(bits[2])
        except ValueError:
            raise UsageError(f"--grid {name}: {spec!r} is not START:STOP:N (two numbers, one count)") from None
        if not (math.isfinite(start) and math.isfinite(stop)):
            raise UsageError(f"--grid {name}: the ends must be finite numbers")
        if not 1 <= n <= MAX_AXIS:
            raise UsageError(f"--grid {name}: N must be between 1 and {MAX_AXIS}, got {n}")
        axes.append((name, _evenly(start, stop, n)))
    if len(axes) != 2 or axes[0][0] == axes[1][0]:
        raise UsageError("--grid needs two different parameters (an image has two axes)")
    return axes


def _evenly(start: float, stop: float, n: int) -> np.ndarray:
    """``n`` evenly spaced values from ``start`` to ``stop``: numpy's ``linspace``, which steps by
    (stop − start)/(n − 1) — ∞ for ends as far apart as −1e308 and 1e308, its points then NaN (an
    internal error, bench/history/2026-11-29.md#hostile33 — unless that step is no double; then the
    points start·(1 − u) + stop·u (``operational.sample.spread``)."""
    if math.isfinite(stop - start):
        return np.linspace(start, stop, n)
    return spread(np.float64(start), np.float64(stop), np.linspace(0.0, 1.0, n))


def _summary(a: np.ndarray) -> dict:
    finite = a[np.isfinite(a)]
    if not finite.size:
        return {"min": None, "max": None, "mean": None, "nan": int(a.size)}
    return {"min": float(finite.min()), "max": float(finite.max()), "mean": float(finite.mean()),
            "nan": int(a.size - finite.size)}


def run(args) -> int:
    loaded = c.load(args)
    c.require_program(loaded, args.file)
    (xn, xs), (yn, ys) = parse_grid(args.grid, loaded.params)
    if xs.size * ys.size * args.samples > MAX_TOTAL:
        raise UsageError(f"{xs.size} × {ys.size} points × {args.samples} samples is more than {MAX_TOTAL:,} "
                         "samples in all: fewer points or fewer --samples")
    inputs = inputs_of(args, loaded)
    npz = _npz_path(args.npz) if args.npz else None
    for option, given, path in (("-o", args.out, args.out), ("--npz", args.npz, npz)):
        if given:
            refusal = f"{given}: refusing to write over a program"
            if given.endswith(".lgr"):
                raise UsageError(refusal)
            if option == "-o":
                args.out = picture_file(path, inputs, option, refusal)  # (pic: pic.png, the file written)
            else:
                output_file(path, inputs, option, refusal)
    if args.out and not all(map(math.isfinite, _extent(xs, ys))):  # (matplotlib: an internal error)
        raise UsageError(f"-o {args.out}: the picture's axes would reach beyond the largest double (±1.8e308): "
                         "narrower --grid ranges, or --npz for the arrays")
    painter = _painter() if args.out else None
    base = {k: float(v) for k, v in c.param_values(args, loaded).items() if k not in (xn, yn)}
    direction = c.direction(args, loaded) if (args.wrt or args.dir) else None
    X, Y = np.meshgrid(xs, ys)  # rows: the second parameter; columns: the first
    grid = {**base, xn: X.ravel(), yn: Y.ravel()}
    shape = X.shape
    t = time.perf_counter()
    with progress.phase(f"Monte Carlo over {X.size} points"):
        mc = estimate_batch(loaded, grid, direction=direction, samples=args.samples, seed=args.seed,
                            method=args.method)
    mc_seconds = time.perf_counter() - t
    arrays = {xn: xs, yn: ys, "value": mc.value.reshape(shape), "value_stderr": mc.stderr.reshape(shape)}
    if direction is not None:
        arrays.update(derivative=mc.derivative.reshape(shape), derivative_stderr=mc.derivative_stderr.reshape(shape),
                      standard_ad=mc.regular.reshape(shape), boundary=mc.boundary.reshape(shape))
    report = {"grid": {xn: [float(xs[0]), float(xs[-1]), int(xs.size)], yn: [float(ys[0]), float(ys[-1]), int(ys.size)]},
              "at": base, "samples": args.samples, "seed": args.seed, "method": args.method,
              "mc_seconds": round(mc_seconds, 3), "value": _summary(mc.value)}
    if direction is not None:
        report.update(direction={k: v for k, v in direction.items() if v}, derivative=_summary(mc.derivative),
                      standard_ad=_summary(mc.regular))
    if mc.notes:
        report["notes"] = list(mc.notes)
    if args.exact:
        report["exact"] = _exact(loaded, grid, direction, mc, shape, arrays)
    written = []
    if npz:
        with writing(npz, "--npz"):
            np.savez_compressed(npz, **arrays)
        written.append(npz)
    if painter is not None:
        with progress.phase("drawing"):
            with writing(args.out, "-o"):
                written.append(_draw(painter, args, arrays, direction, (xn, yn), xs, ys))
    report["written"] = written
    if args.json:
        c.dump_json(report)
    else:
        _print(args, report, X.size)
    sys.stdout.flush()
    return 0


def _npz_path(path: str) -> str:
    """The file ``numpy.savez_compressed(path)`` writes: ``.npz`` appended when missing."""
    return path if path.endswith(".npz") else path + ".npz"


def _exact(loaded, grid, direction, mc, shape, arrays) -> dict:
    """The exact engine's image (:mod:`langur.exact_batch`: sympy, imported only when asked) and
    how far the Monte Carlo image is from it, in standard errors."""
    from ..exact_batch import exact_batch  # sympy (0.8 s): only with --exact
    t = time.perf_counter()
    with progress.phase("exact engine over the grid (sympy)"):
        ex = exact_batch(loaded.program, grid, direction)
    out = {"seconds": round(time.perf_counter() - t, 3), "derivations": ex.derivations,
           "closed_form_points": int(ex.closed.sum()), "missing": ex.missing, "value": _summary(ex.value),
           "undefined": len(ex.undefined)}
    if ex.undefined:  # the integral does not exist there (NaN in the exact image): say so, and why
        out["undefined_reason"] = ex.undefined[min(ex.undefined)]
    arrays["exact_value"] = ex.value.reshape(shape)
    pairs = [("value", mc.value, mc.stderr, ex.value)]
    if direction is not None:
        arrays["exact_derivative"] = ex.derivative.reshape(shape)
        out["derivative"] = _summary(ex.derivative)
        pairs.append(("derivative", mc.derivative, mc.derivative_stderr, ex.derivative))
    for name, m, se, e in pairs:
        out.update(_compared(name, m, se, e))
    return out


def _compared(name: str, m, se, e) -> dict:
    """How far the Monte Carlo image ``m`` (standard errors ``se``) is from the exact one ``e``:
    in standard errors where the SE is positive (``NAME_max_z``, ``NAME_beyond_5se``), and where it
    is 0 — every sample alike, most often all 0 because none hit the region — by equality up to
    10⁻¹²·(1 + |exact|) (``NAME_se_zero`` points, ``NAME_se_zero_differ`` of them differ: an SE of 0
    bounds nothing, and such a point was left out of the comparison, which then read "MC within
    0 SE"; as ``langur.commands._common.agreement`` for one point)."""
    ok = np.isfinite(m) & np.isfinite(e)
    positive, zero = ok & (se > 0), ok & (se == 0)
    z = np.abs(m - e)[positive] / se[positive]
    differ = np.abs(m - e)[zero] > 1e-12 * (1 + np.abs(e[zero]))
    return {f"{name}_max_z": float(z.max()) if z.size else 0.0, f"{name}_beyond_5se": int(np.count_nonzero(z > 5)),
            f"{name}_compared_se": int(z.size), f"{name}_se_zero": int(np.count_nonzero(zero)),
            f"{name}_se_zero_differ": int(np.count_nonzero(differ)),
            f"{name}_compared": int(np.count_nonzero(ok))}  # both finite (where the exact one is undefined, no point)


def _painter():
    try:
        return importlib.import_module("viz.images")
    except ImportError as e:
        raise UsageError(f"-o needs the plot extra ({e.name or e}): pip install -e '.[plot]'") from None


def _extent(xs: np.ndarray, ys: np.ndarray) -> tuple[float, float, float, float]:
    """The picture's axes: each grid point a cell one step wide (∞ for ends beyond the doubles)."""
    with np.errstate(over="ignore", invalid="ignore"):
        dx = (xs[-1] - xs[0]) / (len(xs) - 1) if len(xs) > 1 else 1.0
        dy = (ys[-1] - ys[0]) / (len(ys) - 1) if len(ys) > 1 else 1.0
        return float(xs[0]), float(xs[-1] + dx), float(ys[0]), float(ys[-1] + dy)


def _draw(images, args, arrays, direction, names, xs, ys) -> str:
    extent = _extent(xs, ys)
    row = [images.Panel("value (Monte Carlo)", arrays["value"], scale="value")]
    if "exact_value" in arrays:
        row.append(images.Panel("value (exact)", arrays["exact_value"], scale="value"))
    rows = [row]
    if direction is not None:
        wrt = ", ".join(k for k, v in direction.items() if v)
        drow = [images.Panel(f"d/d{wrt} (Monte Carlo)", arrays["derivative"], True, "d"),
                images.Panel("standard AD (deltas dropped)", arrays["standard_ad"], True, "d")]
        if "exact_derivative" in arrays:
            drow.insert(1, images.Panel(f"d/d{wrt} (exact)", arrays["exact_derivative"], True, "d"))
        rows.append(drow)
    return images.save(rows, extent, names, args.out, f"{args.file}: {args.samples} samples per point")


def _agreement(e: dict, name: str, npoints: int) -> str:
    """The Monte Carlo image against the exact one (:func:`_compared`), saying on how many points."""
    if e[f"{name}_compared"] == 0:
        return "compared with MC at no point (none where both are finite)"
    where = "" if e[f"{name}_compared"] == npoints else f"at the {e[f'{name}_compared']} points where both are finite: "
    said = []
    if e[f"{name}_compared_se"]:
        said.append(f"MC within {e[f'{name}_max_z']:.2g} SE at {e[f'{name}_compared_se']} point(s) "
                    f"(beyond 5 SE: {e[f'{name}_beyond_5se']})")
    zero, differ = e[f"{name}_se_zero"], e[f"{name}_se_zero_differ"]
    if zero:
        said.append(f"MC's SE is 0 at {zero} point(s) (every sample alike), compared for equality: "
                    + (f"{differ} differ (MC saw no variation there: give more samples)" if differ else "all equal"))
    return where + ("; ".join(said) or "no point to compare")


def _print(args, report: dict, npoints: int) -> None:
    (xn, gx), (yn, gy) = report["grid"].items()
    print(f"{args.file}: {npoints} points, {xn} in [{gx[0]:g}, {gx[1]:g}] ({gx[2]}) × {yn} in [{gy[0]:g}, {gy[1]:g}] "
          f"({gy[2]}), {args.samples} samples each, {report['mc_seconds']:g} s")
    v = report["value"]
    print(f"  value       : {c.fmt(v['min'])} to {c.fmt(v['max'])}" if v["min"] is not None else "  value: undefined")
    if "derivative" in report:
        d, s = report["derivative"], report["standard_ad"]
        print(f"  derivative  : {c.fmt(d['min'])} to {c.fmt(d['max'])}")
        print(f"  standard AD : {c.fmt(s['min'])} to {c.fmt(s['max'])}   (deltas dropped)")
    if "exact" in report:
        e = report["exact"]
        parts = [f"{e['derivations']} derivation(s), {e['closed_form_points']} points by closed form"]
        if e["undefined"]:
            parts[0] += f", undefined at {e['undefined']} of {npoints} points ({e['undefined_reason']})"
        for name in ("value", "derivative"):
            if f"{name}_max_z" in e:
                parts.append(f"{name}: " + _agreement(e, name, npoints))
        print(f"  exact       : {'; '.join(parts)}")
    for note in report.get("notes", []):
        print(f"  note: {note}")
    for path in report["written"]:
        print(path)
