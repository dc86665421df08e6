"""The "did you mean" of every error about a name (scene keys and choices, methods, effects, assumptions)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(value: object, known: Iterable[str], *, cutoff: float = 0.6) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to ``value`` (``'x' or 'y'`` for names equally close:
    ``cd`` is as near ``cd1`` as ``cd2``), or ``""`` when none is close.

    Only strings get a suggestion; ``cutoff`` is :func:`difflib.get_close_matches`'s similarity threshold.
    """
    if not isinstance(value, str):
        return ""
    known = list(known)
    near = difflib.get_close_matches(value, known, n=max(len(known), 1), cutoff=cutoff)
    if not near:
        return ""
    ratios = [difflib.SequenceMatcher(None, name, value).ratio() for name in near]  # as get_close_matches scores
    tied = sorted((name for name, r in zip(near, ratios, strict=True) if r == ratios[0]), key=known.index)[:3]
    return f" (did you mean {' or '.join(repr(name) for name in tied)}?)"


def not_known(subject: str, value: object, known: Iterable[str], what: str, *, listing: str = "known") -> str:
    """The one wording of a name error: ``<subject> is not <what> (did you mean 'x'?); <listing>: a, b, c``."""
    known = list(known)
    return f"{subject} is not {what}{did_you_mean(value, known)}; {listing}: {', '.join(known)}"
