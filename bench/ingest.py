"""Benchmark: ingesting a two-robot ROS 1 bag, in the method's convention and in Nav2's.

Writes the bag with the kinematic executor (scenario_c's robots doing their
deliveries over and over for ``--minutes``; the method's topics: robot_pose
at 50 Hz, nav_vel at 25 Hz, distance_travelled and a 720-beam LaserScan at 10 Hz
per robot; Nav2's: TF odom → base_link at 50 Hz and map → odom at 10 Hz,
Odometry at 50 Hz, cmd_vel at 20 Hz, amcl_pose at 2 Hz, the scan at 10 Hz and
navigate_to_pose's status and feedback), then measures in the same run, on
the same file, each way in a fresh process (so that peaks do not mix):

  (a) rosbags iterating the connections the metrics need, without deserializing;
  (b) the naive way: deserialize every message and update the metrics in a Python
      callback per message, as the method's monitors do;
  (c) ``exscec ingest`` itself (the command, run in the process as the console
      script runs it): metrics + run PROV + write into an embedded store;
  (d) the metrics alone, as ingestion computes them: monitors generated from the
      metric declarations (the standard library's);
  (e) the metrics alone by the hand-written path (d) replaced, kept as the tests'
      reference (tests/support/reference_metrics.py), on the same decoded topics.

It prints MB/s and messages/s for each, peak memory, the ratios, and (c)'s fixed
cost on a line of its own: the time from the start of ``exscec ingest`` to the
first time anything opens the bag (an audit hook sees the ``open``): importing
exsce, loading the spec, opening the store and adding the scenario's provenance,
whatever the bag's size.  Interpreter start-up is in no way's figures.  (c) runs
as a user's next ingest of a specification does: with the checked specification
in the user's cache folder (a child loads it there first; ``lang/spec_cache.py``).
The fixed cost printed is the median of five children stopped at the bag's first
open (one run is at the mercy of the machine's other work), beside (c)'s own; the
same for the first ingest after the specification changed (an empty cache
folder: the specification parsed and checked); and the machine's load average.
Every child runs with exsce's bytecode compiled, as an installed exsce has it:
under ``PYTHONDONTWRITEBYTECODE`` (set on some CI and sandbox machines) every
process would compile exsce's modules from source again, so the children write
it under a ``PYTHONPYCACHEPREFIX`` of their own in the temporary folder (a first
child compiles it); ``--source`` measures without.

Targets, on a 30-minute bag (``--minutes 30``): for the Nav2 bag, (c) at least
10× faster than (b), whose callbacks deserialize every TF message, and at least
2× the speed of (a); for the method's, (c) at least half the speed of (a) and
3× faster than (b), and (d) at most 10 % slower than (e); for both, peak memory
at most 1.5× the bag and the fixed cost at most 0.2 s.  Writing a 30-minute bag
takes a few minutes: ``--keep DIR`` writes it there once and reuses it.

    python bench/ingest.py [--minutes 10] [--keep DIR] [--convention method|nav2] [--source]
    python bench/ingest.py --minutes 30 --convention nav2 --keep /tmp/bags
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "brsu_building_c"


def write_spec(folder: Path, rounds: int, convention: str = "method") -> Path:
    robot_type = "tiago" if convention == "method" else "tiago_stack"
    own_type = (
        ""
        if convention == "method"
        else (f"robot type tiago_stack {{\n  base pmb2\n  torso yes\n  convention {convention}\n}}\n\n")
    )
    tasks = " then ".join(["delivery_a then navigate_home_1"] * rounds)
    tasks2 = " then ".join(["delivery_b then navigate_home_2"] * rounds)
    text = f"""import "{EXAMPLE / "environment.exsce"}"
import "{EXAMPLE / "robots.exsce"}"
import "{EXAMPLE / "tasks" / "deliveries.exsce"}"
import "{EXAMPLE / "tasks" / "navigation.exsce"}"

