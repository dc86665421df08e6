"""How a printed form and its derived counterpart are compared: intermediates replaced by their derived values,
numerically at random states around the default scene's values, and symbolically where the difference simplifies."""

from __future__ import annotations

import functools
import importlib

import numpy as np
import sympy as sp

from .. import seal_shape as shape
from ..symbols import P
from .counterparts import Derived
from .values import (
    ACTIVATIONS,
    DEFAULTS,
    EXAMPLE_STATE,
    EXTRA_DEFAULTS,
    N_SAMPLES,
    REL_TOL,
    ROW_RANGES,
    SEED,
    SIMPLIFY_MAX_OPS,
    STATE_RANGES,
    SYMBOLIC_MAX_OPS,
    I,
    rest_deflection,
)


def _substitutions(d: Derived, free: tuple[str, ...]) -> dict[sp.Symbol, sp.Expr]:
    """The derived values of the paper's intermediates; with beta free, ao and b5 follow Eqs. 27-28 in it."""
    if "beta" not in free:
        return d.subs
    subs = {k: v for k, v in d.subs.items() if k is not I["beta"]}
    subs[I["ao"]] = P["ro"] * (1 - sp.cos(I["beta"]))
    subs[I["b5"]] = P["ro"] * sp.sin(I["beta"])
    return subs


def prepare(expr: sp.Expr, d: Derived, settings: tuple[str, str], free: tuple[str, ...] = ()) -> sp.Expr:
    """Intermediates by derived values, friction tanh by its limit, activations by the row's rule."""
    act, sign_limit = settings
    expr = sp.sympify(expr)
    subs = _substitutions(d, free)
    for _ in range(3):  # intermediates may refer to intermediates
        if not expr.free_symbols & set(subs):
            break
        expr = expr.xreplace(subs)
    expr = expr.replace(sp.tanh, (lambda a: sp.S.One) if sign_limit == "forward" else (lambda a: sp.sign(a)))
    if act == "one":
        expr = expr.xreplace({a: sp.S.One for a in ACTIVATIONS.values()})
    elif act == "guard":
        expr = expr.xreplace(d.guard_rule)
    return expr


def _values(names: list[str], rng: np.random.Generator, jitter: bool, ranges: dict) -> dict[str, float]:
    vals = {}
    for n in names:
        if n in DEFAULTS:
            v = DEFAULTS[n]
            vals[n] = v * rng.uniform(0.8, 1.2) if jitter and n not in ("Ws", "Wg", "delta_w") else v
        elif n in ranges:
            vals[n] = rng.uniform(*ranges[n])
        elif n.startswith("s_"):
            vals[n] = float(rng.integers(0, 2))
        else:
            raise KeyError(f"no value for symbol {n}")
    if "Wg" in vals and "Ws" in vals and jitter:
        vals["Wg"] = vals["Ws"] * 1.02
    if "beta_o" in vals:  # a derived parameter: consistent with the (jittered) Ws and ro
        vals["beta_o"] = shape.tip_half_angle(vals.get("Ws", DEFAULTS["Ws"]), vals.get("ro", DEFAULTS["ro"]))
    if "delta_w" in vals and jitter:
        vals["delta_w"] = rest_deflection(vals)
    return vals


@functools.lru_cache(maxsize=512)
def _lambdify(exprs: tuple[sp.Expr, ...]):
    syms = sorted(set().union(*(e.free_symbols for e in exprs)), key=lambda s: s.name)
    big = sum(sp.count_ops(e) for e in exprs) > 300
    f = sp.lambdify(syms, list(exprs), modules=["numpy"], cse=big)
    return syms, f


def evaluate(exprs: tuple[sp.Expr, ...], points: list[dict[str, float]]) -> np.ndarray:
    syms, f = _lambdify(exprs)
    with np.errstate(all="ignore"):
        return np.array([[float(v) for v in f(*[pt[s.name] for s in syms])] for pt in points])


def _sample_points(exprs: tuple[sp.Expr, ...], seed_label: str, n: int = N_SAMPLES) -> list[dict[str, float]]:
    names = sorted({s.name for e in exprs for s in e.free_symbols})
    rng = np.random.default_rng([SEED, sum(ord(c) * 31**i for i, c in enumerate(seed_label)) % 2**32])
    ranges = STATE_RANGES | ROW_RANGES.get(seed_label.split("/")[0], {})
    return [_values(names, rng, jitter=True, ranges=ranges) for _ in range(n)]


def example_point(overrides: dict[str, float]) -> dict[str, float]:
    pt = dict(DEFAULTS) | EXTRA_DEFAULTS | EXAMPLE_STATE | overrides
    pt["delta_w"] = rest_deflection(pt)
    pt["beta_o"] = shape.tip_half_angle(pt["Ws"], pt["ro"])
    return pt


def numeric_equal(a: tuple, b: tuple, label: str, ref: tuple = ()) -> tuple[bool, float]:
    """a == b at random points, to REL_TOL of the largest value of a, b (and ref, if given)."""
    pts = _sample_points(tuple(a) + tuple(b) + tuple(ref), label)
    values = evaluate(tuple(a) + tuple(b) + tuple(ref), pts)
    va, vb, vr = values[:, :len(a)], values[:, len(a):len(a) + len(b)], values[:, len(a) + len(b):]
    vr = vr if ref else np.zeros(1)
    if not (np.all(np.isfinite(va)) and np.all(np.isfinite(vb)) and np.all(np.isfinite(vr))):
        raise ArithmeticError(f"{label}: non-finite values in the numeric check")
    scale = max(float(np.max(np.abs(va))), float(np.max(np.abs(vb))), float(np.max(np.abs(vr))), 1e-300)
    err = float(np.max(np.abs(va - vb))) / scale
    return err <= REL_TOL, err


def symbolic_zero(diffs: tuple[sp.Expr, ...]) -> bool:
    """True when every difference simplifies to zero (cheap rewrites first; simplify only on small ones)."""
    for e in diffs:
        if e == 0:
            continue
        if e.has(sp.Piecewise, sp.Max, sp.sign) or sp.count_ops(e) > SYMBOLIC_MAX_OPS:
            return False
        if sp.expand(e) == 0 or sp.expand(sp.expand_trig(e)) == 0 or sp.cancel(sp.expand_trig(e)) == 0:
            continue
        if sp.count_ops(e) > SIMPLIFY_MAX_OPS or sp.simplify(e) != 0:
            return False
    return True


def show(exprs: tuple[sp.Expr, ...]) -> str:
    s = [sp.sstr(e) for e in exprs]
    return s[0] if len(s) == 1 else "(" + ", ".join(s) + ")"


def resolve(pointer: str) -> bool:
    module, _, attr = pointer.partition(":")
    attr = attr.split(" ")[0].split("[")[0]
    mod = importlib.import_module("." + module.removeprefix("derive."), __package__.rpartition(".")[0])
    return hasattr(mod, attr)
