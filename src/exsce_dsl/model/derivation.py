"""Derivations: a new scenario made from a base one by a chain of input transformations."""

from __future__ import annotations

from dataclasses import dataclass

ParameterValue = str | int | float | bool


@dataclass(frozen=True)
class TransformationStep:
    """One input transformation as applied: its name (``remove_robot``...) and arguments.

    A composite transformation appears as the basic steps it was made of, in order.
    """

    transformation: str
    parameters: tuple[tuple[str, ParameterValue], ...] = ()


@dataclass(frozen=True)
class Derivation:
    """Scenario ``new`` derived from scenario ``base`` by ``steps``, applied in order."""

    new: str
    base: str
    steps: tuple[TransformationStep, ...]