{own_type}scenario long_run in brsu_building_c_with_doors {{
  robots {{
    tiago1: {robot_type} starts at classroom_c025-w001
    tiago2: {robot_type} starts at classroom_c025-w002
  }}
  mission long_mission parallel {{
    tiago1 does {tasks}
    tiago2 does {tasks2}
  }}
}}
"""
    spec = folder / "long_run.exsce"
    spec.write_text(text)
    return spec


NEEDED = {
    "method": (
        "robot_pose",
        "scan",
        "nav_vel",
        "distance_travelled",
        "waypoint_dispatcher/feedback",
        "waypoint_dispatcher/result",
    ),
    "nav2": (
        "tf",
        "tf_static",
        "odom",
        "cmd_vel",
        "scan",
        "plan",
        "navigate_to_pose/_action/status",
        "navigate_to_pose/_action/feedback",
    ),
}
"""What the metrics read of each robot's topics, by convention."""


def needed_topics(convention: str = "method") -> list[str]:
    return [f"/{r}/{t}" for r in ("tiago1", "tiago2") for t in NEEDED[convention]]


# ------------------------------------------------------------ the three ways, each in its own process
def way_a(bag: Path, convention: str) -> dict[str, float]:
    from rosbags.highlevel import AnyReader

    count, size = 0, 0
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in needed_topics(convention)]
        for _, _, raw in reader.messages(connections=conns):
            count += 1
            size += len(raw)
    return {"messages": count, "bytes": size}


def way_b(bag: Path, convention: str) -> dict[str, float]:
    """One Python callback per deserialized message, keeping running metrics as the method's monitors."""
    from rosbags.highlevel import AnyReader

    state: dict[str, dict[str, float]] = {}
    count = 0
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in needed_topics(convention)]
        for conn, _, raw in reader.messages(connections=conns):
            msg: Any = reader.deserialize(raw, conn.msgtype)
            robot = conn.topic.split("/")[1]
            s = state.setdefault(robot, {"max_v": 0.0, "min_obstacle": math.inf, "distance": 0.0, "poses": 0})
            kind = conn.topic.split("/", 2)[2]
            if kind in ("nav_vel", "cmd_vel"):
                s["max_v"] = max(s["max_v"], math.hypot(msg.linear.x, msg.linear.y))
            elif kind == "odom":
                p = msg.pose.pose.position
                if "x" in s:
                    s["distance"] += math.hypot(p.x - s["x"], p.y - s["y"])
                s["x"], s["y"] = p.x, p.y
            elif kind == "tf":
                s["poses"] += sum(t.child_frame_id == "base_link" for t in msg.transforms)
            elif kind == "scan":
                valid = [r for r in msg.ranges if msg.range_min <= r <= msg.range_max]
                if valid:
                    s["min_obstacle"] = min(s["min_obstacle"], min(valid))
            elif kind == "distance_travelled":
                s["distance"] = msg.data
            elif kind == "robot_pose":
                s["poses"] += 1
            count += 1
    return {"messages": count}


class _BagOpened(Exception):
    """Raised by the audit hook at the bag's first open, to stop there (``--child s``)."""


def way_c(bag: Path, spec: Path, store: Path, stop_at_open: bool = False) -> dict[str, float]:
    """``exscec ingest BAG --scenario SPEC --store STORE``, run in this process as the command runs
    it; ``setup`` is the time from the start of this function (this module imports nothing of exsce)
    to the first time anything opens the bag: the imports, loading the spec, opening the store and
    adding the scenario's provenance, whatever the bag's size.  ``stop_at_open``: only that."""
    start = time.perf_counter()
    opened: list[float] = []
    target = str(bag.resolve())

    def on_open(event: str, args: tuple[object, ...]) -> None:
        if event == "open" and not opened and isinstance(args[0], (str, Path)):
            if str(Path(args[0]).resolve()) == target:
                opened.append(time.perf_counter())
                if stop_at_open:
                    raise _BagOpened

    sys.addaudithook(on_open)
    from exsce_dsl.cli.main import main

    try:
        main(["ingest", str(bag), "--scenario", str(spec), "--store", str(store)], standalone_mode=False)
    except SystemExit as exc:  # exits 1 when a bag failed
        if not stop_at_open:
            raise SystemExit(f"exscec ingest failed ({exc.code})") from None
    except _BagOpened:
        pass
    if stop_at_open:
        return {"setup": (opened or [math.nan])[0] - start}
    seconds = time.perf_counter() - start
    from exsce_dsl.store.embedded import EmbeddedStore

    with EmbeddedStore(store) as written:
        statements = len(written.quads())
    return {"statements": statements, "setup": (opened or [math.nan])[0] - start, "seconds": seconds}


