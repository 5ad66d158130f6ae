"""The paper's examples, reproduced with their numbers checked (``langur reproduce``).

Each experiment loads a program from the project's examples (``examples/``), runs both engines, and compares them
with values derived by hand (the derivation is in the comment beside each expected value) or, for
integrals with no elementary hand form, with scipy quadrature of the formula written out here —
never with the output of the engine under test.

* ``fig1``      Fig. 1: ∫₀¹ [x ≤ θ] dx and its derivative; standard AD says 0.
* ``risk``      §2, Fig. 2–3: the risk gradient in a, b, μ, and gradient descent with the correct
                gradient against standard AD, with the paper's settings.
* ``fig9``      Fig. 9: the integrand [y < x + θ](1 + θ + x + y) and its delta ridge.
* ``renderer``  §10.1: one pixel with three swappable shaders; separate compilation recompiles only
                the shader module on a swap; Fig. 13's 100 × 100 images by both engines at once.
* ``raytrace``  §10.2, Fig. 14: a ray-traced triangle with two toon shaders, 40 × 40 pixels per
                colour channel, checked against the scene hand-written in numpy (langur.reference).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import dblquad, quad

from . import exact as api
from . import frontend, operational, reference
from .exact_batch import exact_batch
from .operational.batch import estimate_batch
from .operational.results import Estimate

SIGMAS = 5.0  # Monte Carlo agreement: within 5 standard errors plus a tiny absolute slack
SLACK = 1e-9


@dataclass
class Check:
    what: str
    got: float
    expected: float
    ok: bool
    how: str  # "exact", "mc ± se", "claim"


@dataclass
class Experiment:
    name: str
    title: str
    checks: list[Check] = field(default_factory=list)
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)
    #: What its pictures are drawn from (``viz.paper``): the programs, parameters, descents.
    figures: dict = field(default_factory=dict)

    def close(self, what: str, got: float, expected: float, tol: float = 1e-9) -> None:
        ok = math.isfinite(got) and abs(got - expected) <= tol * max(1.0, abs(expected))
        self.checks.append(Check(what, got, expected, ok, "exact"))

    def mc(self, what: str, est: Estimate, expected: float) -> None:
        got, se = est.value, est.stderr
        ok = math.isfinite(got) and abs(got - expected) <= SIGMAS * se + SLACK
        self.checks.append(Check(what, got, expected, ok, f"mc ± {se:.2g}"))

    def claim(self, what: str, got: float, expected: float, ok: bool) -> None:
        self.checks.append(Check(what, got, expected, bool(ok), "claim"))

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)


def examples_dir() -> Path:
    """The project's own example programs: installed beside the package as ``langur/examples``,
    or, in an editable install, the repository's ``examples/`` folder."""
    here = Path(__file__).resolve().parent
    for cand in (here / "examples", here.parent / "examples"):
        if (cand / "fig1.lgr").is_file():
            return cand
    raise FileNotFoundError(f"the example programs are missing from this installation ({here / 'examples'})")


def _exact_deriv(program, params, wrt):
    return api.exact_deriv(program, params, {k: float(k == wrt) for k in params})


def fig1(samples: int, seed: int) -> Experiment:
    ex = Experiment("fig1", "Fig. 1: d/dθ ∫₀¹ [x ≤ θ] dx")
    loaded = frontend.load(str(examples_dir() / "fig1.lgr"))
    for theta in (0.25, 0.5, 0.75):
        p = {"theta": theta}
        value = api.exact_eval(loaded.program, p)
        ex.close(f"⟦p⟧ at θ={theta} (= θ)", value.value, theta)
        d = _exact_deriv(loaded.program, p, "theta")
        # D_θ θ = 1, all of it from the delta at x = θ; standard AD differentiates each sample: 0.
        ex.close(f"⦇p⦈ at θ={theta} (= 1)", d.value, 1.0)
        ex.close("  boundary part (= 1)", d.boundary, 1.0)
        ex.close("  standard AD (= 0)", d.standard_ad, 0.0)
        ex.mc(f"MC ⟦p⟧ at θ={theta}", operational.estimate_value(loaded, p, samples=samples, seed=seed), theta)
        md = operational.estimate_derivative(loaded, p, {"theta": 1.0}, samples=samples, seed=seed)
        ex.close(f"MC ⦇p⦈ at θ={theta} (one sample on the jump is exact)", md.value, 1.0, tol=1e-12)
        ex.close("MC standard AD (= 0)", md.standard_ad.value, 0.0)
    ex.figures = {"loaded": loaded, "params": {"theta": 0.5}, "wrt": "theta"}
    return ex


