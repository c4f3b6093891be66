"""A scenario's mission as an OSC2 scenario for scenario_execution (``exscec export --to osc2``).

ROS 2 teams run scenarios with scenario_execution (OpenSCENARIO DSL 2 and py_trees); this writes
the mission in its terms, with the actions of its ``osc.ros`` and ``osc.nav2`` libraries:

- each robot an actor of type ``differential_drive_robot``, named by its namespace (by its id
  when its topics are at the root or its namespace is no OSC2 name), whose ``namespace`` field is
  the robot's;
- ``bag_record`` of the topics a run's metrics read (:func:`~exsce_dsl.execute.recording.
  recorded_topics`, for robots whose type names no convention: Nav2's), first, so that the
  mission starts only once every one of them is recorded; exsce's PROV topic is left out, as no
  exsce dispatcher runs;
- ``init_nav2`` of every robot at its start pose, side by side (a robot without one has no task
  and, as in exsce's runs, takes no part);
- per allocation entry, ``follow_waypoints`` (several waypoints) or ``nav_to_pose`` (one), in the
  mission's order: a ``parallel`` mission runs one ``serial`` block per robot side by side, a
  ``sequential`` one a single ``serial`` block; each with a timeout, the sum of its goals'
  (:func:`~exsce_dsl.execute.mission.schedule`: the task's, the mission's, or one from distance
  and speed) in whole seconds, rounded up, and the scenario's, the longest lane's plus
  :data:`STARTUP`;
- a comment block naming the acceptance clauses that judge the bag, and the exsce commands.

A spec is data: ids and namespaces become OSC2 names only when they are OSC2 identifiers (a
scenario id or a robot id needed as a name that is not one is a located
:class:`~exsce_dsl.errors.ExportError`); every other text is an escaped string literal or
a one-line comment (:mod:`exsce_dsl.templating`).
"""

from __future__ import annotations

import math
import re
import shlex
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from exsce_dsl.codegen.output import write_files
from exsce_dsl.errors import ExportError, SourceLocation
from exsce_dsl.execute import Goal, recorded_topics, schedule
from exsce_dsl.lang import display_path, expectation_text
from exsce_dsl.model import MissionType, Pose, Scenario, Specification
from exsce_dsl.runs import PROV_TOPIC
from exsce_dsl.templating import render

SUFFIX = ".osc"

STARTUP = 120.0
"""Seconds the scenario's timeout allows, beyond its goals', for the recorder to subscribe to
every topic and for Nav2 to come up at the start poses."""

CONVENTION = "nav2"
"""The convention of the stacks of robots whose type names none: scenario_execution drives Nav2."""

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

OSC2_KEYWORDS = frozenset(
    "import type is SI unit of factor offset kg m s A K mol cd rad enum struct inherits actor "
    "scenario action modifier extend global list int uint float bool string event if as rise fall "
    "elapsed every var sample with keep default hard remove_default on do serial one_of parallel "
    "wait emit call until def expression undefined external only cover record range or and not in "
    "it true false".split()
)
"""The words of OSC2's lexer (scenario_execution 1.8's ``OpenSCENARIO2Lexer.literalNames``, and
its Boolean literals), which cannot name an actor or a scenario: units among them (``m``, ``s``)."""

USED_NAMES = frozenset(
    "differential_drive_robot robot osc_actor pose_3d position_3d orientation_3d timeout "
    "bag_record init_nav2 nav_to_pose follow_waypoints".split()
)
"""The library names the exported text uses, which a robot's actor may not hide."""


@dataclass(frozen=True, slots=True)
class Actor:
    """A robot as an OSC2 actor."""

    name: str
    namespace: str
    """The robot's, as the spec writes it (``""``: the root)."""
    robot: str
    start: Pose | None


@dataclass(frozen=True, slots=True)
class Step:
    """One allocation entry: a robot visits its task's waypoints with one navigation action."""

    actor: str
    """The name of the actor of the robot."""
    task: str
    poses: tuple[Pose, ...]
    """The task's waypoints, its subtasks one after the other."""
    timeout: float
    """Seconds: the sum of its goals' timeouts, rounded up."""

    @property
    def action(self) -> str:
        return "follow_waypoints" if len(self.poses) > 1 else "nav_to_pose"


@dataclass(frozen=True, slots=True)
class Osc2Scenario:
    """What the OSC2 file says, before it is written."""

    name: str
    """The scenario's id, which names the OSC2 scenario."""
    mission: str
    parallel: bool
    """A ``parallel`` mission (one lane per robot), else ``sequential`` (one lane)."""
    actors: tuple[Actor, ...]
    lanes: tuple[tuple[Step, ...], ...]
    """What runs side by side; each lane's steps one after the other."""
    topics: tuple[str, ...]
    """What ``bag_record`` records: absolute names, sorted."""
    timeout: float
    """Seconds the whole scenario may take."""
    oracles: tuple[str, ...]
    """The acceptance clauses that judge its bag, worded as the DSL words them."""
    source: str
    """The spec file, as its name is shown."""

    @property
    def source_argument(self) -> str:
        """The spec file as a shell word, for the commands the comments show."""
        return shlex.quote(self.source)


