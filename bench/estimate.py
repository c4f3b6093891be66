"""Benchmark: how good the estimate for a path segment no run drove is, on the executor's runs.

Simulates runs of the shipped building-C scenarios (a to e), ingests them into a
temporary embedded store, then for every segment the runs drove, holds it out
(as if no run had driven it, in either direction) and estimates it from the
segments near it (exsce_dsl.derive.expect.segment_value), against the mean of
what was driven.  Prints, per metric, the median and 90th-percentile relative
error and how many segments could be estimated at all.

    python bench/estimate.py              # 2 runs of each scenario
    python bench/estimate.py --runs 3

Prints figures; never a unit test.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

from exsce_dsl.derive.expect import SUMMED, robot_path, segment_value
from exsce_dsl.lang.build import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "brsu_building_c"


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, round(q * (len(ordered) - 1))))]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--runs", type=int, default=2, help="simulated runs of each scenario")
    options = parser.parse_args()
    scenarios: list[Scenario] = [
        load_spec(EXAMPLES / f"scenario_{letter}.exsce").scenario() for letter in "abcde"
    ]
    with tempfile.TemporaryDirectory(prefix="exsce-estimate-") as folder:
        store = EmbeddedStore(Path(folder) / "store")
        for n, scenario in enumerate(scenarios):
            bags = [r.bag for r in simulate(scenario, Path(folder) / scenario.id, options.runs, seed=n + 1)]
            failed = [r for r in ingest_bags(bags, scenario, store) if r.failed]
            assert not failed, failed
        print(f"{options.runs} simulated runs of each of {', '.join(s.id for s in scenarios)}")
        for metric in SUMMED:
            errors: list[float] = []
            missing = 0
            seen: set[frozenset[str]] = set()
            for scenario in scenarios:
                for robot in scenario.robots:
                    for start, goal in robot_path(scenario, robot.id):
                        pair = frozenset((start.id, goal.id))
                        if pair in seen or len(pair) < 2:
                            continue
                        seen.add(pair)
                        measured = segment_value(store, scenario, metric, start, goal)
                        if measured.value is None or not measured.value:
                            continue
                        estimate = segment_value(store, scenario, metric, start, goal, frozenset({pair}))
                        if estimate.value is None:
                            missing += 1
                            continue
                        errors.append(abs(estimate.value - measured.value) / measured.value)
            if errors:
                print(
                    f"{metric}: {len(errors)} segments estimated ({missing} had no neighbour data), "
                    f"relative error median {statistics.median(errors):.1%}, "
                    f"90th percentile {percentile(errors, 0.9):.1%}, worst {max(errors):.1%}"
                )
            else:
                print(f"{metric}: no segment could be estimated ({missing} without neighbour data)")
        store.close()


if __name__ == "__main__":
    main()
