"""The method's input transformations, as pure functions on the semantic model, one record each.

Each takes a scenario and its arguments and returns the new scenario, the tasks it
made (a reversed task is a new task) and the step it records; a precondition that
does not hold is an :class:`~exsce_dsl.errors.ExsceError` saying which.  Composite
transformations (``replace_robot``) are made of basic ones and record those.

A new transformation is a function declared with its record (``@transformation(TABLE, phrase,
parameters, records=..., help=...)``, :mod:`exsce_dsl.transform.records`) in the module of what
it changes (mission, tasks, environment, fleet): the record is all the language, the editors and
the docs need of it.
"""

from __future__ import annotations

from exsce_dsl.transform.environment import ENVIRONMENT
from exsce_dsl.transform.fleet import FLEET
from exsce_dsl.transform.mission import MISSION
from exsce_dsl.transform.records import Transformation, registry
from exsce_dsl.transform.tasks import TASKS

TRANSFORMATIONS: dict[str, Transformation] = registry(MISSION, TASKS, ENVIRONMENT, FLEET)
"""Every input transformation, by name."""
