"""Lower sympy expressions to CasADi SX, node by node.

A direct tree walk (memoised on sympy's structural hashing) keeps every shared
sub-expression one SX node, so the generated C computes it once; ``casadi.cse``
then merges what sympy did not see as shared.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping

import casadi as ca
import sympy as sp

_UNARY: dict[type, Callable] = {
    sp.sin: ca.sin, sp.cos: ca.cos, sp.tan: ca.tan, sp.asin: ca.asin, sp.acos: ca.acos, sp.atan: ca.atan,
    sp.tanh: ca.tanh, sp.exp: ca.exp, sp.log: ca.log, sp.Abs: ca.fabs, sp.sign: ca.sign,
    sp.floor: ca.floor, sp.sinh: ca.sinh, sp.cosh: ca.cosh,
}


class Lowering:
    """Convert sympy expressions to SX, given SX values for the free symbols."""

    def __init__(self, values: Mapping[sp.Symbol, ca.SX]):
        self.values = dict(values)
        self._memo: dict[sp.Basic, ca.SX] = {}

    def __call__(self, expr: sp.Expr) -> ca.SX:
        expr = sp.sympify(expr)
        hit = self._memo.get(expr)
        if hit is not None:
            return hit
        out = self._lower(expr)
        self._memo[expr] = out
        return out

    def _lower(self, e: sp.Basic) -> ca.SX:
        if e.is_Symbol:
            if e not in self.values:
                raise KeyError(f"no CasADi value for symbol {e}")
            return self.values[e]
        if e.is_Integer or e.is_Rational or e.is_Float:
            return ca.SX(float(e))
        if e is sp.pi:
            return ca.SX(float(sp.pi))
        if e.is_Add:
            terms = [self(a) for a in e.args]
            out = terms[0]
            for t in terms[1:]:
                out = out + t
            return out
        if e.is_Mul:
            args = list(e.args)
            out = self(args[0])
            for a in args[1:]:
                out = out * self(a)
            return out
        if e.is_Pow:
            base, ex = e.args
            b = self(base)
            if ex == sp.S.Half:
                return ca.sqrt(b)
            if ex == -sp.S.Half:
                return 1 / ca.sqrt(b)
            if ex.is_Integer:
                n = int(ex)
                if n == -1:
                    return 1 / b
                if 0 < n <= 4:
                    out = b
                    for _ in range(n - 1):
                        out = out * b
                    return out
                if -4 <= n < 0:
                    out = b
                    for _ in range(-n - 1):
                        out = out * b
                    return 1 / out
            return b ** self(ex)
        if isinstance(e, sp.Max | sp.Min):
            return functools.reduce(ca.fmax if isinstance(e, sp.Max) else ca.fmin, [self(a) for a in e.args])
        if isinstance(e, sp.Piecewise):
            pieces = list(e.args)
            value, cond = pieces[-1]
            if cond is not sp.true:
                raise ValueError("Piecewise without an otherwise branch")
            out = self(value)
            for value, cond in reversed(pieces[:-1]):
                out = ca.if_else(self._cond(cond), self(value), out)
            return out
        fn = _UNARY.get(type(e)) or _UNARY.get(e.func)
        if fn is not None:
            return fn(self(e.args[0]))
        if isinstance(e, sp.atan2):
            return ca.atan2(self(e.args[0]), self(e.args[1]))
        raise NotImplementedError(f"cannot lower {type(e).__name__}: {e}")

    def _cond(self, c: sp.Basic) -> ca.SX:
        if isinstance(c, sp.StrictLessThan):
            return self(c.lhs) < self(c.rhs)
        if isinstance(c, sp.LessThan):
            return self(c.lhs) <= self(c.rhs)
        if isinstance(c, sp.StrictGreaterThan):
            return self(c.lhs) > self(c.rhs)
        if isinstance(c, sp.GreaterThan):
            return self(c.lhs) >= self(c.rhs)
        if isinstance(c, sp.And):
            out = self._cond(c.args[0])
            for a in c.args[1:]:
                out = ca.logic_and(out, self._cond(a))
            return out
        if isinstance(c, sp.Or):
            out = self._cond(c.args[0])
            for a in c.args[1:]:
                out = ca.logic_or(out, self._cond(a))
            return out
        raise NotImplementedError(f"cannot lower condition {c}")
