"""A derived scenario as written: ``derive NAME from BASE { steps }``, and what it makes."""

from __future__ import annotations

from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.model.tasks import Task


@dataclass(frozen=True)
class Step:
    """One input transformation as written: its name and arguments (as text)."""

    transformation: str
    arguments: tuple[tuple[str, str], ...]
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    written: tuple[tuple[str, str], ...] = field(default=(), compare=False, repr=False)
    """Arguments as the author wrote them where the text differs (a position with its units:
    ``to`` is ``3 m, 200 cm`` where the argument is ``3.0,2.0``), for the formatter."""

    def argument(self, key: str) -> str | None:
        return dict(self.arguments).get(key)


@dataclass(frozen=True)
class DerivedScenario:
    """The block, and the scenario and tasks its steps make from the base."""

    id: str
    base: str
    steps: tuple[Step, ...]
    scenario: Scenario
    new_tasks: tuple[Task, ...] = ()
    derivation: Derivation | None = field(default=None, compare=False)
    """The steps as recorded for the generation PROV (composites as their basic steps)."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
