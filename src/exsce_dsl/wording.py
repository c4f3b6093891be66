"""Counted nouns in messages and pages: ``1 scenario``, ``3 runs``, never ``1 scenarios``."""

from __future__ import annotations

__all__ = ["counted", "noun"]

_IRREGULAR = {"hypothesis": "hypotheses", "analysis": "analyses", "child": "children"}


def noun(word: str, count: int, plural: str | None = None) -> str:
    """``word`` as it follows the number ``count``: itself for 1, else its plural (``plural``, or
    the word with an ``s``, or ``es`` after s, x, z, ch, sh).  The last word of a phrase is the noun:
    ``noun("run failed", 2)`` is wrong, ``noun("run", 2) + " failed"`` is right."""
    if count == 1:
        return word
    if plural is not None:
        return plural
    if word in _IRREGULAR:
        return _IRREGULAR[word]
    return word + ("es" if word.endswith(("s", "x", "z", "ch", "sh")) else "s")


def counted(count: int, word: str, plural: str | None = None) -> str:
    """``3 runs``, ``1 scenario``: the number and the noun that agrees with it."""
    return f"{count} {noun(word, count, plural)}"