def _normal(x, m):
    return math.exp(-0.5 * ((x - m) / 5.0) ** 2)


def risk(samples: int, seed: int) -> Experiment:

    ex = Experiment("risk", "§2, Fig. 2–3: risk minimization of a truncated normal")
    loaded = frontend.load(str(examples_dir() / "risk.lgr"))
    p = {"a": -1.0, "b": 4.0, "mu": 1.0}
    a, b, mu = p["a"], p["b"], p["mu"]
    # R = ∫_{-10}^{10} h(N − 2g) + g², h = N·[a ≤ x ≤ b]; by Leibniz (Eq. 3):
    #   ∂R/∂a = −N(a)(N(a) − 2g(a)),   ∂R/∂b = N(b)(N(b) − 2g(b)),
    #   ∂R/∂μ = ∫_a^b ∂_μN·(N − 2g) + N·∂_μN dx,  ∂_μN(x) = N(x)(x − μ)/25.
    dmu = quad(lambda x: _normal(x, mu) * (x - mu) / 25 * (2 * _normal(x, mu) - 2 * _normal(x, 2)), a, b,
               epsabs=1e-13, epsrel=1e-12)[0]
    expected = {"a": -_normal(a, mu) * (_normal(a, mu) - 2 * _normal(a, 2)),
                "b": _normal(b, mu) * (_normal(b, mu) - 2 * _normal(b, 2)),
                "mu": dmu}
    standard = {"a": 0.0, "b": 0.0, "mu": dmu}  # standard AD misses the two deltas
    for k in ("a", "b", "mu"):
        d = _exact_deriv(loaded.program, p, k)
        ex.close(f"∂R/∂{k} exact", d.value, expected[k], tol=1e-8)
        ex.close(f"  standard AD ∂R/∂{k}", d.standard_ad, standard[k], tol=1e-8)
        md = operational.estimate_derivative(loaded, p, {q: float(q == k) for q in p}, samples=samples, seed=seed)
        ex.mc(f"∂R/∂{k} MC", md, expected[k])
    # Fig. 2–3: gradient descent from (−1, 4, 1) with the paper's settings, on the normalized density
    # (risk_normalized.lgr): step 400, 100 iterations, 50 uniform samples plus the delta samples at
    # a and b (exact in one variable), the same samples for both methods.  With the boundary terms
    # the window opens towards [−10, 10] and μ → 2; standard AD cannot move a and b (its gradient
    # there is 0), so its loss stays where the window leaves it.
    normalized = frontend.load(str(examples_dir() / "risk_normalized.lgr"))
    runs = {label: descend(normalized, p, standard=label == "standard AD", seed=seed)
            for label in ("Langur", "standard AD")}
    loss = {label: operational.estimate_value(normalized, run[-1], samples=samples, seed=seed)
            for label, run in runs.items()}
    for label, run in runs.items():
        q = run[-1]
        ex.notes.append(f"{label}: after {len(run) - 1} steps a = {q['a']:.3f}, b = {q['b']:.3f}, "
                        f"mu = {q['mu']:.3f}, risk {loss[label].value:.3g}")
    lq, sq = runs["Langur"][-1], runs["standard AD"][-1]
    ex.claim("Langur descent: a opens to about −9.6", lq["a"], -9.6, -10.0 <= lq["a"] <= -9.2)
    ex.claim("Langur descent: b opens past 10", lq["b"], 10.2, lq["b"] >= 10.0)
    ex.claim("Langur descent: μ reaches 2", lq["mu"], 2.0, abs(lq["mu"] - 2) < 0.05)
    ex.claim("standard AD: a stays at −1", sq["a"], -1.0, sq["a"] == -1.0)
    ex.claim("standard AD: b stays at 4", sq["b"], 4.0, sq["b"] == 4.0)
    ratio = loss["standard AD"].value / max(loss["Langur"].value, 1e-300)
    ex.claim("risk: Langur's is 3 orders of magnitude under standard AD's", ratio, 1000.0, ratio >= 1000.0)
    ex.figures = {"loaded": normalized, "runs": runs, "seed": seed}
    return ex


