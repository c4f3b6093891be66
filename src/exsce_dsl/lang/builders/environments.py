"""Build ``environment`` declarations: the map and world, areas with their poses, obstacles."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.context import BuildContext, Declared, name_span, report_duplicate, ros_resource
from exsce_dsl.lang.builders.poses import orientation_of, position_of
from exsce_dsl.lang.lexical import read_length
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Area, Environment, MapModel, Obstacle, Pose, WorldModel


def build_environment(ctx: BuildContext, d: Declared) -> Environment:
    """The environment ``d`` declares; its poses join ``ctx.poses``."""
    pf, env = d.file, d.obj
    map_model: MapModel | None = None
    world: WorldModel | None = None
    areas: list[Area] = []
    obstacles: list[Obstacle] = []
    pose_seen: dict[str, SourceLocation] = {}
    area_seen: dict[str, SourceLocation] = {}
    obstacle_seen: dict[str, SourceLocation] = {}
    inside = f" in environment '{env.name}'"
    for member in env.members:
        kind = member.__class__.__name__
        if kind == "MapModel":
            if map_model is not None:
                ctx.error(f"environment '{env.name}' has two maps", pf.span(member))
                continue
            file = None
            if member.file:
                file = str(Path(pf.path).parent / member.file)
            map_model = MapModel(member.name, ros_resource(member.source), file, pf.span(member))
        elif kind == "WorldModel":
            if world is not None:
                ctx.error(f"environment '{env.name}' has two worlds", pf.span(member))
                continue
            world = WorldModel(member.name, ros_resource(member.source), pf.span(member))
        elif kind == "Area":
            where = name_span(pf, member)
            if report_duplicate("area", member.name, area_seen.get(member.name), where, ctx.error, inside):
                continue
            area_seen[member.name] = where
            poses = _area_poses(ctx, pf, member, pose_seen, inside)
            for pose in poses:
                ctx.poses.setdefault(pose.id, []).append((env.name, pose))
            areas.append(Area(member.name, tuple(poses), where))
        else:  # Obstacle
            where = name_span(pf, member)
            if report_duplicate(
                "obstacle", member.name, obstacle_seen.get(member.name), where, ctx.error, inside
            ):
                continue
            obstacle_seen[member.name] = where
            obstacles.append(_obstacle(member, where))
    return Environment(env.name, map_model, world, tuple(areas), tuple(obstacles), d.name_location)


def _area_poses(
    ctx: BuildContext, pf: ParsedFile, area: Any, seen: dict[str, SourceLocation], inside: str
) -> list[Pose]:
    """The poses of an area (one of the environment's ``seen`` ones is a duplicate)."""
    poses = []
    for decl in area.poses:
        where = name_span(pf, decl)
        if report_duplicate("pose", decl.name, seen.get(decl.name), where, ctx.error, inside):
            continue
        seen[decl.name] = where
        poses.append(
            Pose(decl.name, position_of(decl.position), orientation_of(decl.orientation), area.name, where)
        )
    return poses


def _obstacle(member: Any, where: SourceLocation) -> Obstacle:
    size = None
    size_written: tuple[str, ...] = ()
    if member.sx is not None:
        dims = [member.sx, member.sy] + ([member.sz] if member.sz is not None else [])
        size = tuple(read_length(v) for v in dims)
        size_written = tuple(dims)
    pose = Pose(member.name, position_of(member.position), orientation_of(member.orientation), None, where)
    return Obstacle(member.name, pose, member.model or None, size, where, size_written)