def way_d(bag: Path, spec: Path) -> dict[str, float]:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.runs.analyse import analyse_bag

    analysed = analyse_bag(bag, load_spec(spec).scenario())
    return {"values": len(analysed.run.metrics)}


def way_e(bag: Path, spec: Path) -> dict[str, float]:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from exsce_dsl.lang import load_spec

    from tests.support import reference_metrics as reference  # type: ignore[import-not-found]

    values, _ = reference.metrics_of_bag(bag, load_spec(spec).scenario())
    return {"values": len(values)}


def child(argv: list[str]) -> None:
    way, bag = argv[0], Path(argv[1])
    start = time.perf_counter()
    if way == "a":
        out = way_a(bag, argv[2])
    elif way == "b":
        out = way_b(bag, argv[2])
    elif way == "d":
        out = way_d(bag, Path(argv[2]))
    elif way == "e":
        out = way_e(bag, Path(argv[2]))
    elif way == "s":
        out = way_c(bag, Path(argv[2]), Path(argv[3]), stop_at_open=True)
    elif way == "w":  # exsce compiled (as installed), the checked specification in the user's cache folder
        import compileall

        import exsce_dsl
        from exsce_dsl.lang import load_spec_cached

        if argv[3] == "compile":  # under the run's PYTHONPYCACHEPREFIX
            compileall.compile_dir(Path(exsce_dsl.__file__).parent, quiet=1)
        load_spec_cached(Path(argv[2]))
        out = {}
    else:
        out = way_c(bag, Path(argv[2]), Path(argv[3]))
    out.setdefault("seconds", time.perf_counter() - start)
    out["peak_mb"] = _peak_mb()
    print(json.dumps(out))


def _peak_mb() -> float:
    """This process's peak resident memory (VmHWM: unlike ru_maxrss, not inherited across exec)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


CHILD_ENV: dict[str, str] = dict(os.environ)
"""The children's environment: with exsce's bytecode kept in a folder of the run's own (see ``main``)."""
BYTECODE = ["as the environment has it"]
"""How the children get exsce's bytecode, for the fixed cost's line."""