#: The paper's settings for Fig. 2–3 (§2).
DESCENT_STEPS, DESCENT_RATE, DESCENT_SAMPLES = 100, 400.0, 50


def descend(loaded, start: dict, *, standard: bool, seed: int = 0, steps: int = DESCENT_STEPS,
            rate: float = DESCENT_RATE, samples: int = DESCENT_SAMPLES) -> list[dict]:
    """Gradient descent on ⟦p⟧ from ``start``: the parameters after each step (``start`` first).
    The gradient is the Monte Carlo ⦇p⦈ in each parameter, or its regular part alone
    (``standard``: standard AD); iteration ``i`` draws its samples with seed ``seed + i``."""
    q, out = dict(start), [dict(start)]
    for i in range(steps):
        g = {}
        for k in q:
            est = operational.estimate_derivative(loaded, q, {r: float(r == k) for r in q}, samples=samples,
                                                  seed=seed + i)
            g[k] = est.standard_ad.value if standard else est.value
        q = {k: q[k] - rate * g[k] for k in q}
        out.append(dict(q))
    return out


def fig9(samples: int, seed: int) -> Experiment:
    ex = Experiment("fig9", "Fig. 9: [y < x + θ](1 + θ + x + y) on [−1, 1]² at θ = 0")
    loaded = frontend.load(str(examples_dir() / "fig9.lgr"))
    p = {"theta": 0.0}
    # Value: the half-square y < x has area 2, and x + y integrates to 0 on it (the reflection
    # (x, y) ↦ (−y, −x) keeps y < x and negates x + y): ⟦p⟧ = 2.
    # Derivative: regular ∫∫[y < x]·1 = 2; delta ridge along y = x: ∫₋₁¹ (1 + 2x) dx = 2; total 4.
    ex.close("⟦p⟧ (= 2)", api.exact_eval(loaded.program, p).value, 2.0)
    d = _exact_deriv(loaded.program, p, "theta")
    ex.close("⦇p⦈ (= 4)", d.value, 4.0)
    ex.close("  regular = standard AD (= 2)", d.regular, 2.0)
    ex.close("  boundary: the ridge (= 2)", d.boundary, 2.0)
    ex.mc("MC ⟦p⟧", operational.estimate_value(loaded, p, samples=samples, seed=seed), 2.0)
    md = operational.estimate_derivative(loaded, p, {"theta": 1.0}, samples=samples, seed=seed)
    ex.mc("MC ⦇p⦈", md, 4.0)
    ex.mc("MC standard AD", md.standard_ad, 2.0)
    ex.figures = {"loaded": loaded, "params": p, "wrt": "theta"}
    return ex


