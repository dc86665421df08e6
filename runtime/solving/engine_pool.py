"""Engines kept for reuse between the runs of a study.

Building an engine costs a fifth of what a short run integrates: the erk integrator of the default scene takes
about 15 ms to build (CasADi constructs it, then generates its C to find the compiled library in the cache),
against 70 ms for a whole revolution. Every point of a sweep with the same model and the same solver settings
needs the same engine, with other parameter values, which are an input of every call. Inside :func:`reusing`
(a sweep's points) a run leases its engine here (:func:`lease`) and gives it back when it ends; a later run with
the same model Functions and settings takes it (reset, :meth:`.methods.Engine.reset`) instead of building one.
The Functions are the same object because :func:`~apexseal.generated.load.load_functions` returns the model it
loaded while its files are unchanged. A leased engine serves one run at a time: a run in another thread while
it is out builds its own. An engine is given back when its run ends, whatever the run's status (a call that
failed leaves nothing in it); one whose run raised out of :func:`.run.run` is dropped. ``apexseal.reusing_engines``
is :func:`reusing`, for a user's own loop over designs.

Outside :func:`reusing` every run builds its own engine and drops it: an engine also depends on module constants
(the composite method's rules) that a user or a test may change between two runs.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from .methods import Engine, make_engine

#: models-and-settings kept; the least recently used goes first (an engine holds its compiled library open)
MAX_KEYS = 8
#: the settings that never reach an engine's build: the run's length and its wall-time budget (the budget's
#: calls per revolution reach it as n_samples, which is part of the key)
_NOT_BUILT = ("revolutions", "max_wall_time")

_lock = threading.Lock()
#: how deep this thread is inside reusing()
_local = threading.local()
#: key -> (the model Functions, kept so that their id is never reused while the key is, and the free engines)
_free: OrderedDict[tuple, tuple[object, list[Engine]]] = OrderedDict()


def key_of(functions, settings, n_samples: int, span: float) -> tuple:
    """What an engine is built from: the model Functions (by identity), every setting that reaches the build,
    the number of output intervals and their span."""
    built = tuple((k, v) for k, v in dict(settings).items() if k not in _NOT_BUILT)
    return (id(functions), built, int(n_samples), float(span))


@dataclass
class Lease:
    """An engine taken for one run; :meth:`release` gives it back for the next run with the same key."""

    key: tuple
    functions: object
    engine: Engine

    def release(self) -> None:
        if not _reusing():
            return
        with _lock:
            _, engines = _free.setdefault(self.key, (self.functions, []))
            engines.append(self.engine)
            _free.move_to_end(self.key)
            while len(_free) > MAX_KEYS:
                _free.popitem(last=False)


def lease(functions, settings, *, n_samples: int, span: float, make=None) -> Lease:
    """A free engine of this key (reset) inside :func:`reusing`, or a new one (``make``, by default
    :func:`.methods.make_engine`)."""
    key = key_of(functions, settings, n_samples, span)
    engine = None
    if _reusing():
        with _lock:
            kept = _free.get(key)
            engine = kept[1].pop() if kept and kept[1] else None
    if engine is None:
        engine = (make or make_engine)(functions, settings, n_samples=n_samples, span=span)
    else:
        engine.reset()
    return Lease(key, functions, engine)


def clear() -> None:
    """Forget every kept engine."""
    with _lock:
        _free.clear()


def _reusing() -> bool:
    return getattr(_local, "depth", 0) > 0


@contextmanager
def reusing() -> Iterator[None]:
    """Runs of this thread inside take kept engines and give theirs back (engines stay kept after it ends)."""
    _local.depth = getattr(_local, "depth", 0) + 1
    try:
        yield
    finally:
        _local.depth -= 1
