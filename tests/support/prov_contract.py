"""Compare a compiled PROV document with one of the method's published models.

A document is reduced to its *records per bundle*: each entity, agent,
activity and relation with its attributes, relation blank ids (``_:idN``)
dropped and a relation's own identifier kept, every name an IRI.  The
published side is then normalised, one named step per deliberate difference
(:data:`PUBLISHED_FLAWS`), and the two must be equal.
"""

from __future__ import annotations

import datetime
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from prov.identifier import QualifiedName
from prov.model import Literal as ProvLiteral
from prov.model import ProvBundle, ProvDocument

from exsce_dsl.model import Orientation, Scenario
from exsce_dsl.prov import identifiers as ids

PROV = ids.PROV_NAMESPACE
XSD = ids.XSD_NAMESPACE

Value = tuple[str, Any]
"""An attribute value: ("iri", iri), (xsd datatype IRI, Python value) or ("string", text)."""


@dataclass(frozen=True)
class Record:
    kind: str
    """The record type's name: Entity, Agent, Activity, Membership, Derivation..."""
    identifier: str | None
    attributes: frozenset[tuple[str, Value]]

    def __str__(self) -> str:
        attributes = ", ".join(f"{name}={value[1]!r}" for name, value in sorted(self.attributes))
        return f"{self.kind}({self.identifier or '-'}; {attributes})"


Records = dict[str, frozenset[Record]]
"""Bundle IRI → the bundle's records."""


def _value(value: Any) -> Value:
    if isinstance(value, QualifiedName):
        return ("iri", value.uri)
    if isinstance(value, bool):
        return (XSD + "boolean", value)
    if isinstance(value, int):
        return (XSD + "int", value)
    if isinstance(value, float):
        return (XSD + "double", value)
    if isinstance(value, datetime.datetime):
        return (XSD + "dateTime", value.isoformat())
    if isinstance(value, ProvLiteral):
        datatype = value.datatype.uri if value.datatype else "string"
        return (datatype, value.value)
    return ("string", str(value))


def _bundle_records(bundle: ProvBundle) -> frozenset[Record]:
    found = set()
    for record in bundle.get_records():
        kind = str(record.get_type()).removeprefix("prov:")
        attributes = frozenset(
            (name.uri, _value(value))
            for name, value in (*record.formal_attributes, *record.extra_attributes)
            if value is not None
        )
        identifier = record.identifier.uri if record.identifier else None
        found.add(Record(kind, identifier, attributes))
    return frozenset(found)


def records(document: ProvDocument) -> Records:
    """The records of each bundle of ``document`` (the document's own under "")."""
    found: Records = {}
    if document.get_records():
        found[""] = _bundle_records(document)
    for bundle in document.bundles:
        assert bundle.identifier is not None
        found[bundle.identifier.uri] = _bundle_records(bundle)
    return found


def load_records(path: Path) -> Records:
    return records(ProvDocument.deserialize(str(path)))


# -- the published models' flaws, one normalisation each ---------------------


def _map_iris(found: Records, rename: Callable[[str], str]) -> Records:
    def record(r: Record) -> Record:
        return Record(
            r.kind,
            rename(r.identifier) if r.identifier else None,
            frozenset((name, ("iri", rename(v[1])) if v[0] == "iri" else v) for name, v in r.attributes),
        )

    return {rename(bundle): frozenset(map(record, rs)) for bundle, rs in found.items()}


def _map_values(found: Records, change: Callable[[Record, str, Value], Value]) -> Records:
    return {
        bundle: frozenset(
            replace(r, attributes=frozenset((n, change(r, n, v)) for n, v in r.attributes)) for r in rs
        )
        for bundle, rs in found.items()
    }


def task_ids_without_file_suffix(found: Records, scenario: Scenario, base: str) -> Records:
    """Task ids are the file's basename in the method (``task:delivery_a.yaml``), which
    collides across environments; exsce uses the task id (``task:delivery_a``)."""
    pattern = re.compile(re.escape(base) + r"tasks/([^/]+?)\.yaml(?=$|-subtask_\d+|_bundle)")
    return _map_iris(found, lambda iri: pattern.sub(lambda m: f"{base}tasks/{m[1]}", iri))


