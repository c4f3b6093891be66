"""Benchmark: ingesting a 10-minute two-robot ROS 1 bag.

Writes the bag with the kinematic executor (scenario_c's robots doing their
deliveries over and over for about 10 minutes: robot_pose at 50 Hz, nav_vel
at 25 Hz, distance_travelled and a 720-beam LaserScan at 10 Hz per robot),
then measures in the same process, on the same file:

  (a) rosbags iterating the connections the metrics need, without deserializing;
  (b) the naive way: deserialize every message and update the metrics in a Python
      callback per message, as the method's monitors do;
  (c) exsce's ingestion: metrics + run PROV + write into an embedded store;
  (d) the metrics alone, as ingestion computes them: monitors generated from the
      metric declarations (the standard library's);
  (e) the metrics alone by the hand-written path (d) replaced, kept as the tests'
      reference (tests/reference_metrics.py), on the same decoded topics.

It prints MB/s and messages/s for each, the ratios, and peak memory (each
measurement in a fresh process, so peaks do not mix).  Targets: (c) at least
half the speed of (a) and at least 3× faster than (b); peak memory under 2× the
bag size; (d) at most 10 % slower than (e).

    python bench/ingest.py [--minutes 10] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "brsu_building_c"


def write_spec(folder: Path, rounds: int) -> Path:
    tasks = " then ".join(["delivery_a then navigate_home_1"] * rounds)
    tasks2 = " then ".join(["delivery_b then navigate_home_2"] * rounds)
    text = f"""import "{EXAMPLE / "environment.exsce"}"
import "{EXAMPLE / "robots.exsce"}"
import "{EXAMPLE / "tasks" / "deliveries.exsce"}"
import "{EXAMPLE / "tasks" / "navigation.exsce"}"

scenario long_run in brsu_building_c_with_doors {{
  robots {{
    tiago1: tiago starts at classroom_c025-w001
    tiago2: tiago starts at classroom_c025-w002
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


def needed_topics() -> list[str]:
    return [
        f"/{r}/{t}"
        for r in ("tiago1", "tiago2")
        for t in (
            "robot_pose",
            "scan",
            "nav_vel",
            "distance_travelled",
            "waypoint_dispatcher/feedback",
            "waypoint_dispatcher/result",
        )
    ]


# ------------------------------------------------------------ the three ways, each in its own process
def way_a(bag: Path) -> dict[str, float]:
    from rosbags.highlevel import AnyReader

    count, size = 0, 0
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in needed_topics()]
        for _, _, raw in reader.messages(connections=conns):
            count += 1
            size += len(raw)
    return {"messages": count, "bytes": size}


def way_b(bag: Path) -> dict[str, float]:
    """One Python callback per deserialized message, keeping running metrics as the method's monitors."""
    from rosbags.highlevel import AnyReader

    state: dict[str, dict[str, float]] = {}
    count = 0
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in needed_topics()]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            robot = conn.topic.split("/")[1]
            s = state.setdefault(robot, {"max_v": 0.0, "min_obstacle": math.inf, "distance": 0.0, "poses": 0})
            kind = conn.topic.split("/", 2)[2]
            if kind == "nav_vel":
                s["max_v"] = max(s["max_v"], math.hypot(msg.linear.x, msg.linear.y))
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


def way_c(bag: Path, spec: Path, store: Path) -> dict[str, float]:
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.runs.ingest import ingest_bags
    from exsce_dsl.store.embedded import EmbeddedStore

    scenario = load_spec(spec).scenario()
    with EmbeddedStore(store) as target:
        [result] = ingest_bags([bag], scenario, target)
    if result.failed:
        raise SystemExit(result.message)
    return {"statements": result.statements}


def way_d(bag: Path, spec: Path) -> dict[str, float]:
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.runs.analyse import analyse_bag

    analysed = analyse_bag(bag, load_spec(spec).scenario())
    return {"values": len(analysed.run.metrics)}


def way_e(bag: Path, spec: Path) -> dict[str, float]:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    import reference_metrics as reference

    from exsce_dsl.lang.build import load_spec

    values, _ = reference.metrics_of_bag(bag, load_spec(spec).scenario())
    return {"values": len(values)}


def child(argv: list[str]) -> None:
    way, bag = argv[0], Path(argv[1])
    start = time.perf_counter()
    if way == "a":
        out = way_a(bag)
    elif way == "b":
        out = way_b(bag)
    elif way == "d":
        out = way_d(bag, Path(argv[2]))
    elif way == "e":
        out = way_e(bag, Path(argv[2]))
    else:
        out = way_c(bag, Path(argv[2]), Path(argv[3]))
    out["seconds"] = time.perf_counter() - start
    out["peak_mb"] = _peak_mb()
    print(json.dumps(out))


def _peak_mb() -> float:
    """This process's peak resident memory (VmHWM: unlike ru_maxrss, not inherited across exec)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def measure(*args: str) -> dict[str, float]:
    done = subprocess.run(
        [sys.executable, __file__, "--child", *args], capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--keep", type=Path, help="Write the bag here and keep it.")
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child)
        return
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.sim.run import simulate

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        rounds = max(1, round(args.minutes * 60 / 115))  # one delivery + return ≈ 115 s, giving way included
        existing = sorted((folder / "bags").glob("*.bag")) if args.keep else []
        spec = folder / "long_run.exsce" if existing else write_spec(folder, rounds)
        t = time.perf_counter()
        if existing:  # --keep: reuse the bag written before
            from types import SimpleNamespace

            bag = existing[0]
            run = SimpleNamespace(bag=bag, messages=0, execution=SimpleNamespace(duration=float("nan")))
        else:
            [run] = simulate(load_spec(spec).scenario(), folder / "bags", runs=1, seed=1)
        size_mb = run.bag.stat().st_size / 1e6
        print(
            f"bag: {run.bag.name}, {size_mb:.0f} MB, {run.messages} messages, "
            f"{run.execution.duration / 60:.1f} min (written in {time.perf_counter() - t:.0f} s)"
        )
        a = measure("a", str(run.bag))
        b = measure("b", str(run.bag))
        c = measure("c", str(run.bag), str(spec), str(folder / "store"))
        d = min((measure("d", str(run.bag), str(spec)) for _ in range(3)), key=lambda r: r["seconds"])
        e = min((measure("e", str(run.bag), str(spec)) for _ in range(3)), key=lambda r: r["seconds"])
        n = a["messages"]
        for name, r in (
            ("(a) rosbags, no deserializing", a),
            ("(b) deserialize + callback", b),
            ("(c) exscec ingest", c),
            ("(d) metrics, generated monitors", d),
            ("(e) metrics, hand-written path", e),
        ):
            print(
                f"{name:32s} {r['seconds']:7.2f} s  {size_mb / r['seconds']:7.1f} MB/s  "
                f"{n / r['seconds']:9.0f} msg/s  "
                f"peak {r['peak_mb']:5.0f} MB ({r['peak_mb'] / size_mb:.2f}× bag)"
            )
        print(f"(c) vs (a): {a['seconds'] / c['seconds']:.2f}× the speed (target ≥ 0.5)")
        print(f"(c) vs (b): {b['seconds'] / c['seconds']:.1f}× faster (target ≥ 3)")
        print(f"(c) wrote {c['statements']:.0f} statements")
        print(
            f"(d) vs (e): {d['seconds'] / e['seconds']:.2f}× the time of the hand-written path "
            f"(target ≤ 1.10; best of 3 each; {d['values']:.0f} and {e['values']:.0f} values)"
        )


if __name__ == "__main__":
    main()
