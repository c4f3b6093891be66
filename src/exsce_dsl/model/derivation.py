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
class TaskOrigin:
    """A task a step made from another (``reverse_waypoint_order`` makes a reversed copy)."""

    task: str
    source: str
    step: int
    """The step's position in the derivation, from 1."""


@dataclass(frozen=True)
class Derivation:
    """Scenario ``new`` derived from scenario ``base`` by ``steps``, applied in order."""

    new: str
    base: str
    steps: tuple[TransformationStep, ...]
    origins: tuple[TaskOrigin, ...] = ()
    """The new tasks of the derivation and the tasks they were made from."""
