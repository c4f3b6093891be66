"""Did-you-mean suggestions for unknown names."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from difflib import SequenceMatcher

MARGIN = 0.1
"""How much less like a name than the closest a further suggestion may be."""


def likeness(name: str, candidate: str) -> float:
    """How much ``candidate`` looks like ``name``, from 0 to 1 (case left out).

    Besides whole-name similarity, a candidate whose tail matches (``c025-w01``
    for ``classroom_c025-w001``) counts, since area prefixes are often left out.
    """
    lowered, cand = name.lower(), candidate.lower()
    score = SequenceMatcher(None, lowered, cand).ratio()
    if len(cand) > len(lowered):
        tail = cand[-(len(lowered) + 1) :]
        score = max(score, SequenceMatcher(None, lowered, tail).ratio() - 0.05)
    return score


def closest(name: str, candidates: Iterable[str], cutoff: float = 0.6) -> str | None:
    """The candidate most like ``name`` (:func:`likeness`), or None if none is close enough."""
    best, best_score = None, cutoff
    for candidate in candidates:
        score = likeness(name, candidate)
        if score > best_score or (score == best_score and best is not None and candidate < best):
            best, best_score = candidate, score
    return best


def closest_several(
    name: str,
    candidates: Iterable[str],
    limit: int = 3,
    cutoff: float = 0.6,
    forms: Callable[[str], Sequence[str]] | None = None,
) -> list[str]:
    """Up to ``limit`` candidates like ``name``, the closest first (ties in name order), each
    nearly as close as the closest (:data:`MARGIN`).

    ``forms`` gives the spellings a name is compared by, pairwise and each weaker than the one
    before (a topic: its name without the leading ``/``, then its last part, so that a relative
    name and one in another namespace count as close); by default the name itself.
    """
    spell = forms or (lambda text: (text,))
    mine = spell(name)
    scored = []
    for candidate in dict.fromkeys(candidates):
        theirs = spell(candidate)
        pairs = zip(mine, theirs, strict=False)
        score = max((likeness(a, b) * 0.9**k for k, (a, b) in enumerate(pairs)), default=0.0)
        if score > cutoff:
            scored.append((-score, candidate))
    ranked = sorted(scored)[:limit]
    return [candidate for score, candidate in ranked if -score >= -ranked[0][0] - MARGIN]


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` or the empty string."""
    match = closest(name, candidates)
    return f"; did you mean '{match}'?" if match else ""
