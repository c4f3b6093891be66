"""Did-you-mean suggestions for unknown names."""

from __future__ import annotations

from collections.abc import Iterable
from difflib import SequenceMatcher


def closest(name: str, candidates: Iterable[str], cutoff: float = 0.6) -> str | None:
    """The candidate most like ``name``, or None if none is close enough.

    Besides whole-name similarity, a candidate whose tail matches (``c025-w01``
    for ``classroom_c025-w001``) counts, since area prefixes are often left out.
    """
    best, best_score = None, cutoff
    lowered = name.lower()
    for candidate in candidates:
        cand = candidate.lower()
        score = SequenceMatcher(None, lowered, cand).ratio()
        if len(cand) > len(lowered):
            tail = cand[-(len(lowered) + 1) :]
            score = max(score, SequenceMatcher(None, lowered, tail).ratio() - 0.05)
        if score > best_score or (score == best_score and best is not None and candidate < best):
            best, best_score = candidate, score
    return best


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` or the empty string."""
    match = closest(name, candidates)
    return f"; did you mean '{match}'?" if match else ""
