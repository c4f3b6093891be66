"""Moving a store's robots to the names they have now (:func:`~exsce_dsl.prov.identifiers.robot_name`).

Before issue 48 every robot was named by its id alone (``robot:root_robot``), so two scenarios
could not give one id to two robots.  Now a robot whose namespace is not its id is named by its
id and a digest of its declaration (``robot:root_robot.1a2b3c4d``).  :func:`old_robot_names`
finds the stored robots still named the old way, from what their bundles say (type, namespace,
hardware), and :func:`renamed_robot_graphs` gives the writes that rename them: the robot, its
parts (``robots/<id>/...``) and its bundle, in every graph that names them (its scenario's, its
runs').  Revision graphs are history and keep the names they had.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeVar

from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.model.robots import Robot, RobotType
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, PROV_NAMESPACE, Namespaces
from exsce_dsl.store.base import Store
from exsce_dsl.store.sparql import term_text

__all__ = ["RobotRename", "old_robot_names", "renamed_robot_graphs"]

_Term = TypeVar("_Term")


@dataclass(frozen=True)
class RobotRename:
    """A robot's IRI under its old name, and the one it has now."""

    old: str
    new: str


def old_robot_names(store: Store, namespace: str = DEFAULT_NAMESPACE) -> list[RobotRename]:
    """The stored robots (outside revisions) whose IRI is not the one their declaration gives."""
    names = Namespaces(namespace)
    robots = names.fixed[ids.ROBOT]

    def iri(term: ids.Term) -> str:
        return term_text(NamedNode(names.iri(term)))

    prov_type = term_text(NamedNode(PROV_NAMESPACE + "type"))
    member = term_text(NamedNode(PROV_NAMESPACE + "hadMember"))
    rows = store.select(
        "SELECT ?robot ?type ?ns ?base ?torso WHERE {\n"
        f"  GRAPH ?g {{ ?robot a {iri(ids.ROBOT_TYPE_VALUE)} ; {member} ?software .\n"
        f'    ?software {prov_type} "{ids.SOFTWARE_CONFIG}" ; {iri(ids.ROS_NAMESPACE)} ?ns .\n'
        f"    OPTIONAL {{ ?robot {iri(ids.ROBOT_TYPE)} ?type }}\n"
        f'    OPTIONAL {{ ?robot {member} ?hardware . ?hardware {prov_type} "{ids.HARDWARE_CONFIG}" .\n'
        f"      OPTIONAL {{ ?hardware {iri(ids.BASE_TYPE)} ?base }}\n"
        f"      OPTIONAL {{ ?hardware {iri(ids.TORSO)} ?torso }} }} }}\n"
        '  FILTER(!CONTAINS(STR(?g), "revision="))\n'
        "}"
    )
    renames = []
    for robot, kind, ros_namespace, base, torso in rows.rows:
        if not isinstance(robot, NamedNode) or not robot.value.startswith(robots):
            continue
        local = robot.value[len(robots) :]
        text = [
            term.value if isinstance(term, Literal) else None for term in (kind, ros_namespace, base, torso)
        ]
        robot_type = RobotType(text[0] or "", text[2], None if text[3] is None else text[3] in ("true", "1"))
        now = ids.robot_name(Robot(ids.robot_id_of_name(local), robot_type, text[1] or ""))
        if now != local:
            renames.append(RobotRename(robot.value, robots + now))
    return sorted(set(renames), key=lambda r: r.old)


def renamed_robot_graphs(store: Store, renames: Sequence[RobotRename]) -> dict[str, list[Quad]]:
    """The writes that rename ``renames``: each graph naming an old robot, or part of one, written
    again with the new names (a robot's old bundle emptied, its quads under the new name)."""
    if not renames:
        return {}
    mentions = " || ".join(
        f"?t = {term_text(NamedNode(r.old))} || STRSTARTS(STR(?t), {term_text(Literal(r.old + '/'))})"
        for r in renames
    )
    rows = store.select(
        "SELECT DISTINCT ?g WHERE {\n"
        "  GRAPH ?g { { ?t ?p ?o } UNION { ?s ?p ?t } }\n"
        f'  FILTER(isIRI(?t) && ({mentions}) && !CONTAINS(STR(?g), "revision="))\n'
        "}"
    )
    graphs = sorted(str(row[0].value) for row in rows.rows if isinstance(row[0], NamedNode))
    moved = {r.old: r.new for r in renames}

    def move(name: str) -> str:
        for old, new in moved.items():
            if name == old or name.startswith(old + "/") or name == old + "_bundle":
                return new + name[len(old) :]
        return name

    writes: dict[str, list[Quad]] = {}
    for graph, quads in store.graphs(graphs).items():
        target = move(graph)
        writes.setdefault(graph, [])
        writes.setdefault(target, []).extend(
            Quad(_moved(q.subject, move), q.predicate, _moved(q.object, move), NamedNode(target))
            for q in quads
        )
    return writes


def _moved(term: _Term, move: Callable[[str], str]) -> _Term:
    """``term`` renamed by ``move`` when it is an IRI."""
    return NamedNode(move(term.value)) if isinstance(term, NamedNode) else term  # type: ignore[return-value]
