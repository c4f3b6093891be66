"""Benchmark: how often a performance clause fails a healthy run, and how often it catches a fault.

(draft: filled in below)
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from exsce_dsl.lang.build import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.faults import FAULT_KINDS, Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore

SPEC = Path(__file__).resolve().parent.parent / "examples" / "brsu_building_c" / "scenario_c.exsce"
FAULTS = (
    "overspeed:tiago1",
    "slow:tiago1",
    "skip-waypoint:tiago1",
    "near-collision",
    "detour:classroom_c022:classroom_c018",
    "slow-area:classroom_c018",
)
"""The faults planted, each one that shows in scenario_c's own runs: every plain fault of
exsce_dsl.sim.faults, and the latent ones whose trigger scenario_c has (its robots drive
classroom_c022 → classroom_c018)."""
MANIFEST = "runs.json"


def fill(
    store: EmbeddedStore, scenario: Scenario, folder: Path, runs: int, faulty: int, jobs: int
) -> dict[str, list[str]]:
    """Simulate and ingest the runs once: ``runs`` fault-free ones and ``faulty`` of each fault;
    the run uuids by group (``""`` for the fault-free runs) are kept next to the store."""
    manifest = folder / MANIFEST
    groups: dict[str, list[str]] = json.loads(manifest.read_text()) if manifest.exists() else {}
    wanted = {"": runs, **{fault: faulty for fault in FAULTS}}
    for seed, (group, count) in enumerate(wanted.items()):
        have = groups.get(group, [])
        if len(have) >= count:
            continue
        faults = (Fault.parse(group),) if group else ()
        started = time.perf_counter()
        out = folder / "bags" / (group.replace(":", "_") or "fault-free")
        bags = [r.bag for r in simulate(scenario, out, count, seed=1 + 10_000 * seed, faults=faults)]
        simulated = time.perf_counter() - started
        results = ingest_bags(bags, scenario, store, jobs=jobs)
        failed = [r for r in results if r.failed]
        assert not failed, failed[0].message
        groups[group] = [r.run_id for r in results if r.run_id is not None]
        manifest.write_text(json.dumps(groups, indent=1))
        print(
            f"{group or 'fault-free'}: {count} runs simulated in {simulated:.0f} s, "
            f"ingested in {time.perf_counter() - started - simulated:.0f} s",
            flush=True,
        )
    return groups


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="40 fault-free runs and 10 of each fault")
    parser.add_argument("--runs", type=int, default=200, help="fault-free runs")
    parser.add_argument("--faulty-runs", type=int, default=30, help="runs of each fault")
    parser.add_argument("--jobs", type=int, default=1, help="ingest worker processes")
    parser.add_argument("--store", type=Path, help="keep the runs in this folder (filled once, reused after)")
    parser.add_argument("--fill-only", action="store_true")
    options = parser.parse_args()
    runs, faulty = (40, 10) if options.quick else (options.runs, options.faulty_runs)
    spec = load_spec(SPEC)
    scenario = spec.scenario("scenario_c")
    assert all(Fault.parse(f).kind in FAULT_KINDS for f in FAULTS)
    with tempfile.TemporaryDirectory(prefix="exsce-oracles-") as scratch:
        folder = options.store or Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        store = EmbeddedStore(folder / "store")
        fill(store, scenario, folder, runs, faulty, options.jobs)
        store.close()


if __name__ == "__main__":
    main()