def renderer(samples: int, seed: int) -> Experiment:

    ex = Experiment("renderer", "§10.1: a pixel lit by a half-plane, three swappable shaders, c = −1; Fig. 13")
    root = examples_dir()
    c = -1.0
    r2 = math.sqrt(2)
    shaders = {
        "shader": (lambda x, y: 1.0, lambda x, y: 0.0),
        "lin_shader": (lambda x, y: 1 / (r2 * (x + y + c) + 2), lambda x, y: -r2 / (r2 * (x + y + c) + 2) ** 2),
        "quad_shader": (lambda x, y: 1 / (r2 * (x + y + c) + 2) ** 2,
                        lambda x, y: -2 * r2 / (r2 * (x + y + c) + 2) ** 3),
    }
    operational.reset_cache_stats()
    for i, (name, (s, ds)) in enumerate(shaders.items()):
        frontend.reset_load_stats()
        loaded = frontend.load(str(root / "renderer.lgr"), modules={"shader": str(root / f"{name}.lgr")})
        elaborated = frontend.load_stats()["elaborated"]
        # Eq. (11): D_c f = ∫∫ ∂_c s·[x + y + c ≥ 0] + ∫ s δ(x + y + c); the delta sits on y = −c − x,
        # |∂_y(x + y + c)| = 1, so the boundary term is ∫₀¹ s(x, −c − x) [0 ≤ −c − x ≤ 1] dx.
        interior = dblquad(lambda y, x, ds=ds: ds(x, y), 0, 1, lambda x: max(0.0, -c - x), lambda x: 1.0,
                           epsabs=1e-12, epsrel=1e-11)[0]
        boundary = quad(lambda x, s=s: s(x, -c - x), max(0.0, -c - 1), min(1.0, -c), epsabs=1e-13)[0]
        expected = interior + boundary
        d = _exact_deriv(loaded.program, {"c": c}, "c")
        ex.close(f"{name}: D_c f exact", d.value, expected, tol=1e-8)
        ex.close(f"{name}:   boundary part", d.boundary, boundary, tol=1e-8)
        before = len(operational.cache_stats()["compiled"])
        md = operational.estimate_derivative(loaded, {"c": c}, {"c": 1.0}, samples=samples, seed=seed)
        compiled = operational.cache_stats()["compiled"][before:]
        ex.mc(f"{name}: D_c f MC", md, expected)
        modules = sorted({m for _, m, _ in compiled})
        if i == 0:
            ex.notes.append(f"first load compiled: {', '.join(modules) or 'nothing'}; elaborated: "
                            f"{', '.join(sorted(elaborated)) or 'nothing'}")
        else:
            ex.claim(f"{name}: the swap recompiles only the shader module", float(len(modules)), 1.0,
                     modules == ["shader"])
            # the front end's twin (incremental loading): the renderer is reused, the shader elaborated
            # (or reused too, when this process elaborated the same file under the same name before)
            ex.claim(f"{name}: the swap re-elaborates at most the shader module", float(len(elaborated)), 1.0,
                     set(elaborated) <= {"shader"})
    fig13_images(ex, seed)
    return ex


#: Fig. 13's image: pixels per side, their size, samples per pixel, and the line's offset c (the
#: line x + y = 1.003 crosses the viewport [0, 1]² diagonally and misses every pixel corner).
IMAGE_PIXELS, IMAGE_SAMPLES, IMAGE_C = 100, 64, -1.003


