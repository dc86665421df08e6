"""The "did you mean" of every error about a name (scene keys and choices, methods, effects, assumptions)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(value: object, known: Iterable[str], *, cutoff: float = 0.6) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to ``value``, or ``""`` when none is close.

    Only strings get a suggestion; ``cutoff`` is :func:`difflib.get_close_matches`'s similarity threshold.
    """
    if not isinstance(value, str):
        return ""
    near = difflib.get_close_matches(value, list(known), n=1, cutoff=cutoff)
    return f" (did you mean '{near[0]}'?)" if near else ""


def not_known(subject: str, value: object, known: Iterable[str], what: str, *, listing: str = "known") -> str:
    """The one wording of a name error: ``<subject> is not <what> (did you mean 'x'?); <listing>: a, b, c``."""
    known = list(known)
    return f"{subject} is not {what}{did_you_mean(value, known)}; {listing}: {', '.join(known)}"
