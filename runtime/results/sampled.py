"""The model's outputs and guards at many samples: one call of the model library's loop, or CasADi's map.

With a compiled model library, ``apexseal_outputs_block`` (generated/templates/apexseal_model.in.c) calls the
library's ``outputs`` and ``guards`` at every sample in a C loop. CasADi's map of the same externals costs about
ten times the evaluation per sample (its per-call bookkeeping; `python -m apexseal.runtime.bench.sample_cost`
measures both), and assembling a revolution's outputs was most of the run's time after the integration
(docs/bench/table.md, "End to end"). Without a library (``solver.interpreted``, no C compiler) the Functions are
CasADi's SX ones and their map is used. Both give the same numbers: the loop calls the compiled code the
externals call (tests/runtime/test_sampled.py compares them to the bit).
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from pathlib import Path

import numpy as np

#: (id of the Function, n, p shared) -> (Function, its map over n samples); a few sizes per run, built once each
_MAPPED: dict[tuple[int, int, bool], tuple] = {}

_DBL = ctypes.POINTER(ctypes.c_double)


def mapped(f, n: int, shared_p: bool = True):
    """``f`` mapped over ``n`` samples, built once per Function and size (building a map costs more than
    evaluating it). The parameter vector (input ``p``) is shared by all samples, not repeated: converting
    ``n`` copies of it into CasADi cost more than evaluating the outputs; ``shared_p`` False: one per sample (a
    scene's schedule)."""
    key = (id(f), n, shared_p)
    if key not in _MAPPED:
        if len(_MAPPED) > 64:
            _MAPPED.clear()
        shared = [f.name_in().index("p")] if "p" in f.name_in() and shared_p else []
        _MAPPED[key] = (f, f.map(f"{f.name()}_map", "serial", n, shared, []))
    return _MAPPED[key][1]


@lru_cache(maxsize=16)
def _block(library: Path):
    """The library's loop, or None for a library built before it existed (then CasADi's map serves)."""
    fn = getattr(ctypes.CDLL(str(library)), "apexseal_outputs_block", None)
    if fn is None:
        return None
    fn.argtypes = [_DBL, _DBL, _DBL, _DBL, ctypes.c_int, _DBL, ctypes.c_int, _DBL, _DBL]
    fn.restype = ctypes.c_int
    return fn


def _rows(a: np.ndarray) -> np.ndarray:
    """(k, n) -> its samples as C-contiguous rows (n, k)."""
    return np.ascontiguousarray(np.asarray(a, float).T)


def _ptr(a: np.ndarray | None):
    return None if a is None else a.ctypes.data_as(_DBL)


def looped_outputs(functions, theta, X, closed, params, U) -> tuple[np.ndarray | None, np.ndarray]:
    n = theta.size
    th, x, u = np.ascontiguousarray(theta, float), _rows(X), _rows(U)
    a = None if closed is None else _rows(closed)
    p = np.ascontiguousarray(params, float) if np.ndim(params) == 1 else _rows(params)  # shared, or per sample
    stride = 0 if p.ndim == 1 else p.shape[1]
    y = None if closed is None else np.empty((n, len(functions.output_names)))
    g = np.empty((n, len(functions.guard_names)))
    status = _block(functions.library)(_ptr(th), _ptr(x), _ptr(a), _ptr(p), stride, _ptr(u), n, _ptr(y), _ptr(g))
    if status:
        why = "out of memory" if status == 2 else "a Function failed to evaluate"
        raise RuntimeError(f"apexseal_outputs_block of {Path(functions.library).name}: {why}")
    return (None if y is None else y.T), g.T


def mapped_outputs(functions, theta, X, closed, params, U) -> tuple[np.ndarray | None, np.ndarray]:
    n, shared = theta.size, np.ndim(params) == 1
    g = mapped(functions.guards, n, shared)(theta[None, :], X, params, U).full()
    if closed is None:
        return None, g
    return mapped(functions.outputs, n, shared)(theta[None, :], X, np.asarray(closed, float), params, U).full(), g


def _loops(functions, n_u: int) -> bool:
    """Whether the library's loop applies: a compiled set whose Functions take the sizes the loop was rendered
    with (the ``u`` of ``outputs`` is the pressures given)."""
    return (functions.library is not None and functions.outputs.size1_in(4) == n_u
            and _block(functions.library) is not None)


def outputs_at(functions, theta, X, closed, params, U) -> tuple[np.ndarray | None, np.ndarray]:
    """(the named outputs (n_outputs, n), the guards (n_guards, n)) at the crank angles ``theta`` (n,), physical
    states ``X`` (n_x, n), contacts ``closed`` (n_guards, n; bool or 0/1), parameters ``params`` (n_par,), or
    (n_par, n) one vector per sample (a scene's schedule), pressures ``U`` (n_u, n). With ``closed`` None only the
    guards are evaluated, and the outputs are None."""
    theta = np.asarray(theta, float)
    way = looped_outputs if _loops(functions, U.shape[0]) else mapped_outputs
    return way(functions, theta, X, closed, params, U)


def guards_at(functions, theta, X, params, U) -> np.ndarray:
    """The guards (n_guards, n) at the samples (as :func:`outputs_at`, without the outputs)."""
    return outputs_at(functions, theta, X, None, params, U)[1]
