"""Contact cases, Algorithms 3 and 4 (Section 4.4).

A seal-groove case is named by its back contact (``n``: b2 <= 0, ``q``: b4 <= 0,
``p``: neither) and its front contact (``1``: b1 <= 0, ``3``: b3 <= 0, ``2``:
neither). A *mode* of the hybrid model is a groove case with the housing contact
closed or open and the spring in contact or not: within a mode the right-hand
side is smooth.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .groove_cases import CASES, GROOVE_GUARDS, case_of


@dataclass(frozen=True)
class Ops:
    """The three operations Algorithm 4 needs, for one kind of number (numpy arrays, CasADi symbols)."""

    logical_and: Callable
    minimum: Callable
    where: Callable


#: numpy: floats or arrays of samples
NUMPY = Ops(np.logical_and, np.minimum, np.where)


def gap_width(gaps: Sequence, ops: Ops = NUMPY):
    """Algorithm 4 (Section 4.4): the seal-groove gap b_gap = min(b1..b4) while every groove contact is open, else 0.

    The leakage area is A_gap = b_gap H. ``gaps`` are b1..b4 (floats, numpy arrays of samples, or, with
    CasADi's :class:`Ops`, SX expressions); the result has their shape.
    """
    all_open = functools.reduce(ops.logical_and, [g > 0 for g in gaps])
    return ops.where(all_open, functools.reduce(ops.minimum, gaps), 0.0)


@dataclass(frozen=True)
class Mode:
    """One smooth piece of the hybrid model: which contacts are closed (a case of Algorithm 3 for the groove, with
    the housing, the spring and any other contact closed or open)."""

    closed: tuple[bool, ...]  # in the order of ``guard_names``
    guard_names: tuple[str, ...]

    @property
    def label(self) -> str:
        """The groove's case (Algorithm 3) followed by each other guard's declared closed/open label, e.g. q1_h_s."""
        c = dict(zip(self.guard_names, self.closed, strict=True))
        parts = []
        if all(g in c for g in GROOVE_GUARDS):
            parts.append(case_of(*(c[g] for g in GROOVE_GUARDS)))
        for name in self.guard_names:
            if name not in GROOVE_GUARDS:
                closed_label, open_label = _labels(name)
                parts.append(closed_label if c[name] else open_label)
        return "_".join(parts) or "free"


def _labels(name: str) -> tuple[str, str]:
    """A guard's declared (closed, open) label parts; its name and name + '0' when it declares none."""
    from .submodels.registry import guard

    try:
        return guard(name).labels
    except KeyError:
        return name, name + "0"


def modes(guard_names: tuple[str, ...]) -> list[Mode]:
    """Every mode the contacts of a model allow: the nine groove cases of Algorithm 3 x each other contact closed or
    open."""
    groove = [g for g in GROOVE_GUARDS if g in guard_names]
    others = [g for g in guard_names if g not in groove]
    out = []
    groove_sets = [CASES[c] for c in CASES] if groove else [()]
    for gset in groove_sets:
        for rest in itertools.product((True, False), repeat=len(others)):
            closed = dict(zip(groove, gset, strict=True)) | dict(zip(others, rest, strict=True))
            out.append(Mode(tuple(closed[g] for g in guard_names), guard_names))
    return out
