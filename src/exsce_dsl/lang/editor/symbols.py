"""What a file declares and what it names, with where: for editors.

The semantic model exists only when a specification is valid; an editor needs
its outline, its references and their places while the text is still wrong.
:func:`index_file` reads them off one file's parse tree (however much of it
parsed) into plain data: :class:`Symbol` for each declaration, with its
children (an environment's areas and their poses, a scenario's robots and
mission), and :class:`Reference` for each name that points at one.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.poses import position_of
from exsce_dsl.lang.lexical import quantity_text
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.lang.transformation_syntax import step_of, step_references
from exsce_dsl.transform import TRANSFORMATIONS

# The references each construct of the grammar holds: attribute -> kind of what it names.
_REFERENCES: dict[str, dict[str, str]] = {
    "RobotDecl": {"type": "robot type"},
    "Scenario": {"environment": "environment"},
    "PoseUse": {"pose": "pose"},
    "Assignment": {"robot": "robot", "tasks": "task"},
    "Acceptance": {"scenario": "scenario"},
    "OneRobot": {"robot": "robot"},
    "RobotDoes": {"robot": "robot", "task": "task"},
    "MissionRuns": {"mission": "mission"},
    "Expectation": {"metric": "metric"},
    "EventWindow": {"robot": "robot", "pose": "pose"},
    "TaskWindow": {"task": "task"},
    "Against": {"scenario": "scenario"},
    "Derivation": {"base": "scenario"},
    **step_references(),  # a derive step's, from its transformation's record
}

_MADE = {"new_robot": "robot", "new_task": "task"}
"""What a step's argument of each of these types declares."""

SCOPED_KINDS = frozenset({"robot", "mission"})
"""Kinds whose names are a scenario's own (``scope`` says which scenario)."""


@dataclass(frozen=True)
class Symbol:
    """A declaration: what it is, its name and where, and what an editor shows of it."""

    kind: str
    """``robot type``, ``environment``, ``area``, ``pose``, ``obstacle``, ``map``, ``world``,
    ``task``, ``scenario``, ``robot``, ``mission``, ``metric``, ``acceptance`` or ``criterion``."""
    name: str
    location: SourceLocation
    """Of the name."""
    extent: SourceLocation
    """Of the whole declaration."""
    scope: str | None = None
    """A robot's or mission's scenario; an area's, pose's or obstacle's environment."""
    facts: tuple[tuple[str, str], ...] = ()
    """What it says, as (label, text): a pose's area and coordinates, a task's waypoints..."""
    children: tuple[Symbol, ...] = ()

    def fact(self, label: str) -> str | None:
        return next((text for key, text in self.facts if key == label), None)

    def walk(self) -> Iterator[Symbol]:
        yield self
        for child in self.children:
            yield from child.walk()


@dataclass(frozen=True)
class Reference:
    """A name that stands for a declaration of ``kind``."""

    kind: str
    name: str
    location: SourceLocation
    scope: str | None = None
    """For robots and missions: the scenario they belong to (a derived one's are its base's too)."""


@dataclass(frozen=True)
class IndexedImport:
    path: str
    """As written."""
    location: SourceLocation
    """Of the string."""


@dataclass(frozen=True)
class FileIndex:
    path: str
    symbols: tuple[Symbol, ...]
    """The top-level declarations, each with its children."""
    references: tuple[Reference, ...]
    imports: tuple[IndexedImport, ...] = ()

    def all_symbols(self) -> Iterator[Symbol]:
        for symbol in self.symbols:
            yield from symbol.walk()


def index_file(pf: ParsedFile) -> FileIndex:
    """The declarations and references of one parsed file."""
    reader = _Reader(pf)
    symbols = tuple(s for decl in pf.tree.declarations if (s := reader.declaration(decl)) is not None)
    imports = tuple(IndexedImport(i.path, pf.span(i)) for i in pf.tree.imports)
    return FileIndex(pf.path, symbols, tuple(reader.references), imports)


