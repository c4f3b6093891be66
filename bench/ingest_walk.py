"""The walk of one bag through ingestion: which steps ``analyse_bag`` enters, in which order.

Traces every call into ``exsce_dsl`` while one simulated run of scenario_c is analysed
(``sys.setprofile``), then prints:

- the steps ``analyse_bag`` enters (``runs/bags`` → ``runs/signals`` → ...), consecutive
  calls into one step counted once: a walk straight down enters each step once;
- stops: the package's files the walk enters; returns: entries into a file already left;
- climbs: calls from a later step of ``runs`` (or a higher layer) into an earlier one's caller,
  i.e. a callee in a *higher* step than its caller.

Run: ``PYTHONPATH=src python bench/ingest_walk.py``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from types import FrameType
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "exsce_dsl"
RUNS_STEPS = ["bags", "signals", "segments", "metrics", "coverage", "recorded_execution"]
"""The steps of ``runs`` in their import order; every other module of ``runs`` is on top."""


def _module(frame: FrameType) -> str | None:
    """The package file of ``frame`` (``runs/bags/reading.py``), None outside the package."""
    try:
        return str(Path(frame.f_code.co_filename).resolve().relative_to(PACKAGE))
    except ValueError:
        return None


def _step(module: str) -> str:
    """The step of ``runs`` a file belongs to (``runs/analyse`` for the top of ``runs``)."""
    parts = Path(module).with_suffix("").parts
    if parts[0] != "runs":
        return parts[0]
    return f"runs/{parts[1]}" if len(parts) > 1 and parts[1] in RUNS_STEPS else "runs/analyse"


def _rank(step: str) -> int:
    if step.startswith("runs/"):
        name = step.split("/", 1)[1]
        return 100 + (RUNS_STEPS.index(name) if name in RUNS_STEPS else len(RUNS_STEPS))
    return 200 if step in {"sim", "oracles", "derive", "execute"} else 0


def main() -> None:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.runs.analyse import analyse_bag
    from exsce_dsl.sim.run import simulate

    scenario = load_spec(ROOT / "examples" / "brsu_building_c" / "scenario_c.exsce").scenario()
    with tempfile.TemporaryDirectory() as folder:
        [run] = simulate(scenario, Path(folder), runs=1, fmt="ros1", seed=7)
        bag = run.bag
        analyse_bag(bag, scenario)  # warm: imports, the standard library's cache
        calls: list[tuple[str, str]] = []

        def profile(frame: FrameType, event: str, arg: Any) -> None:
            if event != "call":
                return
            callee = _module(frame)
            caller = _module(frame.f_back) if frame.f_back is not None else None
            if callee is not None and caller is not None and callee != caller:
                calls.append((caller, callee))

        sys.setprofile(profile)
        try:
            analyse_bag(bag, scenario)
        finally:
            sys.setprofile(None)
    _report(calls)


def _report(calls: list[tuple[str, str]]) -> None:
    top = [_step(b) for a, b in calls if _step(a) == "runs/analyse" and _step(b) in _STEPS]
    walk = _collapsed(top)
    print("steps the top of runs enters:", " → ".join(s.removeprefix("runs/") for s in walk))
    print(
        "entries per step:",
        ", ".join(f"{s.removeprefix('runs/')} {walk.count(s)}" for s in dict.fromkeys(walk)),
    )
    inside = _collapsed([_step(b) for _, b in calls if _step(b).startswith("runs/")])
    seen: set[str] = set()
    returns = 0
    for before, after in zip(inside, inside[1:], strict=False):
        seen.add(before)
        returns += after in seen
    files = {f for call in calls for f in call}
    runs_files = {f for f in files if f.startswith("runs/")}
    climbs = {(a, b) for a, b in calls if _rank(_step(b)) > _rank(_step(a)) >= 100}
    print(f"files entered: {len(files)} ({len(runs_files)} of runs/)")
    print(f"step changes inside runs/: {len(inside) - 1}, of which returns to a step already left: {returns}")
    print(f"climbs (caller → callee of a later step of runs/): {len(climbs)}")
    for a, b in sorted(climbs):
        print(f"  {a} → {b}")


_STEPS = {f"runs/{s}" for s in RUNS_STEPS}


def _collapsed(steps: list[str]) -> list[str]:
    """``steps`` with consecutive repeats counted once."""
    return [s for i, s in enumerate(steps) if i == 0 or steps[i - 1] != s]


if __name__ == "__main__":
    main()
