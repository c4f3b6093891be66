"""Shared test helpers."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario, Task

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
FIXTURES = ROOT / "tests" / "fixtures" / "hbrs-sesame-models"


def run_exscec(*args: str, cwd: Path | None = None, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """Run the real ``exscec`` console script of this environment."""
    exe = Path(sys.executable).with_name("exscec")
    return subprocess.run(
        [str(exe), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "COLUMNS": "120"},
    )


def write_map(
    folder: Path,
    name: str = "map",
    size: int = 100,
    occupied: tuple[int, int, int, int] | None = None,
) -> Path:
    """A map_server map of ``size``² cells of 5 cm, origin (0, 0); ``occupied`` = (x0, y0, x1, y1) cells."""
    grid = np.full((size, size), 254, dtype=np.uint8)
    if occupied is not None:
        x0, y0, x1, y1 = occupied
        grid[size - y1 : size - y0, x0:x1] = 0  # rows count from the top
    (folder / f"{name}.pgm").write_bytes(f"P5\n{size} {size}\n255\n".encode() + grid.tobytes())
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return folder / f"{name}.yaml"


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="session")
def spec_c() -> tuple[Scenario, dict[str, Task]]:
    """The shipped scenario_c and the tasks its specification declares (loaded once)."""
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    return spec.scenario("scenario_c"), {t.id: t for t in spec.tasks}


# The yard of tests/oracles/test_verify_e2e (its docstring says what each fault should fail):
# two robots whose paths never meet in a 10 m square (map: write_map(folder, size=200)).
YARD_SPEC = """\
robot type tiago {
  base pmb2
  torso yes
}

environment yard {
  map yard file "map.yaml"
  area field {
    pose field-a at (1.0, 1.0)
    pose field-b at (1.0, 8.0)
    pose field-c at (8.0, 8.0)
    pose field-d at (8.0, 1.0)
    pose field-e at (4.5, 4.5)
  }
}

task patrol_1 {
  visit field-b, field-e
}

task patrol_2 {
  visit field-c
}

scenario yard_run in yard {
  robots {
    r1: tiago starts at field-a
    r2: tiago starts at field-d
  }
  mission yard_mission parallel {
    r1 does patrol_1
    r2 does patrol_2
  }
}

acceptance for yard_run {
  scenario "moves safely" {
    when yard_mission runs
    then each robot max_velocity stays below 1.0 m/s
     and each robot distance_to_obstacles stays above 0.1 m
     and distance_between_robots stays above 0.5 m
  }
  scenario "performs as before" {
    given at least 4 baseline runs
    when yard_mission runs
    then each robot waypoints_visited is invariant within 0
     and each robot task_duration is invariant within 20 %
     and each robot distance_travelled is invariant within 10 %
  }
}
"""