def fig13_images(ex: Experiment, seed: int) -> None:
    """Fig. 13: the scene as 100 × 100 pixels per shader, value and D_c, by both engines over the
    whole grid at once; the shader swapped by separate compilation (one module recompiled).

    Checks, independent of the engines: the boundary part summed over pixels (times the pixel
    area) is the line integral ∫ s(x, −x − c) dx over the line's part in [0, 1]² (x ∈ [0.003, 1]),
    where s = 1, 1/2, 1/4 on the line for the three shaders (x + y + c = 0 there); and the Monte
    Carlo image agrees with the exact one pixel by pixel."""
    root = examples_dir()
    h = 1.0 / IMAGE_PIXELS
    xs = np.arange(IMAGE_PIXELS) * h
    px, py = np.meshgrid(xs, xs)
    grid = {"px": px.ravel(), "py": py.ravel(), "c": IMAGE_C, "h": h}
    on_line = {"shader": 1.0, "lin_shader": 0.5, "quad_shader": 0.25}
    images = {}
    for name, s_line in on_line.items():
        before = len(operational.cache_stats()["compiled"])
        frontend.reset_load_stats()
        loaded = frontend.load(str(root / "scene.lgr"), modules={"shader": str(root / f"{name}.lgr")})
        load = frontend.load_stats()
        t = time.perf_counter()
        mc = estimate_batch(loaded, grid, direction={"c": 1.0}, samples=IMAGE_SAMPLES, seed=seed)
        mc_seconds = time.perf_counter() - t
        modules = sorted({m for _, m, _ in operational.cache_stats()["compiled"][before:]})
        t = time.perf_counter()
        exact = exact_batch(loaded.program, grid, {"c": 1.0})
        exact_seconds = time.perf_counter() - t
        line = (1.0 + IMAGE_C + 1.0) * s_line  # x from −c − 1 = 0.003 to 1, s constant on the line
        area = h * h
        # the pixels share one design (common random numbers): the sum's error is at most Σ se
        ex.checks.append(Check(f"Fig. 13 {name}: Σ boundary · h² (MC)", float(np.sum(mc.boundary)) * area, line,
                               abs(float(np.sum(mc.boundary)) * area - line)
                               <= SIGMAS * float(np.sum(mc.boundary_stderr)) * area + SLACK,
                               f"mc ± {float(np.sum(mc.boundary_stderr)) * area:.2g}"))
        ex.close(f"Fig. 13 {name}: Σ boundary · h² (exact)", float(np.sum(exact.boundary)) * area, line)
        # a pixel whose samples all agree has standard error 0; a part of it below 14/n of its area
        # (missed by all n samples with probability < 1e-6) may differ by up to the shader's range
        slack = np.where(mc.stderr > 0, SIGMAS * mc.stderr, 14.0 / IMAGE_SAMPLES) + SLACK
        off = int(np.count_nonzero(~(np.abs(mc.value - exact.value) <= slack)))
        doff = int(np.count_nonzero(~(np.abs(mc.derivative - exact.derivative)
                                      <= SIGMAS * mc.derivative_stderr + SLACK)))
        ex.claim(f"Fig. 13 {name}: MC and exact images agree (pixels off)", float(off + doff), 0.0, off + doff == 0)
        if images:  # the scene is compiled with the first shader; a swap compiles no more than the
            # new shader (nothing when the single pixel above compiled it already: the cache is by content)
            ex.claim(f"Fig. 13 {name}: the swap compiles at most the shader module", float(len(modules)), 1.0,
                     set(modules) <= {"shader"})
            ex.claim(f"Fig. 13 {name}: the swap re-elaborates at most the shader module",
                     float(len(load["elaborated"])), 1.0, set(load["elaborated"]) <= {"shader"})
        else:
            ex.claim(f"Fig. 13 {name}: the scene compiles its own module once", float(len(modules)), 1.0,
                     "scene" in modules)
        ex.notes.append(f"Fig. 13 {name}: {IMAGE_PIXELS}×{IMAGE_PIXELS} pixels, value and D_c, Monte Carlo "
                        f"{mc_seconds:.2f} s ({IMAGE_SAMPLES} samples per pixel), exact {exact_seconds:.2f} s "
                        f"({exact.derivations} derivation(s)); modules elaborated: "
                        f"{', '.join(load['elaborated']) or 'none'}, reused: {load['reused']}")
        images[name] = {"value": mc.value.reshape(px.shape), "derivative": mc.derivative.reshape(px.shape),
                        "standard_ad": mc.regular.reshape(px.shape),
                        "exact_derivative": exact.derivative.reshape(px.shape)}
    ex.figures["fig13"] = {"images": images, "extent": (0.0, 1.0, 0.0, 1.0), "c": IMAGE_C}


#: Fig. 14: pixels per side over [−0.3, 0.3]², samples per pixel, and the reference's supersampling
#: (points per pixel side) and finite-difference step in t.
RT_PIXELS, RT_SAMPLES, RT_SUPER, RT_STEP = 40, 64, 48, 0.01
RT_SHADERS = {"depth": "shader.lgr", "lambert": "lambert.lgr"}


