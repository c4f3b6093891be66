"""Every query of the library prints the same, byte for byte, from the embedded store (Oxigraph)
and from a real Virtuoso 7 holding the same runs: ``exscec runs`` and ``exscec query NAME`` as a
table, as JSON and as CSV.

What differed: Oxigraph printed ``2026-01-04T01:02:04.62Z`` and ``0`` where Virtuoso printed
``2026-01-04T01:02:04.620Z`` and ``0.0``; Virtuoso answered an AVG as a decimal (an integer, when
whole, in the Turtle exsce reads), summed in another order (26.71333332856496 against
26.713333328564964), and listed rows and concatenated topics in another order.

The runs are ingested into both stores by the CLI (compile, ingest, baseline, derive); what
carries the wall clock's time (a verification, an exploration campaign) is made once, in the
embedded store, and its graphs copied into Virtuoso as they are.
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from click.testing import CliRunner

from exsce_dsl.cli.main import main
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import query, query_names

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.store_servers import virtuoso_server
from tests.support.yard_spec import YARD_SPEC

FORMATS = ("table", "json", "csv")
EMPTY_HERE = {"campaign_shrinkings", "run_coverage", "run_problems"}
"""Queries with no rows on these runs (the campaign violated nothing, so shrank nothing; the
executor's recordings cover every run, and ingestion had nothing to say of them)."""


@dataclass(frozen=True)
class Stores:
    folder: Path
    embedded: str
    virtuoso: str

    def output(self, store: str, *args: str) -> str:
        done = exscec_here(*args, "--store", store, cwd=self.folder)
        assert done.returncode == 0, f"{args} on {store}: {done.stderr}"
        assert "Traceback" not in done.stderr
        return done.stdout

    def answer(self, store: str, *args: str) -> str:
        """What ``exscec ARGS --store STORE`` prints, run in this process (the comparison below
        runs 234 of them: a process each would cost a minute of starting Python)."""
        before = Path.cwd()
        os.chdir(self.folder)  # contextlib.chdir is Python 3.11's; exsce runs on 3.10 too
        try:
            done = CliRunner(env={"COLUMNS": "120"}).invoke(main, [*args, "--store", store])
        finally:
            os.chdir(before)
        assert done.exit_code == 0, f"{args} on {store}: {done.stderr}{done.exception!r}"
        return done.stdout


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Stores]:
    """Four runs of the yard and one over speed, with a baseline and a derived scenario, in both
    stores; a verification and a campaign made in the embedded one and copied."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = [str(run.bag) for run in simulate(scenario, folder / "runs", 4, seed=1)]
    faulty = simulate(scenario, folder / "faults", 1, seed=2, faults=(Fault.parse("overspeed:r1"),))
    bags += [str(run.bag) for run in faulty]
    with virtuoso_server(tmp_path_factory.mktemp("virtuoso")) as server:
        both = Stores(folder, str(folder / "store"), f"virtuoso+{server.url}")
        for store in (both.embedded, both.virtuoso):
            both.output(store, "compile", "spec.exsce")
            both.output(store, "ingest", *bags, "--scenario", "spec.exsce")
            both.output(store, "baseline", "spec.exsce")
            both.output(store, "derive", "spec.exsce", "--id", "yard_reversed", "-t", "reverse_waypoint_order",
                        "--task", "patrol_1", "-o", "reversed.exsce", "--expect", "--add-to-store")  # fmt: skip
        judged = exscec_here(
            "verify", bags[-1], "--scenario", "spec.exsce", "--store", both.embedded, cwd=folder
        )
        assert judged.returncode == 1 and "2 failed" in judged.stderr  # the run over speed
        both.output(
            both.embedded, "explore", "spec.exsce", "-n", "1", "-k", "1", "-t", "reverse_waypoint_order"
        )
        with open_store(both.embedded) as here, open_store(both.virtuoso, timeout=60) as there:
            missing = sorted(here.graph_names() - there.graph_names())
            assert any("validation" in name or "verdict" in name for name in missing), missing
            there.write(GraphSet({name: here.graph(name) for name in missing}))
        yield both


def _runs_of(stores: Stores) -> list[str]:
    answer = json.loads(stores.output(stores.embedded, "runs", "-f", "json"))
    return [row["run"]["value"] for row in answer["results"]["bindings"]]


def _first(stores: Stores, *args: str, needed: bool = True) -> dict[str, str]:
    answer = json.loads(stores.output(stores.embedded, *args, "-f", "json"))
    rows = answer["results"]["bindings"]
    assert rows or not needed, args
    return {name: term["value"] for name, term in rows[0].items()} if rows else {}


def _commands(stores: Stores, scenario: str = "yard_run", robot: str = "r1") -> dict[str, tuple[str, ...]]:
    """Each query of the library, with parameters that find something in these runs (a store
    without campaigns or verdicts gets parameters that find nothing there)."""
    runs = _runs_of(stores)
    everything = scenario == "yard_run"  # the yard's stores hold campaigns, verdicts, derivations
    every_run = tuple(a for run in runs for a in ("-p", f"run={run}"))
    segment = _first(stores, "query", "path_segments", "-p", f"scenario={scenario}")
    start, goal = segment["start"], segment["goal"]
    campaign = _first(stores, "query", "campaigns", needed=everything).get("campaign", "none")
    judged = _first(stores, "query", "verdicts", needed=everything).get("run", runs[-1])  # with its verdicts
    dispatched = _first(stores, "query", "run_lineage", "-p", f"run={judged}")["item"]  # its execution
    poses = ("-p", f"start={start}", "-p", f"goal={goal}")
    distance = ("-p", "metric=distance_travelled")
    speeding = ("-p", f"scenario={scenario}", "-p", "metric=max_velocity")
    given: dict[str, tuple[str, ...]] = {
        "action_times": every_run,
        "campaign_shrinkings": ("-p", f"campaign={campaign}"),
        "campaign_trials": ("-p", f"campaign={campaign}"),
        "campaigns": (),
        "derivation": ("-p", "scenario=yard_reversed"),
        "derived_scenarios": ("-p", f"base={scenario}"),
        "dispatched_runs": ("-p", f"prefix={dispatched[:8]}"),
        "hotspot_counts": speeding,
        "hotspots": every_run,
        "metric_names": (),
        "metric_sources": ("-p", f"run={runs[0]}", *distance),
        "mission_metric_stats": ("-p", "metric=mission_duration", *every_run),
        "oracles": ("-p", f"scenario={scenario}"),
        "path_segments": ("-p", f"scenario={scenario}"),
        "pose_positions": ("-p", f"pose={start}", "-p", f"pose={goal}"),
        "robot_metric_stats": ("-p", "metric=task_duration", "-p", f"robot={robot}", *every_run),
        "robot_names": (),
        "robots": ("-p", f"scenario={scenario}"),
        "run_ids": ("-p", f"prefix={runs[0][:8]}"),
        "run_known": ("-p", f"run={runs[0]}"),
        "run_lineage": ("-p", f"run={judged}"),
        "run_metric": ("-p", f"run={runs[0]}", *distance, "-p", f"robot={robot}"),
        "run_coverage": every_run,
        "run_metric_values": every_run,
        "run_problems": ("-p", f"run={runs[0]}"),
        "run_defects": ("-p", f"scenario={scenario}"),
        "run_mission_metric": ("-p", f"run={runs[0]}", "-p", "metric=mission_duration"),
        "run_scenarios": every_run,
        "run_segment_values": every_run,
        "run_topic_rates": every_run,
        "runs": ("-p", f"scenario={scenario}"),
        "safety_metrics": ("-p", f"scenario={scenario}"),
        "scenarios": (),
        "value_accounting": ("-p", f"run={runs[0]}", *distance),
        "segment_metric": (*distance, *poses, *every_run),
        "segment_metric_any": (*distance, *poses),
        "segment_metric_between": (
            *distance,
            "-p",
            f"from={start.split('-R')[0]}",
            "-p",
            f"to={goal.split('-R')[0]}",
        ),
        "segment_metric_of_scenario": (*distance, *poses, "-p", f"scenario={scenario}"),
        "verdicts": (),
        "violation_duration_stats": speeding,
        "violation_durations": speeding,
    }
    return {name: ("query", name, *arguments) for name, arguments in given.items()}


def test_every_query_prints_the_same_from_oxigraph_and_virtuoso(stores: Stores) -> None:
    commands = _commands(stores)
    commands["exscec runs"] = ("runs",)
    commands["exscec runs yard_run"] = ("runs", "yard_run")
    library = {name for name in query_names() if not query(name).is_update}
    assert library <= set(commands), "a query of the library is not compared"
    different = differences(stores, commands, EMPTY_HERE)
    assert not different, "\n\n".join(different)


def differences(stores: Stores, commands: dict[str, tuple[str, ...]], empty: set[str]) -> list[str]:
    """Each command (every query of the library among them) that prints otherwise on the two
    stores, in any format, with its first lines of difference."""
    different = []
    for name, command in commands.items():
        for fmt in FORMATS:
            here = stores.answer(stores.embedded, *command, "-f", fmt)
            there = stores.answer(stores.virtuoso, *command, "-f", fmt)
            if fmt == "json" and name not in empty:
                assert json.loads(here)["results"]["bindings"], f"{name} found nothing to compare"
            if not _same(here, there):
                lines = difflib.unified_diff(
                    here.splitlines(), there.splitlines(), "oxigraph", "virtuoso", n=0
                )
                different.append(f"{name} -f {fmt}:\n" + "\n".join(list(lines)[:8]))
    return different


_DECIMAL = re.compile(r"(-?\d+\.\d+(?:[eE][-+]?\d+)?)")


def _same(here: str, there: str) -> bool:
    """The same text, but for decimals computed by the store, which must agree to 12 significant
    digits: two engines add a mean's or a deviation's terms in their own order, and the 15th
    digit may differ (Oxigraph 11.2124893445545, Virtuoso 11.2124893445543)."""
    if here == there:
        return True
    mine, theirs = _DECIMAL.split(here), _DECIMAL.split(there)
    if len(mine) != len(theirs):
        return False
    for i, (a, b) in enumerate(zip(mine, theirs, strict=True)):
        if i % 2:  # a decimal
            if not math.isclose(float(a), float(b), rel_tol=1e-12):
                return False
        elif " ".join(a.split()) != " ".join(b.split()):  # a table pads to the longer decimal
            return False
    return True


def test_the_decimals_of_two_stores_agree_to_twelve_digits_and_nothing_else_may_differ() -> None:
    assert _same("6  26.713333328565  11.2124893445545", "6  26.713333328565  11.2124893445543")
    assert not _same("6  26.713333328565  11.2124893445545", "6  26.713333328565  11.2124893446")
    assert not _same("tiago1,26.7", "tiago2,26.7")
    assert not _same("a 1.5", "a 1.5 b")


def test_the_stumbles_values_print_in_one_form(stores: Stores) -> None:
    """The values of the stumble, as the comparison saw them: date-times with milliseconds and
    Z, whole doubles without a decimal point, doubles with 15 significant digits."""
    runs = stores.output(stores.virtuoso, "runs", "yard_run", "-f", "csv").splitlines()[1:]
    ends = [line.split(",")[3] for line in runs]
    assert ends and all(end.endswith("Z") and len(end.rsplit(".", 1)[1]) == len("000Z") for end in ends)
    values = json.loads(stores.output(stores.virtuoso, "query", "violation_durations", "-p", "scenario=yard_run",
                                      "-p", "metric=distance_to_obstacles", "-f", "json"))  # fmt: skip
    seconds = [row["seconds"] for row in values["results"]["bindings"]]
    assert seconds and {s["value"] for s in seconds} == {"0"}  # Virtuoso's 0.0, Oxigraph's 0
    assert {s["datatype"] for s in seconds} == {"http://www.w3.org/2001/XMLSchema#double"}
    stats = json.loads(stores.output(stores.virtuoso, "query", "segment_metric_of_scenario",
                                     "-p", "metric=distance_travelled", "-p", "scenario=yard_run",
                                     "-p", "start=field-d-R0.00_P0.00_Y0.00", "-p", "goal=field-c-R0.00_P0.00_Y0.00",
                                     "-f", "json"))["results"]["bindings"][0]  # fmt: skip
    # r2 drives field-d (8, 1) to field-c (8, 8) in the open yard: 7 m in each of the five runs
    assert (stats["count"]["value"], stats["mean"]["value"], stats["variance"]["value"]) == ("5", "7", "0")
    assert (
        stats["mean"]["datatype"]
        == stats["variance"]["datatype"]
        == "http://www.w3.org/2001/XMLSchema#double"
    )
