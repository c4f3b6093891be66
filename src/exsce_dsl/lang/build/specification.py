"""Build the semantic model from parse trees, resolving every reference.

References are resolved here rather than by textX so that *every* unknown
name is reported (with a did-you-mean), not only the first one.  Checks that
need the whole scenario live in :mod:`exsce_dsl.lang.build.checks`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from exsce_dsl.errors import Diagnostic, Severity, SourceLocation, SpecError, diagnostic_order
from exsce_dsl.lang.build.acceptance import build_all_acceptance
from exsce_dsl.lang.build.derivation import build_derivations
from exsce_dsl.lang.build.metrics import build_metric
from exsce_dsl.lang.build.poses import orientation_of, position_of
from exsce_dsl.lang.build.signals import build_signals
from exsce_dsl.lang.build.checks import check_environment_map, check_scenario
from exsce_dsl.lang.lexical import quantity_parts, quantity_text, read_angle, read_duration, read_length
from exsce_dsl.lang.loader import Parse, read_sources
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.lang.build.references import UnknownNames, not_in_fleet
from exsce_dsl.lang.build.standard_metrics import reserved_metric_names
from exsce_dsl.model import (
    Acceptance,
    Area,
    Assignment,
    Document,
    Environment,
    Import,
    MapModel,
    Mission,
    MissionType,
    Obstacle,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    RosResource,
    Scenario,
    Specification,
    Subtask,
    Task,
    WorldModel,
)
from exsce_dsl.model.derived import DerivedScenario
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.robots import root_namespace

_KIND_WORDS = {
    "RobotType": "robot type",
    "Environment": "environment",
    "Task": "task",
    "Scenario": "scenario",
    "Metric": "metric",
}


@dataclass
class Analysis:
    """What :func:`analyse` found: the model if it is valid, and every diagnostic."""

    spec: Specification | None
    diagnostics: list[Diagnostic] = field(default_factory=list)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.is_error]


def load_spec(path: str | Path, overlay: Mapping[str, str] | None = None) -> Specification:
    """Parse, resolve and check a specification; raise :class:`SpecError` listing every error
    (and the notes about them)."""
    return load_spec_reading(path, overlay)[0]


def load_spec_reading(
    path: str | Path, overlay: Mapping[str, str] | None = None
) -> tuple[Specification, tuple[str, ...]]:
    """:func:`load_spec`, also naming the ``.exsce`` files it read (the root first), for
    :mod:`exsce_dsl.lang.spec_cache`."""
    sources = read_sources(path, overlay)
    analysis = analyse_files(sources.files, sources.diagnostics, sources.broken)
    if analysis.errors or analysis.spec is None:
        told = [d for d in analysis.diagnostics if d.is_error or d.severity is Severity.NOTE]
        raise SpecError(told or analysis.diagnostics)
    return analysis.spec, tuple(f.path for f in sources.files)


def analyse(path: str | Path, overlay: Mapping[str, str] | None = None) -> Analysis:
    """Like :func:`load_spec`, but return diagnostics instead of raising (for editors and ``check``)."""
    sources = read_sources(path, overlay)
    return analyse_files(sources.files, sources.diagnostics, sources.broken)


def analyse_files(
    files: list[ParsedFile],
    diagnostics: list[Diagnostic],
    broken: Mapping[str, str] | None = None,
    parse: Parse | None = None,
) -> Analysis:
    """:func:`analyse` of files already parsed (the root first), with the problems found reading
    them; ``broken`` has the text of each file with a syntax error (the names they seem to
    declare are not reported unknown: see :mod:`exsce_dsl.lang.build.references`), and ``parse``
    reads the files not imported where an unknown name may be declared."""
    diagnostics = list(diagnostics)
    unknown = UnknownNames(files, broken, parse)
    builder = _Builder(files, unknown)
    spec = builder.build() if files else None
    diagnostics.extend(builder.diagnostics)
    diagnostics.extend(unknown.notes(diagnostics))
    unique = sorted(set(diagnostics), key=diagnostic_order)
    has_errors = any(d.is_error for d in unique)
    return Analysis(None if has_errors else spec, unique)


@dataclass
class _Declared:
    obj: Any
    file: ParsedFile
    name_location: SourceLocation


class _Builder:
    def __init__(self, files: list[ParsedFile], unknown: UnknownNames) -> None:
        self.files = files
        self.unknown = unknown
        self.diagnostics: list[Diagnostic] = []
        self.declared: dict[str, dict[str, _Declared]] = {k: {} for k in _KIND_WORDS}
        self.robot_types: dict[str, RobotType] = {}
        self.environments: dict[str, Environment] = {}
        self.tasks: dict[str, Task] = {}
        self.scenarios: dict[str, Scenario] = {}
        self.metrics: dict[str, MetricDefinition] = {}
        # pose id -> the environments declaring it, with the pose
        self.poses: dict[str, list[tuple[str, Pose]]] = {}
        self.task_poses: dict[str, Pose | None] = {}
        self.acceptance: dict[int, Acceptance] = {}
        self.derived: dict[int, DerivedScenario] = {}
        """Built acceptance blocks, by the id of their parse tree node."""

    # ---------------------------------------------------------------- helpers
    def error(self, message: str, location: SourceLocation | None, code: str = "semantic") -> None:
        self.diagnostics.append(Diagnostic(message, location, code=code))

    def warning(self, message: str, location: SourceLocation | None, code: str = "semantic") -> None:
        self.diagnostics.append(Diagnostic(message, location, Severity.WARNING, code=code))

    def metric_problem(
        self, message: str, location: SourceLocation | None, severity: Severity = Severity.ERROR
    ) -> None:
        self.diagnostics.append(Diagnostic(message, location, severity, code="metric"))

    def unknown_name(self, kind: str, name: str, at: SourceLocation, known: Iterable[str]) -> None:
        """Report that no file read declares ``name`` (unless a file with a syntax error may)."""
        message = self.unknown.message(kind, name, at, known)
        if message is not None:
            self.error(message, at, code="reference")

    @staticmethod
    def name_span(pf: ParsedFile, obj: Any) -> SourceLocation:
        """The span of ``obj.name`` inside the text of ``obj``."""
        text, name, end = pf.text, obj.name, obj._tx_position_end
        start = text.find(name, obj._tx_position, end)
        while start >= 0:  # the first whole-word occurrence (`t` in `task t` is not the one in `task`)
            before = text[start - 1] if start else " "
            after = text[start + len(name)] if start + len(name) < len(text) else " "
            if not (before.isalnum() or before in "_-") and not (after.isalnum() or after in "_-"):
                return pf.lines.span(start, start + len(name))
            start = text.find(name, start + 1, end)
        return pf.span(obj)

    # ------------------------------------------------------------------ build
    def build(self) -> Specification:
        for pf in self.files:
            for decl in pf.tree.declarations:
                if decl.__class__.__name__ not in ("Acceptance", "Derivation"):
                    self._declare(pf, decl)
        for name, d in self.declared["RobotType"].items():
            self.robot_types[name] = self._robot_type(d)
        for name, d in self.declared["Environment"].items():
            self.environments[name] = self._environment(d)
        reserved = reserved_metric_names()
        for name, d in self.declared["Metric"].items():
            metric = build_metric(
                d.file,
                d.obj,
                self.metric_problem,
                reserved,
                name_location=d.name_location,
            )
            if metric is not None:
                self.metrics[name] = metric
        self.task_poses = self._task_pose_candidates()
        for name, d in self.declared["Task"].items():
            task = self._task(d)
            if task is not None:
                self.tasks[name] = task
        for name, d in self.declared["Scenario"].items():
            scenario = self._scenario(d)
            if scenario is not None:
                self.scenarios[name] = replace(scenario, metrics=tuple(self.metrics.values()))
        for env in self.environments.values():
            self.diagnostics.extend(check_environment_map(env))
        for scenario in self.scenarios.values():
            self.diagnostics.extend(check_scenario(scenario))
        self._derivations()
        self._acceptance()
        return Specification(self.files[0].path, tuple(self._document(pf) for pf in self.files))

    def _declare(self, pf: ParsedFile, decl: Any) -> None:
        kind = decl.__class__.__name__
        table = self.declared[kind]
        where = self.name_span(pf, decl)
        first = table.get(decl.name)
        if first is not None:
            self.error(
                f"duplicate {_KIND_WORDS[kind]} '{decl.name}' (first declared at {first.name_location})",
                where,
            )
            return
        table[decl.name] = _Declared(decl, pf, where)

    def _derivations(self) -> None:
        self.derived = build_derivations(
            self.files,
            self.scenarios,
            self.declared["Scenario"],
            self.tasks,
            lambda message, at: self.error(message, at, code="derivation"),
            lambda pf, decl: _Declared(decl, pf, self.name_span(pf, decl)),
            self.unknown,
        )

    def _acceptance(self) -> None:
        self.acceptance = build_all_acceptance(
            self.files,
            self.scenarios,
            self.declared["Scenario"],
            lambda message, at: self.error(message, at, code="acceptance"),
            self.unknown,
        )

    def _document(self, pf: ParsedFile) -> Document:
        imports = tuple(Import(i.path, pf.span(i)) for i in pf.tree.imports)
        tables: dict[str, Mapping[str, Any]] = {
            "RobotType": self.robot_types,
            "Environment": self.environments,
            "Task": self.tasks,
            "Scenario": self.scenarios,
            "Metric": self.metrics,
        }
        declarations: list[Any] = []
        for decl in pf.tree.declarations:
            kind = decl.__class__.__name__
            if kind == "Acceptance":
                if id(decl) in self.acceptance:
                    declarations.append(self.acceptance[id(decl)])
                continue
            if kind == "Derivation":
                if id(decl) in self.derived:
                    declarations.append(self.derived[id(decl)])
                continue
            declared = self.declared[kind].get(decl.name)
            built = tables[kind].get(decl.name)
            if built is not None and declared is not None and declared.obj is decl:
                declarations.append(built)
        return Document(pf.path, imports, tuple(declarations))

    # ------------------------------------------------------------ robot types
    def _robot_type(self, d: _Declared) -> RobotType:
        base: str | None = None
        torso: bool | None = None
        motion = "planar"
        seen: set[str] = set()
        words = {"BaseFact": "base", "TorsoFact": "torso", "MotionFact": "motion"}
        for fact in d.obj.facts:
            kind = fact.__class__.__name__
            if kind not in words:
                continue  # where its signals are: build_signals
            if kind in seen:
                self.error(f"robot type '{d.obj.name}' states its {words[kind]} twice", d.file.span(fact))
            seen.add(kind)
            if kind == "BaseFact":
                base = fact.base
            elif kind == "TorsoFact":
                torso = fact.torso == "yes"
            else:
                motion = fact.motion
        signals = build_signals(f"robot type '{d.obj.name}'", d.obj.facts, d.file.span, self.error)
        return RobotType(d.obj.name, base, torso, d.name_location, signals, motion)

    # ----------------------------------------------------------- environments
    def _environment(self, d: _Declared) -> Environment:
        pf, env = d.file, d.obj
        map_model: MapModel | None = None
        world: WorldModel | None = None
        areas: list[Area] = []
        obstacles: list[Obstacle] = []
        pose_seen: dict[str, SourceLocation] = {}
        area_seen: dict[str, SourceLocation] = {}
        obstacle_seen: dict[str, SourceLocation] = {}
        for member in env.members:
            kind = member.__class__.__name__
            if kind == "MapModel":
                if map_model is not None:
                    self.error(f"environment '{env.name}' has two maps", pf.span(member))
                    continue
                file = None
                if member.file:
                    file = str(Path(pf.path).parent / member.file)
                map_model = MapModel(member.name, _ros(member.source), file, pf.span(member))
            elif kind == "WorldModel":
                if world is not None:
                    self.error(f"environment '{env.name}' has two worlds", pf.span(member))
                    continue
                world = WorldModel(member.name, _ros(member.source), pf.span(member))
            elif kind == "Area":
                where = self.name_span(pf, member)
                if member.name in area_seen:
                    self.error(
                        f"duplicate area '{member.name}' in environment '{env.name}' "
                        f"(first declared at {area_seen[member.name]})",
                        where,
                    )
                    continue
                area_seen[member.name] = where
                poses = []
                for decl in member.poses:
                    pwhere = self.name_span(pf, decl)
                    if decl.name in pose_seen:
                        self.error(
                            f"duplicate pose '{decl.name}' in environment '{env.name}' "
                            f"(first declared at {pose_seen[decl.name]})",
                            pwhere,
                        )
                        continue
                    pose_seen[decl.name] = pwhere
                    pose = Pose(
                        decl.name,
                        position_of(decl.position),
                        orientation_of(decl.orientation),
                        member.name,
                        pwhere,
                    )
                    poses.append(pose)
                    self.poses.setdefault(decl.name, []).append((env.name, pose))
                areas.append(Area(member.name, tuple(poses), where))
            else:  # Obstacle
                where = self.name_span(pf, member)
                if member.name in obstacle_seen:
                    self.error(
                        f"duplicate obstacle '{member.name}' in environment '{env.name}' "
                        f"(first declared at {obstacle_seen[member.name]})",
                        where,
                    )
                    continue
                obstacle_seen[member.name] = where
                size = None
                size_written: tuple[str, ...] = ()
                if member.sx is not None:
                    dims = [member.sx, member.sy] + ([member.sz] if member.sz is not None else [])
                    size = tuple(read_length(v) for v in dims)
                    size_written = tuple(dims)
                pose = Pose(
                    member.name,
                    position_of(member.position),
                    orientation_of(member.orientation),
                    None,
                    where,
                )
                obstacles.append(Obstacle(member.name, pose, member.model or None, size, where, size_written))
        return Environment(env.name, map_model, world, tuple(areas), tuple(obstacles), d.name_location)

    # ------------------------------------------------------------------ tasks
    def _task(self, d: _Declared) -> Task | None:
        pf, task = d.file, d.obj
        subtasks: list[Subtask] = []
        ok = True
        coordinate_count = 0
        for number, sub in enumerate(task.subtasks, start=1):
            waypoints: list[Pose] = []
            for visit in sub.visits:
                for wp in visit.waypoints:
                    if wp.__class__.__name__ == "CoordinateWaypoint":
                        coordinate_count += 1
                        waypoints.append(
                            Pose(
                                f"{task.name}-w{coordinate_count:03d}",
                                position_of(wp.position),
                                orientation_of(wp.orientation),
                                None,
                                pf.span(wp),
                            )
                        )
                        continue
                    pose = self._pose_use(pf, wp, self.task_poses)
                    if pose is None:
                        ok = False
                    else:
                        waypoints.append(pose)
            if not sub.visits and sub.__class__.__name__ == "Subtask":
                self.error(f"subtask {number} of task '{task.name}' has no waypoints", pf.span(sub))
                ok = False
            subtasks.append(Subtask(tuple(waypoints), pf.span(sub)))
        if not task.subtasks:
            self.error(f"task '{task.name}' has no waypoints; add 'visit <pose>'", d.name_location)
            ok = False
        timeout, written, fine = self._timeout(pf, task.timeout, f"task '{task.name}'")
        if not ok or not fine:
            return None
        return Task(task.name, tuple(subtasks), _ros(task.source), d.name_location, timeout, written)

    def _task_pose_candidates(self) -> dict[str, Pose | None]:
        """Pose ids a task may name: unambiguous ones map to their pose."""
        table: dict[str, Pose | None] = {}
        for pose_id, found in self.poses.items():
            distinct = {(p.position, p.orientation) for _, p in found}
            table[pose_id] = found[0][1] if len(distinct) == 1 else None
        return table

    def _pose_use(self, pf: ParsedFile, use: Any, table: Mapping[str, Pose | None]) -> Pose | None:
        name = use.pose.name
        where = pf.span(use.pose)
        if name not in table:
            self.unknown_name("pose", name, where, table)
            return None
        pose = table[name]
        if pose is None:
            envs = ", ".join(sorted(e for e, _ in self.poses[name]))
            self.error(
                f"pose '{name}' is declared differently in environments {envs}; "
                "a task cannot tell which one it means",
                where,
                code="reference",
            )
            return None
        loc = pf.span(use)
        if use.orientation is not None:
            return Pose(pose.id, pose.position, orientation_of(use.orientation), pose.area, loc)
        return Pose(pose.id, pose.position, pose.orientation, pose.area, loc)

    # -------------------------------------------------------------- scenarios
    def _scenario(self, d: _Declared) -> Scenario | None:
        pf, sc = d.file, d.obj
        ok = True
        env = self.environments.get(sc.environment.name)
        if env is None:
            self.unknown_name("environment", sc.environment.name, pf.span(sc.environment), self.environments)
            ok = False
        env_poses: dict[str, Pose | None] = {p.id: p for p in env.poses()} if env else {}

        robots: list[Robot] = []
        robot_seen: dict[str, SourceLocation] = {}
        for decl in sc.robots:
            where = self.name_span(pf, decl)
            if decl.name in robot_seen:
                self.error(
                    f"duplicate robot '{decl.name}' in scenario '{sc.name}' "
                    f"(first declared at {robot_seen[decl.name]})",
                    where,
                )
                ok = False
                continue
            robot_seen[decl.name] = where
            rtype = self.robot_types.get(decl.type.name)
            if rtype is None:
                self.unknown_name("robot type", decl.type.name, pf.span(decl.type), self.robot_types)
                ok = False
            start = None
            if decl.start is not None and env is not None:
                if decl.start.pose.name not in env_poses and decl.start.pose.name in self.poses:
                    self.error(
                        f"start pose '{decl.start.pose.name}' of robot '{decl.name}' is not in "
                        f"environment '{env.id}'",
                        pf.span(decl.start.pose),
                        code="reference",
                    )
                    ok = False
                else:
                    start = self._pose_use(pf, decl.start, env_poses)
                    ok = ok and start is not None
            namespace = root_namespace(decl.namespace) if decl.has_namespace else decl.name
            if rtype is not None:
                own = build_signals(
                    f"robot '{decl.name}'", decl.overrides, pf.span, self.error, rtype.signals
                )
                if own == rtype.signals:
                    own = None  # it says what its type says
                robots.append(Robot(decl.name, rtype, namespace, start, where, own))

        mission = self._mission(pf, sc, robot_seen)
        if mission is None or env is None or not ok:
            return None
        used: dict[str, Task] = {}
        for entry in mission.allocation:
            task = self.tasks.get(entry.task)
            if task is None:
                return None  # reported where the task is declared or referenced
            used.setdefault(task.id, task)
        return Scenario(sc.name, env, tuple(robots), mission, tuple(used.values()), d.name_location)

    def _mission(self, pf: ParsedFile, sc: Any, fleet: Mapping[str, SourceLocation]) -> Mission | None:
        m = sc.mission
        if m is None:
            self.error(
                f"scenario '{sc.name}' has no mission; add 'mission <id> parallel {{ ... }}'",
                self.name_span(pf, sc),
            )
            return None
        allocation: list[Assignment] = []
        ok = True
        for line in m.assignments:
            robot = line.robot.name
            if robot not in fleet:
                self.error(not_in_fleet(robot, sc.name, fleet), pf.span(line.robot), code="reference")
                ok = False
            for ref in line.tasks:
                if ref.name not in self.declared["Task"]:
                    self.unknown_name("task", ref.name, pf.span(ref), self.declared["Task"])
                    ok = False
                allocation.append(Assignment(robot, ref.name, pf.span(ref)))
        if not m.assignments:
            self.error(f"mission '{m.name}' allocates no task", self.name_span(pf, m))
            ok = False
        timeout, written, fine = self._timeout(pf, m.timeout, f"mission '{m.name}'")
        if not ok or not fine:
            return None
        kind, where = MissionType(m.kind), self.name_span(pf, m)
        return Mission(m.name, kind, tuple(allocation), where, timeout, written)

    def _timeout(self, pf: ParsedFile, node: Any, whose: str) -> tuple[float | None, str | None, bool]:
        """A ``timeout`` in seconds and as written (None, None: none given); False: it was wrong,
        and reported at its number."""
        if node is None:
            return None, None, True
        text = node.duration
        where = pf.lines.span(node._tx_position_end - len(text), node._tx_position_end)
        seconds = read_duration(text)
        if seconds is None:
            self.error(f"the timeout of {whose} has no unit; write '{text} s' or '{text} min'", where)
            return None, None, False
        if not seconds > 0:
            self.error(f"the timeout of {whose} must be above 0 s, not {quantity_text(text)}", where)
            return None, None, False
        return seconds, text, True


def _ros(source: Any) -> RosResource | None:
    if source is None:
        return None
    return RosResource(source.package, source.path or None)