def raytrace(samples: int, seed: int, pixels: int = RT_PIXELS) -> Experiment:
    """§10.2, Fig. 14: the ray-traced triangle (examples/raytrace/), 40 × 40 pixels, the z-depth and
    the thresholded point-light shader swapped by separate compilation, each colour channel's value
    and derivative in t (the triangle expanding) by the Monte Carlo engine over the whole image.

    Checked against ``langur.reference`` — the scene written out again in numpy, not read from the
    program — supersampled (48² points per pixel) at t and t ± 0.01: the images agree pixel by
    pixel; the derivative images sum (times the pixel area) to the finite difference of the
    supersampled images' sums; and the derivative's sparsity pattern is the finite difference's
    (a pixel whose finite differences at steps 0.01 and 0.005 both exceed 0.5 has a nonzero
    derivative, and one whose derivative is 0 has finite differences near 0)."""
    ex = Experiment("raytrace", f"§10.2, Fig. 14: a ray-traced triangle, {pixels}×{pixels} pixels, two toon shaders")
    root = examples_dir() / "raytrace"
    h = 0.6 / pixels
    xs = -0.3 + np.arange(pixels) * h
    px, py = np.meshgrid(xs, xs)
    images = {}
    for shader, module in RT_SHADERS.items():
        before = len(operational.cache_stats()["compiled"])
        loaded = frontend.load(str(root / "scene.lgr"), modules={"shader": str(root / module)})
        rgb, drgb = [], []
        seconds = 0.0  # the engine's images only, not the reference's
        for ch in range(3):
            t = time.perf_counter()
            b = estimate_batch(loaded, {"px": px.ravel(), "py": py.ravel(), "h": h, "ch": float(ch), "t": 0.0},
                               direction={"t": 1.0}, samples=RT_SAMPLES, seed=seed)
            seconds += time.perf_counter() - t
            value, se = b.value.reshape(px.shape), b.stderr.reshape(px.shape)
            d, dse = b.derivative.reshape(px.shape), b.derivative_stderr.reshape(px.shape)
            ref = reference.pixels(xs, xs, h, 0.0, shader, ch, RT_SUPER)
            fd = reference.derivative(xs, xs, h, 0.0, shader, ch, RT_SUPER, RT_STEP)
            fd2 = reference.derivative(xs, xs, h, 0.0, shader, ch, RT_SUPER, RT_STEP / 2)
            # the reference's own error: its midpoint rule misplaces an edge by up to a sub-pixel
            quantum = 4.0 / RT_SUPER
            off = int(np.count_nonzero(np.abs(value - ref) > SIGMAS * se + quantum))
            ex.claim(f"{shader} ch{ch}: image = reference (pixels off)", float(off), 0.0, off == 0)
            total, total_se = float(np.sum(d)) * h * h, float(np.sum(dse)) * h * h
            fd_total, fd_err = float(np.sum(fd)) * h * h, abs(float(np.sum(fd - fd2))) * h * h
            ex.checks.append(Check(f"{shader} ch{ch}: Σ D_t · h² against the reference's FD", total, fd_total,
                                   abs(total - fd_total) <= SIGMAS * total_se + 2 * fd_err + 1e-4,
                                   f"mc ± {total_se:.2g}, fd ± {fd_err:.2g}"))
            strong = (np.abs(fd) > 0.5) & (np.abs(fd2) > 0.5)
            missed = int(np.count_nonzero(strong & (d == 0)))
            still = (fd == 0) & (fd2 == 0)  # the reference sees no change at either step
            spurious = int(np.count_nonzero(still & (np.abs(d) > SIGMAS * dse + 1e-9)))
            ex.claim(f"{shader} ch{ch}: derivative's pattern = FD's (pixels missed, spurious)", float(missed + spurious),
                     0.0, missed + spurious == 0)
            rgb.append(value)
            drgb.append(d)
        modules = sorted({m for _, m, _ in operational.cache_stats()["compiled"][before:]})
        if images:
            ex.claim(f"{shader}: the swap compiles at most the shader module", float(len(modules)), 1.0,
                     set(modules) <= {"shader"})
        ex.notes.append(f"{shader}: 3 channels × {pixels * pixels} pixels, value and D_t, {seconds:.2f} s wall-clock "
                        f"({RT_SAMPLES} samples per pixel; compiled: {', '.join(modules) or 'nothing'})")
        images[shader] = {"rgb": np.stack(rgb, axis=-1), "drgb": np.stack(drgb, axis=-1)}
    ex.figures["fig14"] = {"images": images, "extent": (-0.3, 0.3, -0.3, 0.3)}
    return ex


EXPERIMENTS = {"fig1": fig1, "risk": risk, "fig9": fig9, "renderer": renderer, "raytrace": raytrace}


def run(names: list[str], samples: int, seed: int) -> list[Experiment]:
    out = []
    for name in names:
        t = time.perf_counter()
        ex = EXPERIMENTS[name](samples, seed)
        ex.seconds = time.perf_counter() - t
        out.append(ex)
    return out
