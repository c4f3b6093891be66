"""Benchmark: the executor writing a run's bag, batches against one message at a time.

Simulates runs of the shipped scenario_c in each convention (and format) twice, in the same
process: (a) as ``exscec simulate`` does, each robot's high-rate topics serialized in batches
from a template (``exsce_dsl.sim.batches``); (b) the baseline, every message of those batches
built and serialized by rosbags on its own, as the executor wrote them before.  It prints the
CPU seconds per run of each, the ratio, and whether the two bags are the same bytes (they must
be).  Targets: (a) at least 1.5× faster for move_base (ROS 1) and 1.15× for Nav2 (MCAP: the
writer's own time per message, the same in both, is a larger share); the method's topics are
few at high rate, so about even there.  (Measured 2026-11-27 on 2 cores, over two runs:
method 1.0–1.2×, Nav2 1.2–1.5×, move_base 1.4–1.8×.)

    python bench/bag_batches.py [--runs 2]
"""

from __future__ import annotations

import argparse
import hashlib
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from exsce_dsl.lang import load_spec
from exsce_dsl.sim import batches
from exsce_dsl.sim.run import simulate

SPEC = Path(__file__).resolve().parents[1] / "examples" / "brsu_building_c" / "scenario_c.exsce"
CASES = (("method", "ros1"), ("nav2", "mcap"), ("move_base", "ros1"))


@contextmanager
def one_message_at_a_time() -> Iterator[None]:
    """The baseline: no batch is serialized from its template."""
    from_template = batches.Batch._from_template
    batches.Batch._from_template = lambda self, serialize: None  # type: ignore[method-assign]
    try:
        yield
    finally:
        batches.Batch._from_template = from_template  # type: ignore[method-assign]


def _digest(bag: Path) -> str:
    """The bag's bytes (a ROS 2 folder's files but its metadata.yaml, which dates itself)."""
    files = [bag] if not bag.is_dir() else sorted(p for p in bag.rglob("*") if p.suffix != ".yaml")
    digest = hashlib.sha256()
    for file in files:
        digest.update(file.read_bytes())
    return digest.hexdigest()


def _timed(folder: Path, convention: str, fmt: str, runs: int) -> tuple[float, list[str]]:
    scenario = load_spec(SPEC).scenario("scenario_c")
    started = time.process_time()
    bags = [run.bag for run in simulate(scenario, folder, runs, fmt, seed=7, convention=convention)]
    return (time.process_time() - started) / runs, [_digest(bag) for bag in bags]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=2)
    args = parser.parse_args()
    header = ("convention", "format", "batches s/run", "one by one s/run", "ratio")
    print(f"{header[0]:<10} {header[1]:<6} {header[2]:>14} {header[3]:>17} {header[4]:>6}  bytes")
    with tempfile.TemporaryDirectory() as scratch:
        for convention, fmt in CASES:  # a run of each first, untimed: the map, the typestores
            _timed(Path(scratch) / f"{convention}-warm", convention, fmt, 1)
        for convention, fmt in CASES:
            fast, fast_bags = _timed(Path(scratch) / f"{convention}-batches", convention, fmt, args.runs)
            with one_message_at_a_time():
                slow, slow_bags = _timed(Path(scratch) / f"{convention}-single", convention, fmt, args.runs)
            same = "same" if fast_bags == slow_bags else "DIFFERENT"
            print(f"{convention:<10} {fmt:<6} {fast:>14.2f} {slow:>17.2f} {slow / fast:>5.1f}×  {same}")


if __name__ == "__main__":
    main()
