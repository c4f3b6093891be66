"""``exscec bag info`` and ``exscec init --from-bag``: what a bag holds, and a starting specification
from it, before any specification is written."""

from __future__ import annotations

import datetime as dt
import json
from collections.abc import Mapping
from pathlib import Path

import click

from exsce_dsl.cli.common import bag_arguments, exit_status, reports_errors


@click.group()
def bag() -> None:
    """Look into bags: what they hold, before a specification is written.

    \b
    Example:
      exscec bag info bags/*
    """


@bag.command("info", epilog=exit_status(bad_input="a bag that cannot be read (named), or bad input"))
@click.argument("bags", nargs=-1, required=True, type=click.Path())
@click.option(
    "--format",
    "-f",
    "fmt",
    type=click.Choice(["table", "json"]),
    default="table",
    show_default=True,
    help="Aligned text, or JSON (one object per bag, in a list).",
)
@reports_errors
def info(bags: tuple[str, ...], fmt: str) -> None:
    """What each bag holds: format, size, time span; per topic its type, where the type's definition
    comes from (the bag, $EXSCE_MSG_PATH or rosbags' typestore), messages, rate and the clock of
    its stamps (wall clock or a simulation's, from a sample of its first messages); the TF tree
    with each edge's rate; the navigation goals and how they ended; and per namespace the
    convention ingestion would detect.

    \b
    Example:
      exscec simulate examples/brsu_building_c/scenario_c.exsce -o bags/ --convention nav2 --format mcap
      exscec bag info bags/*
    """
    from exsce_dsl.api import describe_bags

    found = describe_bags(bag_arguments(bags))
    if not found:
        raise click.UsageError("no bag among the files given")
    if fmt == "json":
        click.echo(json.dumps([f.as_dict() for f in found], indent=2))
        return
    for number, described in enumerate(found):
        if number:
            click.echo("")
        click.echo(_table(described))


def _table(info: object) -> str:
    from exsce_dsl.api import BagInfo

    assert isinstance(info, BagInfo)
    if info.dated:
        start = dt.datetime.fromtimestamp(info.start, tz=dt.timezone.utc).isoformat(timespec="seconds")
    else:  # log time that is no date (simulated time): never a date of 1970
        start = f"{info.start:.3f} s (no date)"
    lines = [
        f"bag       {info.path}",
        f"format    {info.format}, {info.size / 1e6:.1f} MB",
        f"span      {info.end - info.start:.1f} s of log time from {start}",
        f"timeline  {info.timeline}",
        "",
    ]
    rows = [("topic", "type", "definition", "messages", "rate (Hz)", "stamps", "log - stamp (s)")]
    for t in info.topics:
        rate = _hertz(t.rate) if t.rate is not None else "-"
        offset = f"{t.offset:+.3f}" if t.offset is not None else "-"
        rows.append((t.name, t.msgtype, t.definition, str(t.messages), rate, t.clock, offset))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    if info.tf_edges:
        edges = ", ".join(f"{p} -> {c} ({_edge_rate(info.tf_rates, p, c, s)})" for p, c, s in info.tf_edges)
        lines += ["", f"tf        {edges}"]
    for topic, ends in info.goals.items():
        counted = ", ".join(f"{n} {status}" for status, n in sorted(ends.items()))
        lines.append(f"goals     {topic}: {sum(ends.values())} ({counted})")
    for said in info.conventions:
        lines.append(f"robots    {said}")
    for said in info.plausibility:
        lines.append(f"poses     {said}: no distance or speed is made of it")
    return "\n".join(lines)


@click.command(
    "init", epilog=exit_status(bad_input="a bag that cannot be read, no robot in it, or a file in the way")
)
@click.option(
    "--from-bag",
    "bag_path",
    required=True,
    type=click.Path(),
    metavar="BAG",
    help="The bag (a ROS 1 .bag, a ROS 2 folder or an .mcap file) to draft the specification from.",
)
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False),
    help="The specification to write.  [default: <bag stem>.exsce in the current folder]",
)
@click.option("--force", is_flag=True, help="Replace the specification and its map files if they exist.")
@reports_errors
def init(bag_path: str, output: str | None, force: bool) -> None:
    """Write a starting specification from a bag, which checks and ingests as written: a robot
    type per convention detected, a robot per namespace (namespace "" at the root), an environment
    whose poses are the navigation goals' targets in recorded order (without goals: the start,
    farthest point and end of each robot's path), a task per goal and a mission of them in that
    order, the bag's OccupancyGrid as a map_server YAML and PGM beside it, and the method's safety
    limits as acceptance criteria.  Its comments say what was detected from which topics.

    \b
    Example:
      exscec simulate examples/brsu_building_c/scenario_c.exsce -o nav2_runs/ --convention nav2
      exscec init --from-bag nav2_runs/*.bag -o from_bag.exsce
      exscec check from_bag.exsce
    """
    from exsce_dsl.api import init_from_bag

    draft = init_from_bag(Path(bag_path), output, force)
    robots = ", ".join(f"{rid} ({ns or '/'}, {convention})" for rid, ns, convention in draft.robots)
    click.echo(f"wrote {draft.spec}: robots {robots}")
    for written in draft.map_files:
        click.echo(f"wrote {written}")
    for note in draft.notes:
        click.echo(f"note: {note}", err=True)
    click.echo(f"next: exscec check {draft.spec} && exscec ingest {bag_path} --scenario {draft.spec}")


def _edge_rate(rates: Mapping[tuple[str, str], float], parent: str, child: str, static: bool) -> str:
    rate = rates.get((parent, child))
    return "static" if static else f"{_hertz(rate)} Hz" if rate is not None else "once"


COMMANDS = [bag, init]


def _hertz(rate: float) -> str:
    """A rate to one decimal, or to two significant digits below 1 Hz (a plan sent four times in
    ten minutes is 0.0069 Hz, not 0.0)."""
    return f"{rate:.1f}" if rate >= 1 else f"{rate:.2g}"
