"""``exscec demo``: the whole method on the shipped example, from an empty folder to a report.

The demo runs, in-process, exactly the ``exscec`` commands that
``docs/tutorial.md`` has a user type by hand (:data:`STEPS`; a test checks that
the two agree), so that what the demo shows is what the tutorial teaches.
"""

from __future__ import annotations

import glob
import os
import re
import shlex
import shutil
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import click

from exsce_dsl.cli.common import reports_errors

EXAMPLE = "brsu_building_c"
SCENARIOS = "scenarios"


@dataclass(frozen=True)
class Step:
    title: str
    command: str
    """As typed in a shell, from the project folder (globs allowed)."""
    expected_exit: int = 0
    verdict: str | None = None
    """For a verify step: what the runs it judges are (shown in the summary)."""


STEPS: tuple[Step, ...] = (
    Step("Check the scenario (syntax, references, free space on the map, SHACL)",
         "exscec check scenarios/scenario_c.exsce"),
    Step("Compile it to PROV and add it to the store",
         "exscec compile scenarios/scenario_c.exsce -f provn -o scenario_c.provn --store"),
    Step("Simulate three baseline runs (bags and their run-time PROV)",
         "exscec simulate scenarios/scenario_c.exsce --runs 3 --seed 1 -o runs/baseline"),
    Step("Ingest them: metrics per run and per path segment, one transaction per bag",
         "exscec ingest runs/baseline/*.bag --scenario scenarios/scenario_c.exsce --jobs 2"),
    Step("Build the baseline oracles from the acceptance criteria and the stored runs",
         "exscec baseline scenarios/scenario_c.exsce"),
    Step("Simulate a new run, and one where tiago1 drives too fast",
         "exscec simulate scenarios/scenario_c.exsce --runs 1 --seed 7 -o runs/new"),
    Step("(the faulty run)",
         "exscec simulate scenarios/scenario_c.exsce --runs 1 --seed 8 --fault overspeed:tiago1 "
         "-o runs/faulty"),
    Step("Verify the new run against every oracle (it passes)",
         "exscec verify runs/new/*.bag --scenario scenarios/scenario_c.exsce --junit verdicts-new.xml",
         verdict="new run of scenario_c"),
    Step("Verify the faulty run (it fails its safety limits and the baseline: exit 1)",
         "exscec verify runs/faulty/*.bag --scenario scenarios/scenario_c.exsce", expected_exit=1,
         verdict="run of scenario_c with the over-speed fault"),
    Step("Derive a scenario: remove tiago2 and give its tasks to tiago1, with the oracles it must meet",
         "exscec derive scenarios/scenario_c.exsce -t remove_robot --robot tiago2 --reassign tiago1 "
         "--id c_one -o scenarios/c_one.exsce --expect --tolerance 15 --add-to-store"),
    Step("What its runs should show, and where each number comes from",
         "exscec expect scenarios/c_one.exsce"),
    Step("Simulate the derived scenario",
         "exscec simulate scenarios/c_one.exsce --runs 1 --seed 3 -o runs/c_one"),
    Step("Verify it against its metamorphic oracles (it passes)",
         "exscec verify runs/c_one/*.bag --scenario scenarios/c_one.exsce", verdict="run of derived c_one"),
    Step("Where c_one comes from", "exscec lineage c_one"),
    Step("Cluster the stored scenarios, with a dendrogram",
         "exscec cluster --k 2 --dendrogram clusters.svg"),
    Step("Write the HTML report",
         "exscec report -o report --spec scenarios/scenario_c.exsce"),
)


_ROBOT_TYPE = re.compile(r"^(robot type \S+ \{\n(?:(?!\}).*\n)*?)\}", re.MULTILINE)


def with_convention(text: str, convention: str) -> str:
    """``text`` with every robot type naming ``convention`` (as its last line, where the
    formatter puts it)."""
    return _ROBOT_TYPE.sub(lambda m: f"{m.group(1)}  convention {convention}\n}}", text)


def example_folder() -> Path:
    from exsce_dsl.resources import resource_dir

    return resource_dir("examples") / EXAMPLE


@contextmanager
def _inside(folder: Path, store_url: str | None) -> Iterator[None]:
    before, store_before = Path.cwd(), os.environ.get("EXSCE_STORE")
    os.chdir(folder)
    if store_url is not None:
        os.environ["EXSCE_STORE"] = store_url
    try:
        yield
    finally:
        os.chdir(before)
        if store_url is not None:
            if store_before is None:
                os.environ.pop("EXSCE_STORE", None)
            else:
                os.environ["EXSCE_STORE"] = store_before


