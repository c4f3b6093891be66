"""Compile the derivation of a scenario into W3C PROV, in the method's shape (report Listings 18–34).

:func:`compile_derivation` writes one bundle, ``<new>:scenario_generation``:

* the generation activity ``<new>:generation`` (``prov:type=exsce:generation``),
  which *used* the base scenario ``exsce:<base>`` and *generated* the new one
  ``exsce:<new>``; and ``wasDerivedFrom(exsce:<new>, exsce:<base>, <new>:generation)``;
* one activity per transformation step, ``<new>:step_NN-<transformation>``
  (``prov:type=exsce:transform``, ``exsce:transform=<name>``, ``exsce:step=NN``,
  and each argument as ``exsce:<key>``), each informed by the step before it
  (``wasInformedBy``); the generation was started by the first step and ended
  by the last (``wasStartedBy``/``wasEndedBy`` with the step as starter/ender);
* a task that a step made from another (``reverse_waypoint_order``): the step
  *used* the old task (the method's Listing 26) and *generated* the new one, and
  ``wasDerivedFrom(task:<new>, task:<old>, <step>)``.

Where the method is silent or loose, exsce chooses:

* step identifiers are numbered (``step_01-remove_robot``), where the method made
  them from a transformation's main argument (``remove_robot-tiago2``), which
  collides when a transformation is applied twice;
* steps carry their position (``exsce:step``), so that their order is a fact of
  the graph and not only of the ``wasInformedBy`` chain;
* the generation activity is typed ``exsce:generation`` and the derivation is also
  stated as ``wasDerivedFrom`` (the method had only the generation and usage);
* every argument is an ``exsce:`` attribute (the method wrote ``swap_assignment``'s
  target robot as ``prov:value``).
"""

from __future__ import annotations

from prov.constants import PROV_TYPE
from prov.model import ProvDocument

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.prov.records import Attributes, DocumentWriter

__all__ = ["compile_derivation"]

_RESERVED_KEYS = frozenset({"transform", "step", "scenario", "run"})


def compile_derivation(
    derivation: Derivation, namespace: str = DEFAULT_NAMESPACE, *, checked: bool = False
) -> ProvDocument:
    """The PROV document of how scenario ``derivation.new`` was made from ``derivation.base``."""
    new, base = derivation.new, derivation.base
    ids.check_name(new, "scenario id")
    ids.check_name(base, "base scenario id")
    if new == base:
        raise ExsceError(f"scenario '{new}' cannot be derived from itself")
    names = Namespaces(namespace)
    writer = DocumentWriter(names, checked)
    writer.document_namespace(ids.EXSCE)
    document_parts = writer.element_namespace(new, names.of_scenario(new), "scenario")
    w = writer.bundle(document_parts[ids.GENERATION_BUNDLE], f"the generation of '{new}'")
    t = w.term
    parts = w.of_element(new, names.of_scenario(new), "scenario")
    exsce = w.fixed(ids.EXSCE)
    generation = parts[ids.GENERATION]
    new_id, base_id = exsce[new], exsce[base]
    w.activity(generation, {PROV_TYPE: t(ids.GENERATION_TYPE)})
    w.generated(new_id, generation)
    w.used(generation, base_id)
    w.derivation(new_id, base_id, {}, activity=generation)

    transform_type, transform, step_attr = t(ids.TRANSFORM_TYPE), t(ids.TRANSFORM_ATTR), t(ids.STEP)
    previous = None
    for number, step in enumerate(derivation.steps, start=1):
        activity = parts[ids.transformation_step_name(number, step.transformation)]
        writer.claim(activity, f"step {number} of the derivation of '{new}'")
        facts: Attributes = {PROV_TYPE: transform_type, transform: step.transformation, step_attr: number}
        for key, value in step.parameters:
            ids.check_name(key, "transformation argument")
            if key in _RESERVED_KEYS:
                raise ExsceError(f"'{key}' cannot name an argument of transformation '{step.transformation}'")
            name = exsce[key]
            if name in facts:
                raise ExsceError(f"transformation '{step.transformation}' has argument '{key}' twice")
            facts[name] = value
        w.activity(activity, facts)
        if previous is None:
            w.started(generation, starter=activity)
        else:
            w.informed(activity, previous)
        previous = activity
    if previous is not None:
        w.ended(generation, ender=previous)
    task = w.fixed(ids.TASK)
    for origin in derivation.origins:
        if not 1 <= origin.step <= len(derivation.steps):
            raise ExsceError(f"task '{origin.task}' comes from step {origin.step}, which is not one")
        ids.check_name(origin.task, "task id")
        ids.check_name(origin.source, "task id")
        step = derivation.steps[origin.step - 1]
        made_by = parts[ids.transformation_step_name(origin.step, step.transformation)]
        new_task, old_task = task[origin.task], task[origin.source]
        w.used(made_by, old_task)
        w.generated(new_task, made_by)
        w.derivation(new_task, old_task, {}, activity=made_by)
    return writer.document
