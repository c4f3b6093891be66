"""``exscec report``: a static HTML report of the store."""

from __future__ import annotations

import click

from exsce_dsl.cli.common import REMEDIES, Progress, reports_errors
from exsce_dsl.cli.store_commands import store_option


@click.command()
@click.option(
    "--output",
    "-o",
    default="report",
    show_default=True,
    type=click.Path(file_okay=False),
    help="The folder to write the report into (its pages are replaced when the new report is complete).",
)
@click.option(
    "--spec",
    "specs",
    multiple=True,
    type=click.Path(dir_okay=False, exists=True),
    help="A scenario file whose map to draw paths on (repeatable; derived scenarios use their base's).",
)
@store_option
@reports_errors
def report(output: str, specs: tuple[str, ...], store_url: str | None) -> None:
    """Write an HTML report of the store that opens in any browser, offline.

    The overview has every scenario's lineage tree, the runs per scenario, the
    verdicts of all runs (failures first) and the similarity dendrogram; each
    scenario has a page with its runs, its metric values against the bands
    its oracles accept, and its oracles; each run a page with the paths its
    robots drove (read from its bag) over the occupancy grid, the planned
    waypoints and the hotspots where a safety limit was broken.

    \b
    Example:
      exscec report -o report --spec examples/brsu_building_c/scenario_c.exsce
    """
    from exsce_dsl.api import counted, gather_report, write_report

    contents = gather_report(store_url, specs)
    runs = sum(len(s.runs) for s in contents.scenarios)
    with Progress(runs, "drawing runs") as progress:
        index = write_report(contents, output, progress.update)
    for note in contents.notes:
        click.echo(f"note: {note if isinstance(note, str) else note.said(REMEDIES)}", err=True)
    shown = f"{counted(len(contents.scenarios), 'scenario')}, {counted(runs, 'run')}"
    click.echo(f"wrote {index} ({shown})", err=True)


COMMANDS = [report]
