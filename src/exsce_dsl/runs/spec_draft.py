"""A starting specification drafted from a bag (``exscec init --from-bag``), which checks and
ingests as written.

From what :func:`~exsce_dsl.runs.bag_robots.bag_contents` reads of the bag:

- a robot type per convention found (``convention nav2``...; a robot without navigation goals
  gets a type that names none, detected again at each ingest, with ``window whole recording``:
  its metrics are of its whole path);
- one robot per namespace (``namespace ""`` at the root), starting where its path starts;
- an environment with an area of each robot's places (its goals' targets in recorded order, or
  the start, farthest point and end of its path), and the bag's occupancy grid as a map_server
  YAML and PGM beside the specification;
- a task per dispatcher goal or navigation goal (one for a path), and a mission of them in the
  recorded order (parallel when there are several robots);
- acceptance criteria with the method's safety limits (DESIGN §1);
- comments saying what was detected from which topics.

Names come from the bag (namespaces, waypoint ids): each becomes a valid id of the language
(:func:`dsl_name`) before it reaches the specification; file names come from the user's paths.
The text is the formatter's (IR → ``.exsce``), comments placed through source locations.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.errors import BagError, ExportError, SourceLocation
from exsce_dsl.lang import Comment, declared_poses, format_document
from exsce_dsl.maps.grid import FREE, OccupancyGrid, grid_from_ros, save_occupancy_grid
from exsce_dsl.model import (
    Acceptance,
    Area,
    Assignment,
    Declaration,
    Document,
    Environment,
    MapModel,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.acceptance import (
    BasicRelation,
    Criterion,
    Expectation,
    Quantifier,
    Quantity,
    Subject,
    When,
)
from exsce_dsl.model.conventions import CONVENTIONS, METHOD, MetricSpan
from exsce_dsl.model.names import KEYWORDS, is_valid_name
from exsce_dsl.model.runs import run_uuid
from exsce_dsl.output_folder import existing, write_below
from exsce_dsl.remedies import REPLACE_FILES
from exsce_dsl.runs.bag_identity import content_hash
from exsce_dsl.runs.bag_robots import BagContents, BagRobot, Place, bag_contents
from exsce_dsl.wording import counted

SAFETY_LIMITS: tuple[tuple[str, BasicRelation, float, str], ...] = (
    ("max_velocity", BasicRelation.BELOW_MAX, 1.0, "m/s"),
    ("distance_to_obstacles", BasicRelation.ABOVE_MIN, 0.1, "m"),
    ("distance_between_robots", BasicRelation.ABOVE_MIN, 0.1, "m"),
)
"""The method's safety limits (DESIGN §1): metric, relation, limit and its unit."""
DIGITS = 4
"""Decimals a drafted position or heading keeps (0.1 mm, 0.0001 rad)."""


@dataclass(frozen=True)
class SpecDraft:
    """What was written: the specification, its map files, and its scenario's robots."""

    spec: Path
    text: str
    map_files: tuple[Path, ...] = ()
    robots: tuple[tuple[str, str, str], ...] = ()
    """(robot id, namespace, convention or ``detected``) per robot."""
    notes: tuple[str, ...] = ()


def default_spec_path(bag: Path, folder: Path) -> Path:
    """``<bag stem>.exsce`` in ``folder`` (the bag's name made a plain file name)."""
    return folder / f"{_file_stem(bag)}.exsce"


def draft_spec(bag: Path, out: Path, force: bool = False) -> SpecDraft:
    """Read ``bag`` and write a starting specification at ``out`` (and the bag's map beside it);
    nothing is written if a file to write exists and not ``force``."""
    if out.suffix != ".exsce":
        raise ExportError(f"{out}: a specification's file name ends in .exsce")
    contents = bag_contents(bag)
    if not contents.robots:  # every robot's namespace is a name the language cannot hold
        raise BagError(f"{bag}: no robot to draft a specification for: {'; '.join(contents.skipped)}")
    if all(r.start is None for r in contents.robots):
        raise BagError(_nowhere(bag, contents))
    map_yaml = out.with_name(f"{out.stem}_map.yaml") if contents.map is not None else None
    targets = [out] + ([map_yaml, map_yaml.with_suffix(".pgm")] if map_yaml else [])
    found = [str(t) for t in targets if existing(t.parent, t.name)]  # a link there is refused
    if found and not force:
        raise ExportError(f"would overwrite {', '.join(found)}", remedy=REPLACE_FILES)
    m = contents.map
    grid = grid_from_ros(m.values, m.width, m.height, m.resolution, m.origin) if m is not None else None
    tag = run_uuid(content_hash(bag))[:8]  # the start of the id its run will have
    drafter = _Drafter(contents, out.name, _name(f"{out.stem}_{tag}", set(), "scenario"), grid=grid)
    document, poses = drafter.document(map_yaml.name if map_yaml else None)
    text = format_document(document, poses, drafter.comments)
    written = _write_map(grid, map_yaml) if grid is not None and map_yaml is not None else ()
    write_below(out.parent, out.name, text.encode("utf-8"))
    robots = tuple((rid, r.namespace, r.convention or "detected") for rid, r in drafter.ids.items())
    return SpecDraft(out, text, written, robots, tuple(drafter.notes))


