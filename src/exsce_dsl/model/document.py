"""A specification as written: files, their imports and declarations."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from exsce_dsl.errors import ExsceError, ScenarioChoiceError, SourceLocation
from exsce_dsl.model.acceptance import Acceptance
from exsce_dsl.model.derived import DerivedScenario
from exsce_dsl.model.environment import Environment
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.robots import RobotType
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.model.tasks import Task

Declaration = RobotType | Environment | Task | Scenario | Acceptance | DerivedScenario | MetricDefinition


@dataclass(frozen=True)
class Import:
    path: str
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Document:
    """One ``.exsce`` file: what it imports and what it declares, in order."""

    path: str
    imports: tuple[Import, ...]
    declarations: tuple[Declaration, ...]


@dataclass(frozen=True)
class Specification:
    """A root file with everything it imports, checked and resolved."""

    root: str
    documents: tuple[Document, ...]
    """The root document first, then the imported ones."""

    def declarations(self) -> Iterator[Declaration]:
        for document in self.documents:
            yield from document.declarations

    @property
    def scenarios(self) -> tuple[Scenario, ...]:
        """Written and derived ones, in the order they are declared."""
        return tuple(
            d.scenario if isinstance(d, DerivedScenario) else d
            for d in self.declarations()
            if isinstance(d, (Scenario, DerivedScenario))
        )

    @property
    def derived(self) -> tuple[DerivedScenario, ...]:
        return tuple(d for d in self.declarations() if isinstance(d, DerivedScenario))

    @property
    def environments(self) -> tuple[Environment, ...]:
        return tuple(d for d in self.declarations() if isinstance(d, Environment))

    @property
    def tasks(self) -> tuple[Task, ...]:
        """Declared ones, and those derivations made."""
        declared = tuple(d for d in self.declarations() if isinstance(d, Task))
        return declared + tuple(t for d in self.derived for t in d.new_tasks)

    @property
    def acceptance(self) -> tuple[Acceptance, ...]:
        return tuple(d for d in self.declarations() if isinstance(d, Acceptance))

    def acceptance_of(self, scenario_id: str) -> Acceptance | None:
        """The acceptance criteria of a scenario, if the specification gives any."""
        return next((a for a in self.acceptance if a.scenario == scenario_id), None)

    @property
    def metrics(self) -> tuple[MetricDefinition, ...]:
        """The metrics the specification declares (not the standard library's)."""
        return tuple(d for d in self.declarations() if isinstance(d, MetricDefinition))

    @property
    def robot_types(self) -> tuple[RobotType, ...]:
        return tuple(d for d in self.declarations() if isinstance(d, RobotType))

    @property
    def root_document(self) -> Document:
        return self.documents[0]

    def scenario(self, scenario_id: str | None = None) -> Scenario:
        """The scenario with this id, or the root file's only scenario."""
        if scenario_id is not None:
            for s in self.scenarios:
                if s.id == scenario_id:
                    return s
            raise ExsceError(f"no scenario '{scenario_id}' in {self.root}")
        own = [
            d.scenario if isinstance(d, DerivedScenario) else d
            for d in self.root_document.declarations
            if isinstance(d, (Scenario, DerivedScenario))
        ]
        if len(own) != 1:
            raise ScenarioChoiceError(str(self.root), [s.id for s in own])
        return own[0]