def osc2_name(name: str, what: str, location: SourceLocation | None, remedy: str = "") -> str:
    """``name`` if it can be ``what``'s name in OSC2: an identifier that is no keyword nor a library
    name the export uses; a located :class:`ExportError` otherwise (never rewritten)."""
    if not _is_osc2_name(name):
        raise ExportError(
            f"{what} {name!r} is no OSC2 name: an OSC2 name is an identifier (a letter or '_', "
            "then letters, digits or '_') that is not an OSC2 keyword (units such as 'm' and 's' "
            f"are) nor one of {', '.join(sorted(USED_NAMES))}{remedy}",
            location,
        )
    return name


def osc2_number(value: float) -> str:
    """A finite number as an OSC2 float literal: decimal digits with a point, no exponent."""
    number = Decimal(repr(float(value)))
    if not number.is_finite():
        raise ExportError(f"{value!r} is not a finite number")
    text = format(number, "f")
    return text if "." in text else f"{text}.0"


def osc2_scenario(spec: Specification, scenario: Scenario) -> Osc2Scenario:
    """The OSC2 scenario of ``scenario`` (declared in ``spec``), checked, not yet written."""
    name = osc2_name(scenario.id, "scenario id", scenario.location)
    actors = tuple(_actor(r.id, r.namespace, r.start_pose, r.location) for r in scenario.robots)
    seen: dict[str, str] = {}
    for actor, robot in zip(actors, scenario.robots, strict=True):
        if actor.name in seen:
            raise ExportError(
                f"robots '{seen[actor.name]}' and '{robot.id}' would both be the OSC2 actor "
                f"'{actor.name}': give them namespaces of their own",
                robot.location,
            )
        seen[actor.name] = robot.id
    actor_of = {a.robot: a.name for a in actors}
    plan = schedule(scenario)
    lanes = tuple(_steps(lane, actor_of) for lane in plan.lanes)
    if not any(lanes):
        raise ExportError(
            f"mission '{scenario.mission.id}' allocates no task: there is nothing to run",
            scenario.mission.location,
        )
    topics = tuple(t for t in recorded_topics(scenario, CONVENTION) if t != PROV_TOPIC)
    longest = max(sum(step.timeout for step in lane) for lane in lanes)
    return Osc2Scenario(
        name=name,
        mission=scenario.mission.id,
        parallel=scenario.mission.type is MissionType.PARALLEL,
        actors=actors,
        lanes=lanes,
        topics=topics,
        timeout=longest + STARTUP,
        oracles=_oracles(spec, scenario),
        source=display_path(spec.root),
    )


def osc2_text(plan: Osc2Scenario) -> str:
    """The ``.osc`` file of ``plan``."""
    return render("osc2/scenario.osc.j2", plan=plan, number=osc2_number, startup=STARTUP)


def export_osc2(spec: Specification, out: Path, scenario_id: str | None = None) -> list[Path]:
    """Write the OSC2 scenario of ``scenario_id`` (the spec's only one when None) to ``out``: a
    ``.osc`` file, or a folder that gets ``<scenario>.osc``; return the file written."""
    plan = osc2_scenario(spec, spec.scenario(scenario_id))
    if out.suffix == SUFFIX:
        folder, name = out.parent, out.name
    else:
        folder, name = out, f"{plan.name}{SUFFIX}"
    return write_files(folder, {name: osc2_text(plan)}, overwrite=True)


def _actor(robot: str, namespace: str, start: Pose | None, location: SourceLocation | None) -> Actor:
    """The robot's actor: named by its namespace, or by its id when the namespace is the root or
    no OSC2 name (``/fleet/tiago1``); its ``namespace`` field says the namespace in either case."""
    bare = namespace.strip("/")
    if bare and _is_osc2_name(bare):
        return Actor(bare, namespace, robot, start)
    remedy = "; a robot's actor is named by its namespace, else by its id: give it a namespace that is one"
    return Actor(osc2_name(robot, "robot id", location, remedy), namespace, robot, start)


def _is_osc2_name(name: str) -> bool:
    return bool(_IDENTIFIER.fullmatch(name)) and name not in OSC2_KEYWORDS and name not in USED_NAMES


def _steps(lane: tuple[Goal, ...], actor_of: dict[str, str]) -> tuple[Step, ...]:
    """The lane's goals, one step per allocation entry (a robot may do the same task twice)."""
    entries: dict[tuple[str, int], list[Goal]] = {}
    for goal in lane:
        entries.setdefault(goal.task_key, []).append(goal)
    return tuple(
        Step(
            actor_of[goals[0].robot],
            goals[0].task,
            tuple(g.pose for g in goals),
            float(math.ceil(sum(g.timeout for g in goals))),
        )
        for goals in entries.values()
    )


def _oracles(spec: Specification, scenario: Scenario) -> tuple[str, ...]:
    """Each acceptance clause of the scenario, as the DSL words it, after its criterion's title."""
    acceptance = spec.acceptance_of(scenario.id)
    if acceptance is None:
        return ()
    clauses = []
    for criterion in acceptance.criteria:
        when = criterion.when
        part = f" when {when.text()}" if when is not None and not when.mission else ""
        clauses += [f'"{criterion.title}"{part}: {expectation_text(e)}' for e in criterion.expectations]
    return tuple(clauses)
