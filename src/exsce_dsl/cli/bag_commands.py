"""``exscec bag info``: what a bag holds, before any specification is written."""

from __future__ import annotations

import datetime as dt
import json
from pathlib import Path

import click

from exsce_dsl.cli.common import bag_arguments, reports_errors


@click.group()
def bag() -> None:
    """Look into bags: what they hold, before a specification is written.

    \b
    Example:
      exscec bag info bags/*
    """


@bag.command("info")
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
    """What each bag holds: format, size, time span; per topic its type, messages, rate and the
    clock of its stamps (wall clock or a simulation's, from a sample of its first messages); the
    TF tree; the navigation goals and how they ended; and per namespace the convention ingestion
    would detect.

    \b
    Example:
      exscec simulate examples/brsu_building_c/scenario_c.exsce -o bags/ --convention nav2 --format mcap
      exscec bag info bags/*
    """
    from exsce_dsl.runs.bag_info import bag_info

    found = [bag_info(Path(b)) for b in bag_arguments(bags)]
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
    from exsce_dsl.runs.bag_info import BagInfo

    assert isinstance(info, BagInfo)
    start = dt.datetime.fromtimestamp(info.start, tz=dt.timezone.utc).isoformat(timespec="seconds")
    lines = [
        f"bag       {info.path}",
        f"format    {info.format}, {info.size / 1e6:.1f} MB",
        f"span      {info.end - info.start:.1f} s of log time from {start}",
        f"timeline  {info.timeline}",
        "",
    ]
    rows = [("topic", "type", "messages", "rate (Hz)", "stamps", "log - stamp (s)")]
    for t in info.topics:
        rate = f"{t.rate:.1f}" if t.rate is not None else "-"
        offset = f"{t.offset:+.3f}" if t.offset is not None else "-"
        rows.append((t.name, t.msgtype, str(t.messages), rate, t.clock, offset))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    if info.tf_edges:
        edges = ", ".join(f"{p} -> {c}{' (static)' if s else ''}" for p, c, s in info.tf_edges)
        lines += ["", f"tf        {edges}"]
    for topic, ends in info.goals.items():
        counted = ", ".join(f"{n} {status}" for status, n in sorted(ends.items()))
        lines.append(f"goals     {topic}: {sum(ends.values())} ({counted})")
    for said in info.conventions:
        lines.append(f"robots    {said}")
    return "\n".join(lines)


COMMANDS = [bag]