def _argv(command: str) -> list[str]:
    words = shlex.split(command)
    assert words[0] == "exscec"
    expanded: list[str] = []
    for word in words[1:]:
        matches = sorted(glob.glob(word)) if any(c in word for c in "*?[") else []
        expanded += matches or [word]
    return expanded


def _run(argv: Sequence[str]) -> int:
    from exsce_dsl.cli.main import main

    try:
        main.main(list(argv), prog_name="exscec", standalone_mode=False)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 1
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    return 0


@click.command()
@click.argument("folder", default="exsce-demo", type=click.Path(file_okay=False))
@click.option(
    "--store", "store_url", help="Use this store instead of the folder's own (e.g. a SPARQL endpoint)."
)
@click.option(
    "--setup-only", is_flag=True, help="Only copy the example into FOLDER/scenarios (for the tutorial)."
)
@click.option(
    "--convention",
    type=click.Choice(["method", "nav2", "move_base"]),
    default="method",
    show_default=True,
    help="Whose topics the robots publish: the example's robot types are given this convention, so "
    "every step runs on Nav2's (or move_base's) topics and types.",
)
@reports_errors
def demo(folder: str, store_url: str | None, setup_only: bool, convention: str) -> None:
    """Run the whole method on the shipped example, in a new FOLDER.

    Copies the example (building C of the method, scenario_c with two TIAGo
    robots) into FOLDER/scenarios, then checks and compiles scenario_c into
    the store, simulates and ingests baseline runs, builds the baseline,
    verifies a new run and a run with a fault (which fails), derives a
    scenario without tiago2 with the oracles it must meet, simulates and
    verifies it, clusters the scenarios and writes the HTML report.  Each
    step prints the command it runs: docs/tutorial.md walks the same path by
    hand.  Exits 0 when every step ended as expected.

    \b
    Example:
      exscec demo exsce-demo && xdg-open exsce-demo/report/index.html
      exscec demo exsce-nav2 --convention nav2
    """
    from exsce_dsl.errors import ExsceError

    target = Path(folder)
    if target.exists() and any(target.iterdir()):
        raise ExsceError(f"{folder} is not empty: the demo starts from an empty folder (give another one)")
    target.mkdir(parents=True, exist_ok=True)
    shutil.copytree(example_folder(), target / SCENARIOS)
    if convention != "method":
        for spec in sorted((target / SCENARIOS).rglob("*.exsce")):
            spec.write_text(with_convention(spec.read_text(encoding="utf-8"), convention), encoding="utf-8")
    if setup_only:
        click.echo(f"copied the example scenarios into {target / SCENARIOS}", err=True)
        return
    shown = "" if convention == "method" else f" (robots on {convention}'s topics)"
    click.secho(f"exsce demo in {target.resolve()}{shown}", bold=True, err=True)
    outcomes: list[tuple[Step, int]] = []
    started = time.monotonic()
    with _inside(target, store_url):
        for number, step in enumerate(STEPS, start=1):
            click.secho(f"\n[{number}/{len(STEPS)}] {step.title}", bold=True, err=True)
            click.secho(f"$ {step.command}", fg="cyan", err=True)
            sys.stdout.flush()
            code = _run(_argv(step.command))
            outcomes.append((step, code))
            if code != step.expected_exit:
                raise ExsceError(
                    f"step {number} ({step.command}) exited {code}, not {step.expected_exit} as expected"
                )
    _summary(target, store_url, outcomes, time.monotonic() - started)


def _summary(
    target: Path, store_url: str | None, outcomes: Sequence[tuple[Step, int]], seconds: float
) -> None:
    click.secho(f"\nSummary ({seconds:.0f} s)", bold=True, err=True)
    for step, code in outcomes:
        if step.verdict is not None:
            shown = {0: "passed", 1: "FAILED", 2: "not judged"}.get(code, f"exit {code}")
            click.echo(f"  {shown:10} {step.verdict}", err=True)
    store = store_url or os.environ.get("EXSCE_STORE") or target / ".exsce" / "store"
    click.echo(f"  store      {store}", err=True)
    click.echo(f"  report     {target / 'report' / 'index.html'}", err=True)
    click.echo("  tutorial   docs/tutorial.md runs the same commands by hand", err=True)


COMMANDS = [demo]