def exact_pose_ids(found: Records, scenario: Scenario, base: str) -> Records:
    """The method writes angles in pose and orientation ids with two decimals, merging
    different poses; exsce writes them exactly where two decimals are not (0.925, not 0.93).
    The published orientation entities carry the exact angles: rename from those."""
    names = ids.Namespaces(base)
    orientation_ns, pose_ns = names.fixed[ids.ORIENTATION], names.fixed[ids.POSE]
    angles: dict[str, dict[str, float]] = {}
    pose_orientation: dict[str, str] = {}
    for rs in found.values():
        for r in rs:
            if r.kind == "Entity" and r.identifier and r.identifier.startswith(orientation_ns):
                angles[r.identifier] = {
                    name.rsplit("/", 1)[1]: float(v[1])
                    for name, v in r.attributes
                    if name.startswith(names.fixed[ids.ANGLE])
                }
            if r.kind == "Membership":
                attrs = dict(r.attributes)
                collection = attrs[PROV + "collection"][1]
                member = attrs[PROV + "entity"][1]
                if collection.startswith(pose_ns) and member.startswith(orientation_ns):
                    known = pose_orientation.setdefault(collection, member)
                    assert known == member, f"{collection} has two orientations"
    exact: dict[str, str] = {}
    for orientation, a in angles.items():
        exact[orientation] = orientation_ns + ids.orientation_name(
            Orientation(a["roll"], a["pitch"], a["yaw"])
        )
    for pose, orientation in pose_orientation.items():
        stem = re.sub(r"-R[^_]+_P[^_]+_Y[^/]+$", "", pose)
        exact[pose] = f"{stem}-{exact[orientation].removeprefix(orientation_ns)}"
    # A pose used only in a relation (never declared in this document) has no
    # orientation entity here: it cannot be renamed, and the comparison shows it.
    return _map_iris(found, lambda iri: exact.get(iri, iri))


def numbers_as_doubles(found: Records, scenario: Scenario, base: str) -> Records:
    """Coordinates and angles are sometimes ``xsd:int`` in the method (``coord:z=0``);
    exsce writes every number as ``xsd:double``."""

    def change(r: Record, name: str, v: Value) -> Value:
        if v[0] == XSD + "int":
            return (XSD + "double", float(v[1]))
        return v

    return _map_values(found, change)


def types_as_qualified_names(found: Records, scenario: Scenario, base: str) -> Records:
    """The method writes most ``prov:type`` values as strings (``"prov:Plan"``) and a few as
    qualified names (``'ros:GazeboModel'``); exsce writes every type that names a class as a
    qualified name.  Types without a prefix (``"software-config"``) stay strings."""
    prefixes = {"prov": PROV, **ids.Namespaces(base).fixed}

    def change(r: Record, name: str, v: Value) -> Value:
        if name == PROV + "type" and v[0] == "string" and ":" in v[1]:
            prefix, local = v[1].split(":", 1)
            if prefix in prefixes:
                return ("iri", prefixes[prefix] + local)
        return v

    return _map_values(found, change)


def robot_facts_added(found: Records, scenario: Scenario, base: str) -> Records:
    """exsce adds the robot type's facts, which the method leaves out: ``exsce:robotType``
    on ``robot:<id>``, ``exsce:baseType`` and ``exsce:torso`` on ``<id>:hardware-config``,
    and the ROS namespace (``ros:namespace``) on ``<id>:software-config``."""
    names = ids.Namespaces(base)
    added: dict[str, dict[str, Value]] = {}
    for robot in scenario.robots:
        parts = names.of_robot(robot.id)
        added[names.fixed[ids.ROBOT] + robot.id] = {names.iri(ids.ROBOT_TYPE): ("string", robot.type.id)}
        added[parts + "software-config"] = {names.iri(ids.ROS_NAMESPACE): ("string", robot.namespace)}
        hardware: dict[str, Value] = {}
        if robot.type.base is not None:
            hardware[names.iri(ids.BASE_TYPE)] = ("string", robot.type.base)
        if robot.type.torso is not None:
            hardware[names.iri(ids.TORSO)] = (XSD + "boolean", robot.type.torso)
        added[parts + "hardware-config"] = hardware

    def record(r: Record) -> Record:
        extra = added.get(r.identifier or "") if r.kind == "Entity" else None
        if not extra:
            return r
        return replace(r, attributes=r.attributes | frozenset(extra.items()))

    return {bundle: frozenset(map(record, rs)) for bundle, rs in found.items()}


Normalisation = Callable[[Records, Scenario, str], Records]

PUBLISHED_FLAWS: tuple[Normalisation, ...] = (
    task_ids_without_file_suffix,
    exact_pose_ids,
    numbers_as_doubles,
    types_as_qualified_names,
    robot_facts_added,
)
"""Each deliberate difference between exsce's PROV and the published models."""


def normalised_published(path: Path, scenario: Scenario, base: str = ids.DEFAULT_NAMESPACE) -> Records:
    """The records of a published model, with every flaw of :data:`PUBLISHED_FLAWS` undone."""
    found = load_records(path)
    found.pop("", None)  # the published documents hold nothing outside their bundles
    for normalise in PUBLISHED_FLAWS:
        found = normalise(found, scenario, base)
    return found


def differences(ours: Mapping[str, frozenset[Record]], theirs: Records) -> list[str]:
    """What differs, bundle by bundle, as readable lines (empty when equal)."""
    lines = []
    for bundle in sorted(set(ours) | set(theirs)):
        if bundle not in theirs:
            lines.append(f"bundle {bundle}: only in ours")
            continue
        if bundle not in ours:
            lines.append(f"bundle {bundle}: only in the published model")
            continue
        for r in sorted(ours[bundle] - theirs[bundle], key=str):
            lines.append(f"{bundle}: only ours: {r}")
        for r in sorted(theirs[bundle] - ours[bundle], key=str):
            lines.append(f"{bundle}: only published: {r}")
    return lines
