"""Build ``robot_type`` declarations and the robots of a scenario."""

from __future__ import annotations

from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.context import BuildContext, Declared, name_span, report_duplicate
from exsce_dsl.lang.builders.signals import build_signals
from exsce_dsl.lang.builders.tasks import pose_use
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Environment, Pose, Robot, RobotType
from exsce_dsl.model.robots import root_namespace

_FACT_WORDS = {"BaseFact": "base", "TorsoFact": "torso", "MotionFact": "motion"}


def build_robot_type(ctx: BuildContext, d: Declared) -> RobotType:
    """The robot type ``d`` declares."""
    base: str | None = None
    torso: bool | None = None
    motion = "planar"
    seen: set[str] = set()
    for fact in d.obj.facts:
        kind = fact.__class__.__name__
        if kind not in _FACT_WORDS:
            continue  # where its signals are: build_signals
        if kind in seen:
            ctx.error(f"robot type '{d.obj.name}' states its {_FACT_WORDS[kind]} twice", d.file.span(fact))
        seen.add(kind)
        if kind == "BaseFact":
            base = fact.base
        elif kind == "TorsoFact":
            torso = fact.torso == "yes"
        else:
            motion = fact.motion
    signals = build_signals(f"robot type '{d.obj.name}'", d.obj.facts, d.file.span, ctx.error)
    return RobotType(d.obj.name, base, torso, d.name_location, signals, motion)


def build_robots(
    ctx: BuildContext, pf: ParsedFile, sc: Any, env: Environment | None
) -> tuple[list[Robot], dict[str, SourceLocation], bool]:
    """The robots of scenario ``sc`` (in ``env``, None when it is unknown), where each is declared,
    and False when one of them has an error."""
    env_poses: dict[str, Pose | None] = {p.id: p for p in env.poses()} if env else {}
    robots: list[Robot] = []
    robot_seen: dict[str, SourceLocation] = {}
    ok = True
    for decl in sc.robots:
        where = name_span(pf, decl)
        inside = f" in scenario '{sc.name}'"
        if report_duplicate("robot", decl.name, robot_seen.get(decl.name), where, ctx.error, inside):
            ok = False
            continue
        robot_seen[decl.name] = where
        rtype = ctx.robot_types.get(decl.type.name)
        if rtype is None:
            ctx.unknown_name("robot type", decl.type.name, pf.span(decl.type), ctx.robot_types)
            ok = False
        start = None
        if decl.start is not None and env is not None:
            if decl.start.pose.name not in env_poses and decl.start.pose.name in ctx.poses:
                ctx.error(
                    f"start pose '{decl.start.pose.name}' of robot '{decl.name}' is not in "
                    f"environment '{env.id}'",
                    pf.span(decl.start.pose),
                    code="reference",
                )
                ok = False
            else:
                start = pose_use(ctx, pf, decl.start, env_poses)
                ok = ok and start is not None
        namespace = root_namespace(decl.namespace) if decl.has_namespace else decl.name
        if rtype is not None:
            own = build_signals(f"robot '{decl.name}'", decl.overrides, pf.span, ctx.error, rtype.signals)
            if own == rtype.signals:
                own = None  # it says what its type says
            robots.append(Robot(decl.name, rtype, namespace, start, where, own))
    return robots, robot_seen, ok