def _nowhere(bag: Path, contents: BagContents) -> str:
    """Why no robot of ``bag`` can be drafted: none has a pose exsce reads, nor goals (a
    specification without robots would not check: its mission would allocate no task)."""
    robots = ", ".join(f"{r.namespace or '/'}" for r in contents.robots)
    listed = "; ".join(contents.pose_like) or "none"
    return (
        f"{bag}: no robot to draft a specification for: the namespaces that look like robots "
        f"({robots}) have no navigation goals and no pose exsce reads (TF map or odom -> base_link "
        f"or base_footprint on /{{ns}}/tf, an Odometry, a PoseStamped or a PoseWithCovarianceStamped); "
        f"the bag's pose-like topics: {listed}. Write the robots' types by hand, saying where each "
        'pose is (pose from tf FIXED -> BODY, or pose on "TOPIC"): docs/bags.md'
    )


def _write_map(grid: OccupancyGrid, map_yaml: Path) -> tuple[Path, ...]:
    """The map's YAML and PGM, made in a private folder and written beside the specification
    as :func:`~exsce_dsl.output_folder.write_below` writes (never through a link)."""
    with tempfile.TemporaryDirectory() as private:
        made = save_occupancy_grid(grid, Path(private) / map_yaml.name)
        return tuple(write_below(map_yaml.parent, path.name, path.read_bytes()) for path in made)


def dsl_name(text: str, taken: set[str], fallback: str) -> str:
    """``text`` made a valid id of the language (other characters become ``_``), not one of
    ``taken`` (a number is appended), and added to ``taken``."""
    return _name(text, taken, fallback)


def _name(text: str, taken: set[str], fallback: str) -> str:
    name = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9_-]", "_", text)).strip("_-")
    name = re.sub(r"-(?=-|_)|(?<=_)-", "", name).strip("-")
    if not name:
        name = fallback
    if not (name[0].isalpha() or name[0] == "_"):
        name = f"{fallback}_{name}"
    if name in KEYWORDS:
        name = f"{name}_"
    unique, number = name, 2
    while unique in taken:
        unique, number = f"{name}_{number}", number + 1
    assert is_valid_name(unique), unique
    taken.add(unique)
    return unique


def _file_stem(path: Path) -> str:
    stem = path.name if path.is_dir() else path.stem
    return re.sub(r"[^A-Za-z0-9_.-]", "_", stem).lstrip(".-") or "bag"


