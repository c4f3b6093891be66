"""Apply a chain of input transformations to a scenario: the new scenario, its new tasks, the
derivation record (for the generation PROV), and the ``.exsce`` document that declares them."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Document, Environment, Import, Scenario, Task
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.model.derived import DerivedScenario, Step
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.suggest import did_you_mean
from exsce_dsl.transform.applied import Applied
from exsce_dsl.transform.transformations import TRANSFORMATIONS

Request = tuple[str, Mapping[str, str]]
"""A transformation's name and its arguments as text."""


@dataclass(frozen=True)
class Derived:
    scenario: Scenario
    new_tasks: tuple[Task, ...]
    derivation: Derivation
    requests: tuple[Step, ...]
    """The steps as asked for (a composite as one step), to write them as a ``derive`` block."""
    environment_changed: bool
    """The steps changed the environment, so it has an id of its own: ``<new>_environment``."""


def derive(
    base: Scenario,
    requests: Sequence[Request],
    new_id: str | None = None,
    tasks: Mapping[str, Task] | None = None,
) -> Derived:
    """``base`` transformed by ``requests`` in order; ``tasks`` are the tasks the spec declares
    (a transformation may allocate one the base does not use)."""
    if not requests:
        raise ExsceError("say which transformations to apply (-t NAME ...)")
    known = {t.id: t for t in base.tasks} | dict(tasks or {})
    applied = Applied(base)
    for name, arguments in requests:
        transformation = TRANSFORMATIONS.get(name)
        if transformation is None:
            raise ExsceError(f"unknown transformation '{name}'{did_you_mean(name, TRANSFORMATIONS)}")
        missing = [k for k in transformation.required if k not in arguments]
        unknown = [k for k in arguments if k not in transformation.required + transformation.optional]
        if missing or unknown:
            takes = ", ".join(transformation.required + tuple(f"[{o}]" for o in transformation.optional))
            problem = f"needs {', '.join(missing)}" if missing else f"takes no {', '.join(unknown)}"
            raise ExsceError(f"{name} {problem} (it takes {takes})")
        known.update({t.id: t for t in applied.new_tasks})
        applied = applied.then(transformation.apply(applied.scenario, arguments, known))
    derivation_id = new_id or _default_id(base.id, applied)
    if not is_valid_name(derivation_id):
        raise ExsceError(f"'{derivation_id}' cannot be a scenario id")
    if derivation_id == base.id:
        raise ExsceError("the derived scenario needs an id of its own")
    mission = replace(applied.scenario.mission, id=f"{derivation_id}_mission")
    environment = applied.scenario.environment
    environment_changed = environment != base.environment
    if environment_changed:  # another environment under the base's id would clash in the store
        environment = _renamed(environment, f"{derivation_id}_environment")
    scenario = replace(
        applied.scenario, id=derivation_id, mission=mission, environment=environment, location=None
    )
    derivation = Derivation(derivation_id, base.id, applied.steps, applied.origins)
    asked = tuple(Step(name, tuple(arguments.items())) for name, arguments in requests)
    return Derived(scenario, applied.new_tasks, derivation, asked, environment_changed)


def _renamed(environment: Environment, new_id: str) -> Environment:
    """The environment under a new id.  Its obstacles' poses are named by it too: an obstacle's
    pose is named by the obstacle alone (``pose:mast-R.._P.._Y..``, ``point:mast``), so a moved
    one would give the base's point IRI other coordinates when both are in one store."""
    obstacles = tuple(replace(o, pose=replace(o.pose, id=f"{new_id}-{o.id}")) for o in environment.obstacles)
    return replace(environment, id=new_id, obstacles=obstacles)


def _default_id(base: str, applied: Applied) -> str:
    """Deterministic: the base's id and a digest of the steps."""
    text = repr((base, applied.steps))
    return f"{base}_{hashlib.sha256(text.encode()).hexdigest()[:8]}"


def derived_document(derived: Derived, base_spec: Path, target: Path) -> Document:
    """The new file: it imports the base's spec (relative to where it is written) and declares
    the new tasks and the new scenario.

    When the steps changed the environment, the file holds the ``derive NEW from BASE { ... }``
    block instead: the environment cannot be declared again (its poses would be duplicates),
    and building the block makes it.
    """
    relative = os.path.relpath(base_spec.resolve(), target.resolve().parent)
    imports = (Import(Path(relative).as_posix()),)
    if not derived.environment_changed:
        return Document(str(target), imports, (*derived.new_tasks, derived.scenario))
    block = DerivedScenario(
        derived.scenario.id,
        derived.derivation.base,
        derived.requests,
        derived.scenario,
        derived.new_tasks,
        derived.derivation,
    )
    return Document(str(target), imports, (block,))