class _Reader:
    def __init__(self, pf: ParsedFile) -> None:
        self.pf = pf
        self.references: list[Reference] = []

    # -------------------------------------------------------------- helpers
    def text(self, obj: Any) -> str:
        return " ".join(self.pf.text[obj._tx_position : obj._tx_position_end].split())

    def name_span(self, obj: Any, name: str | None = None) -> SourceLocation:
        """The span of ``name`` (``obj.name`` by default), its first whole-word occurrence in ``obj``."""
        text, name = self.pf.text, name or obj.name
        start = text.find(name, obj._tx_position, obj._tx_position_end)
        while start >= 0:
            before = text[start - 1] if start else " "
            end = start + len(name)
            after = text[end] if end < len(text) else " "
            if not (before.isalnum() or before in "_-") and not (after.isalnum() or after in "_-"):
                return self.pf.lines.span(start, end)
            start = text.find(name, start + 1, obj._tx_position_end)
        return self.pf.span(obj)

    def symbol(
        self,
        kind: str,
        obj: Any,
        name: str | None = None,
        scope: str | None = None,
        facts: list[tuple[str, str]] | None = None,
        children: list[Symbol] | None = None,
    ) -> Symbol:
        name = name or obj.name
        return Symbol(
            kind,
            name,
            self.name_span(obj, name),
            self.pf.span(obj),
            scope,
            tuple((k, v) for k, v in (facts or []) if v),
            tuple(children or ()),
        )

    def collect(self, obj: Any, scope: str | None) -> None:
        """Every reference inside ``obj`` (robots and missions said of scenario ``scope``)."""
        stack: list[Any] = [obj]
        while stack:
            node = stack.pop()
            table = _REFERENCES.get(node.__class__.__name__, {})
            for attr in node._tx_attrs:
                value = getattr(node, attr, None)
                values: list[Any] = value if isinstance(value, list) else [value]
                kind = table.get(attr)
                for item in values:
                    if not hasattr(item, "_tx_position"):
                        continue
                    if kind is not None and item.__class__.__name__ == "Ref":
                        where = self.pf.span(item)
                        self.references.append(
                            Reference(kind, item.name, where, scope if kind in SCOPED_KINDS else None)
                        )
                    else:
                        stack.append(item)

    # --------------------------------------------------------- declarations
    def declaration(self, decl: Any) -> Symbol | None:
        kind = decl.__class__.__name__
        method = getattr(self, f"_{kind.lower()}", None)
        return method(decl) if method is not None else None

    def _robottype(self, decl: Any) -> Symbol:
        facts = []
        for fact in decl.facts:
            if fact.__class__.__name__ == "BaseFact":
                facts.append(("base", str(fact.base)))
            else:
                facts.append(("torso", str(fact.torso)))
        return self.symbol("robot type", decl, facts=facts)

    def _environment(self, decl: Any) -> Symbol:
        children = []
        for member in decl.members:
            kind = member.__class__.__name__
            if kind == "Area":
                poses = [self._pose(pose, member.name, decl.name) for pose in member.poses]
                facts = [("environment", decl.name), ("poses", str(len(poses)))]
                children.append(self.symbol("area", member, scope=decl.name, facts=facts, children=poses))
            elif kind == "Obstacle":
                facts = [
                    ("environment", decl.name),
                    ("at", self.text(member.position)),
                    ("heading", self.text(member.orientation) if member.orientation else ""),
                    ("model", member.model or ""),
                ]
                children.append(self.symbol("obstacle", member, scope=decl.name, facts=facts))
            else:
                word = "map" if kind == "MapModel" else "world"
                source = self.text(member.source) if member.source else ""
                facts = [("from", source), ("file", getattr(member, "file", "") or "")]
                children.append(self.symbol(word, member, scope=decl.name, facts=facts))
        areas = [c for c in children if c.kind == "area"]
        facts = [("areas", str(len(areas))), ("poses", str(sum(len(a.children) for a in areas)))]
        return self.symbol("environment", decl, facts=facts, children=children)

    def _pose(self, pose: Any, area: str, environment: str) -> Symbol:
        p = position_of(pose.position)
        facts = [
            ("area", area),
            ("environment", environment),
            ("at", self.text(pose.position)),
            ("heading", self.text(pose.orientation) if pose.orientation else ""),
            ("position", f"x {p.x:g} m, y {p.y:g} m, z {p.z:g} m"),
        ]
        return self.symbol("pose", pose, scope=environment, facts=facts)

    def _task(self, decl: Any) -> Symbol:
        self.collect(decl, None)
        facts = []
        subtasks = list(decl.subtasks)
        for number, sub in enumerate(subtasks, start=1):
            waypoints = [self.text(wp) for visit in sub.visits for wp in visit.waypoints]
            label = "waypoints" if len(subtasks) == 1 else f"subtask {number}"
            facts.append((label, ", ".join(waypoints)))
        if decl.source is not None:
            facts.append(("source", self.text(decl.source)))
        if decl.timeout is not None:
            facts.append(("goal timeout", quantity_text(decl.timeout.duration)))
        return self.symbol("task", decl, facts=facts)

    def _scenario(self, decl: Any) -> Symbol:
        self.collect(decl, decl.name)
        children = []
        for robot in decl.robots:
            facts = [
                ("type", robot.type.name),
                ("namespace", robot.namespace or robot.name),
                ("starts at", robot.start.pose.name if robot.start else ""),
            ]
            children.append(self.symbol("robot", robot, scope=decl.name, facts=facts))
        mission = decl.mission
        facts = [("environment", decl.environment.name), ("robots", ", ".join(r.name for r in decl.robots))]
        if mission is not None:
            allocation = [
                f"{a.robot.name}: {' then '.join(t.name for t in a.tasks)}" for a in mission.assignments
            ]
            mission_facts = [("type", mission.kind), ("allocation", "; ".join(allocation))]
            if mission.timeout is not None:
                mission_facts.append(("goal timeout", quantity_text(mission.timeout.duration)))
            children.append(self.symbol("mission", mission, scope=decl.name, facts=mission_facts))
            facts.append(("mission", f"{mission.name} ({mission.kind})"))
        return self.symbol("scenario", decl, facts=facts, children=children)

    def _acceptance(self, decl: Any) -> Symbol:
        scenario = decl.scenario.name
        self.collect(decl, scenario)
        children = [
            self.symbol("criterion", c, name=c.title, scope=scenario, facts=[("of", scenario)])
            for c in decl.criteria
        ]
        return self.symbol("acceptance", decl, name=scenario, facts=[("for", scenario)], children=children)

    def _derivation(self, decl: Any) -> Symbol:
        self.collect(decl, decl.name)
        facts = [("derived from", decl.base.name)]
        children = []
        for number, node in enumerate(decl.steps, start=1):
            name, arguments = step_of(node)
            given = " ".join(f"{k}={v}" for k, v in arguments.items() if v is not None)
            facts.append((f"step {number}", f"{name} {given}".strip()))
            for parameter, made in arguments.items():
                kind = _MADE.get(TRANSFORMATIONS[name].type_of(parameter))
                if kind is None or made is None:
                    continue
                said = [("made by", name)] + [(k, v) for k, v in arguments.items() if k != parameter and v]
                scope = decl.name if kind == "robot" else None
                children.append(self.symbol(kind, node, name=made, scope=scope, facts=said))
        return self.symbol("scenario", decl, facts=facts, children=children)

    def _metric(self, decl: Any) -> Symbol:
        if decl.mission:
            subject = "the mission"
        elif decl.pairs is not None:
            subject = "each pair of robots"
        else:
            subject = "each robot"
        facts = [
            ("of", subject + (", per segment" if decl.per_segment else "")),
            ("meaning", decl.meaning or ""),
            ("unit", decl.unit or ""),
            ("safe", self.text(decl.safety)[len("safe ") :] if decl.safety else ""),
            ("reads", "; ".join(self.text(r)[len("reads ") :] for r in decl.reads)),
            ("value", self.text(decl.value)),
            ("otherwise", self.text(decl.fallback) if decl.fallback else ""),
        ]
        return self.symbol("metric", decl, facts=facts)