@dataclass
class _Drafter:
    contents: BagContents
    file: str
    scenario: str
    """The scenario's id: the specification's file name and the first 8 digits of the bag's run
    id.  Its environment, areas and tasks start with it: a store shares an area or task of one
    id among its scenarios, so drafts of many bags (each ``recording.mcap``, each robot's
    ``root_robot_places``) would collide."""
    comments: list[Comment] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    ids: dict[str, BagRobot] = field(default_factory=dict)
    grid: OccupancyGrid | None = None
    taken: set[str] = field(default_factory=set)
    """Every id given so far: ids are unique across kinds."""
    _line: int = 0

    def at(self, *said: str) -> SourceLocation:
        """A location for the next element, with ``said`` as comments before it."""
        for text in said:
            self._line += 1
            self.comments.append(Comment(self.file, self._line, 1, _comment(text)))
        self._line += 1
        return SourceLocation(self.file, self._line, 1)

    def after(self, said: str) -> SourceLocation:
        """A location for the next element, with ``said`` as a comment at the end of its line."""
        location = self.at()
        self.comments.append(Comment(self.file, location.line, 80, _comment(said)))
        return location

    def document(self, map_file: str | None) -> tuple[Document, dict[str, Pose]]:
        c = self.contents
        self.taken.add(self.scenario)
        self.notes += c.skipped
        for robot in c.robots:
            self.ids[_name(robot.namespace or "root_robot", self.taken, "robot")] = robot
        header = [
            f"Drafted by `exscec init --from-bag` from {c.path.name}: {counted(c.topics, 'topic')}, "
            f"{c.end - c.start:.1f} s, {counted(len(c.robots), 'robot')} found.",
            f"Next: exscec check {self.file}; exscec ingest {c.path.name} --scenario {self.file}",
            f"Names start with {self.scenario}: the file's name and the start of the bag's run id, "
            "so drafts of bags that share a file name share a store.",
            *(f"Left out: {why}" for why in c.skipped),  # a name the language could not hold
            "",
        ]
        types = self._robot_types(header)
        env, starts, tasks = self._environment(map_file)
        mission_id = _name(f"{self.scenario}_mission", self.taken, "mission")
        allocation = tuple(Assignment(rid, t.id) for rid, robot_tasks in tasks.items() for t in robot_tasks)
        kind = MissionType.PARALLEL if len(starts) > 1 else MissionType.SEQUENTIAL
        location = self.at()  # the scenario's line comes before its robots and mission
        robots = tuple(
            Robot(rid, types[rid], robot.namespace, starts[rid])
            for rid, robot in self.ids.items()
            if rid in starts
        )
        said = "Tasks in the order the robots went to them" + (", side by side." if len(starts) > 1 else ".")
        mission = Mission(mission_id, kind, allocation, self.at(said))
        all_tasks = tuple(t for robot_tasks in tasks.values() for t in robot_tasks)
        scenario = Scenario(self.scenario, env, robots, mission, all_tasks, location)
        used = {types[r.id].id: types[r.id] for r in robots}
        declarations: tuple[Declaration, ...] = (
            *used.values(),
            env,
            *all_tasks,
            scenario,
            self._acceptance(mission_id, robots),
        )
        return Document(self.file, (), declarations), declared_poses([env])

    def _robot_types(self, header: list[str]) -> dict[str, RobotType]:
        """A robot type per convention, its comment saying which robots have it and from what."""
        grouped: dict[str, list[str]] = {}
        for rid, robot in self.ids.items():
            grouped.setdefault(robot.convention or "detected", []).append(rid)
        types: dict[str, RobotType] = {}
        for key, rids in grouped.items():
            said = list(header)
            header = []
            for rid in rids:
                robot = self.ids[rid]
                evidence = ", ".join(robot.detected.evidence) or "nothing of its namespace"
                where = robot.namespace or "/"
                said.append(f"{rid} (namespace {where}): {robot.detected.convention}, from {evidence}")
                if robot.pose_from:
                    said.append(f"  its pose from {', '.join(robot.pose_from)}")
            if key in CONVENTIONS:
                signals = CONVENTIONS[key]
            else:
                whole = MetricSpan.RECORDING
                signals = METHOD.overridden(window=whole, named=False, said=frozenset({"window"}))
                said.append(
                    "No goals: the convention is detected at each ingest; metrics of the whole recording."
                )
            rtype = RobotType(
                _name(f"{key}_robot", self.taken, "robot"), location=self.at(*said), declared_signals=signals
            )
            types.update(dict.fromkeys(rids, rtype))
        return types

    def _environment(
        self, map_file: str | None
    ) -> tuple[Environment, dict[str, Pose], dict[str, list[Task]]]:
        c = self.contents
        areas: list[Area] = []
        starts: dict[str, Pose] = {}
        tasks: dict[str, list[Task]] = {}
        declared: dict[str, Pose] = {}
        said = ["Each robot's places, in the order it went to them."]
        if c.map is not None and map_file is not None:
            m = c.map
            said.insert(
                0,
                f"The map: the last of {counted(m.messages, 'OccupancyGrid message')} on {m.topic}, "
                f"{m.width} x {m.height} cells of {m.resolution:g} m.",
            )
            outside = self._off_the_map()
            if outside:
                said[1:1] = [
                    f"{map_file} is not referenced: {counted(outside, 'place')} outside its free space",
                    "(a path from odometry is in another frame than the map). Move them and add: "
                    "map NAME file ...",
                ]
                self.notes.append(
                    f"{map_file} written but not referenced: {counted(outside, 'place')} off its free space"
                )
                map_file = None
        elif c.other_maps:
            said.insert(0, f"Occupancy grids not used as the map: {', '.join(c.other_maps)}.")
        env_id = _name(f"{self.scenario}_environment", self.taken, "environment")
        env_location = self.at(*said)
        map_model = None
        if map_file is not None:
            map_model = MapModel(
                _name(f"{self.scenario}_map", self.taken, "map"), file=map_file, location=self.at()
            )
        for rid, robot in self.ids.items():
            if robot.start is None:
                self.notes.append(
                    f"robot {rid} (namespace {robot.namespace or '/'}): no pose and no goals: left out"
                )
                continue
            where = ", ".join(robot.goals_from) or ", ".join(robot.pose_from) or "its path"
            area = _name(f"{self.scenario}_{rid}_places", self.taken, "area")
            counted_goals = counted(len(robot.tasks), "goal") if robot.goals_from else "its path"
            area_location = self.at(f"{rid}: {counted_goals}, from {where}", *robot.notes[:5])
            start = self._pose(f"{rid}-start", robot.start, area)
            poses: list[Pose] = [start]
            starts[rid] = start
            mine: list[Task] = []
            for number, places in enumerate(robot.tasks, start=1):
                visits: list[Pose] = []
                for place in places:
                    if place.name is not None and place.name in declared:
                        visits.append(declared[place.name])
                        continue
                    pose = self._pose(
                        _place_name(rid, number, place, places, bool(robot.goals_from)), place, area
                    )
                    declared[place.name or pose.id] = pose
                    poses.append(pose)
                    visits.append(pose)
                wanted = f"{self.scenario}_{rid}_" + (f"goal_{number}" if robot.goals_from else "path")
                mine.append(Task(_name(wanted, self.taken, "task"), (Subtask(tuple(visits)),)))
            tasks[rid] = mine
            areas.append(Area(area, tuple(poses), area_location))
        return Environment(env_id, map_model, None, tuple(areas), (), env_location), starts, tasks

    def _off_the_map(self) -> int:
        """How many of the robots' places the bag's map does not have in free space."""
        if self.grid is None:
            return 0
        places = [
            p
            for r in self.ids.values()
            for p in ([r.start] if r.start else []) + [q for t in r.tasks for q in t]
        ]
        return sum(self.grid.state_at(p.x, p.y) != FREE for p in places)

    def _pose(self, wanted: str, place: Place, area: str) -> Pose:
        name = _name(wanted, self.taken, "pose")
        orientation = Orientation(yaw=round(place.yaw, DIGITS)) if place.yaw is not None else Orientation()
        position = Position(round(place.x, DIGITS), round(place.y, DIGITS))
        note = place.note if name == wanted else f"{place.note}; named {wanted} in the bag"
        return Pose(name, position, orientation, area, self.after(note))

    def _acceptance(self, mission: str, robots: tuple[Robot, ...]) -> Acceptance:
        scans = all(self.ids[r.id].scan for r in robots)
        expectations = []
        for metric, relation, limit, unit in SAFETY_LIMITS:
            if metric == "distance_to_obstacles" and not scans:
                continue
            if metric == "distance_between_robots" and len(robots) < 2:
                continue
            mission_wide = metric == "distance_between_robots"
            subject = Subject(Quantifier.MISSION) if mission_wide else Subject(Quantifier.EACH_ROBOT)
            expectations.append(
                Expectation(subject, metric, relation, limit=Quantity(limit, unit, str(limit)))
            )
        said = ["The method's safety limits."]
        if not scans:
            said.append("No laser scan for every robot: distance_to_obstacles is left out.")
        criterion = Criterion("moves safely", (), When(mission=mission), tuple(expectations))
        return Acceptance(self.scenario, (criterion,), self.at(*said))


def _place_name(robot: str, number: int, place: Place, places: list[Place], goals: bool) -> str:
    """A place's pose id: the bag's name for it, else by what the place is."""
    if place.name is not None:
        return place.name
    if goals:
        return f"{robot}-goal-{number}"
    return f"{robot}-end" if place is places[-1] else f"{robot}-farthest"


def _comment(text: str) -> str:
    """A line comment of ``text`` (a bag's names may hold anything: only printable text is kept)."""
    kept = "".join(ch if ch.isprintable() else "?" for ch in text)
    return f"// {kept}".rstrip()