def measure(*args: str, env: dict[str, str] | None = None) -> dict[str, float]:
    done = subprocess.run(
        [sys.executable, __file__, "--child", *args],
        capture_output=True,
        text=True,
        check=True,
        env=env or CHILD_ENV,
    )
    found: dict[str, float] = json.loads(done.stdout.strip().splitlines()[-1])
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--keep", type=Path, help="Write the bags here and keep them.")
    parser.add_argument("--convention", choices=sorted(NEEDED), help="Only this convention's bag.")
    parser.add_argument(
        "--source", action="store_true", help="Children compile exsce from source (no bytecode kept)."
    )
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child)
        return
    with tempfile.TemporaryDirectory() as tmp:
        if not args.source:
            CHILD_ENV.pop("PYTHONDONTWRITEBYTECODE", None)
            CHILD_ENV["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "pycache")
            BYTECODE[0] = "compiled once (as installed)"
        CHILD_ENV["EXSCE_CACHE"] = str(Path(tmp) / "cache")  # the run's own: its first ingest fills it
        for convention in [args.convention] if args.convention else list(NEEDED):
            folder = (args.keep or Path(tmp)) / convention
            folder.mkdir(parents=True, exist_ok=True)
            print(f"-- the {convention} convention")
            bench_convention(
                folder, convention, args.minutes, keep=args.keep is not None, compiled=not args.source
            )


FIXED_RUNS = 5
"""Children timed to the bag's first open, for each fixed cost (the median is printed)."""


def fixed_costs(bag: Path, spec: Path, folder: Path) -> tuple[float, float]:
    """The fixed cost of ``exscec ingest`` into a new store, with the specification in the run's
    cache folder (as after a first ingest) and with an empty one (the first ingest after the
    specification changed): medians of :data:`FIXED_RUNS` children each, stopped at the open."""
    found: dict[bool, list[float]] = {True: [], False: []}
    for i in range(FIXED_RUNS):
        for cached in (True, False):
            store, empty = folder / "store-fixed", folder / f"empty-cache-{i}"
            shutil.rmtree(store, ignore_errors=True)
            env = CHILD_ENV if cached else {**CHILD_ENV, "EXSCE_CACHE": str(empty)}
            found[cached].append(measure("s", str(bag), str(spec), str(store), env=env)["setup"])
            shutil.rmtree(store, ignore_errors=True)
            shutil.rmtree(empty, ignore_errors=True)
    return statistics.median(found[True]), statistics.median(found[False])


def bench_convention(folder: Path, convention: str, minutes: float, keep: bool, compiled: bool) -> None:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.sim.run import simulate

    rounds = max(1, round(minutes * 60 / 115))  # one delivery + return ≈ 115 s, giving way included
    existing = sorted((folder / "bags").glob("*.bag")) if keep else []
    spec = folder / "long_run.exsce" if existing else write_spec(folder, rounds, convention)
    t = time.perf_counter()
    if existing:  # --keep: reuse the bag written before
        from types import SimpleNamespace

        execution = SimpleNamespace(duration=float("nan"))
        run: Any = SimpleNamespace(bag=existing[0], messages=0, execution=execution)
    else:
        [run] = simulate(load_spec(spec).scenario(), folder / "bags", runs=1, seed=1)
    size_mb = run.bag.stat().st_size / 1e6
    print(
        f"bag: {run.bag.name}, {size_mb:.0f} MB, {run.messages} messages, "
        f"{run.execution.duration / 60:.1f} min (written in {time.perf_counter() - t:.0f} s)"
    )
    a = measure("a", str(run.bag), convention)
    b = measure("b", str(run.bag), convention)
    measure("w", str(run.bag), str(spec), "compile" if compiled else "no")
    shutil.rmtree(folder / "store", ignore_errors=True)  # a store that has the run would skip it
    c = measure("c", str(run.bag), str(spec), str(folder / "store"))
    warm, cold = fixed_costs(run.bag, spec, folder)
    ways = [("(a) rosbags, no deserializing", a), ("(b) deserialize + callback", b), ("(c) exscec ingest", c)]
    if convention == "method":
        d = min((measure("d", str(run.bag), str(spec)) for _ in range(3)), key=lambda r: r["seconds"])
        e = min((measure("e", str(run.bag), str(spec)) for _ in range(3)), key=lambda r: r["seconds"])
        ways += [("(d) metrics, generated monitors", d), ("(e) metrics, hand-written path", e)]
    n = a["messages"]
    for name, r in ways:
        print(
            f"{name:32s} {r['seconds']:7.2f} s  {size_mb / r['seconds']:7.1f} MB/s  "
            f"{n / r['seconds']:9.0f} msg/s  "
            f"peak {r['peak_mb']:5.0f} MB ({r['peak_mb'] / size_mb:.2f}× bag)"
        )
    speed, faster = (0.5, 3) if convention == "method" else (2.0, 10)
    print(f"(c) vs (a): {a['seconds'] / c['seconds']:.2f}× the speed (target ≥ {speed})")
    print(f"(c) vs (b): {b['seconds'] / c['seconds']:.1f}× faster (target ≥ {faster})")
    print(f"(c) peak memory: {c['peak_mb'] / size_mb:.2f}× the bag (target ≤ 1.5)")
    print(
        f"(c) fixed cost: {warm:.2f} s before the bag's first byte is read (imports, spec, store, "
        f"the scenario's PROV; target ≤ 0.2; median of {FIXED_RUNS}, this (c) {c['setup']:.2f} s); "
        f"{cold:.2f} s at the first ingest after the specification changed (parsed and checked); "
        f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; exsce's bytecode {BYTECODE[0]}"
    )
    print(f"(c) left {c['statements']:.0f} statements in the store (the scenario's and the run's)")
    if convention == "method":
        print(
            f"(d) vs (e): {d['seconds'] / e['seconds']:.2f}× the time of the hand-written path "
            f"(target ≤ 1.10; best of 3 each; {d['values']:.0f} and {e['values']:.0f} values)"
        )


if __name__ == "__main__":
    main()
