"""simulate → ingest → query through the exscec commands (in-process: tests/support/cli.py), in a
temporary project folder."""

from __future__ import annotations

import json
from pathlib import Path

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_d.exsce")


def test_simulate_ingest_and_query(in_tmp: Path) -> None:
    made = exscec_here("simulate", SPEC, "--runs", "2", "-o", "runs", "--seed", "3")
    assert made.returncode == 0, made.stderr
    bags = sorted(str(p) for p in (in_tmp / "runs").glob("*.bag"))
    assert len(bags) == 2 and len(list((in_tmp / "runs").glob("*.prov.json"))) == 2
    broken = in_tmp / "runs" / "broken.bag"
    broken.write_bytes(Path(bags[0]).read_bytes()[:4000])
    done = exscec_here("ingest", *sorted(str(p) for p in (in_tmp / "runs").iterdir()), "--scenario", SPEC)
    assert done.returncode == 2  # the broken bag failed...
    assert "broken.bag" in done.stderr and "Traceback" not in done.stderr
    assert "2 ingested, 0 skipped, 1 failed" in done.stderr  # ...the others went in
    again = exscec_here("ingest", *bags, "--scenario", SPEC)
    assert again.returncode == 0 and "0 ingested, 2 skipped, 0 failed" in again.stderr
    listed = exscec_here("runs", "--format", "json")
    assert listed.returncode == 0, listed.stderr
    rows = json.loads(listed.stdout)["results"]["bindings"]
    assert len(rows) == 2 and {r["scenario_id"]["value"] for r in rows} == {"scenario_d"}
    run_id = rows[0]["run"]["value"]
    value = exscec_here("query", "run_metric", "-p", f"run={run_id}", "-p", "metric=waypoints_visited",
                        "-p", "robot=tiago1", "--format", "csv")
    assert value.returncode == 0, value.stderr
    assert value.stdout.splitlines() == ["value,unit", "5,"]  # scenario_d visits 5 waypoints; a count has no unit
