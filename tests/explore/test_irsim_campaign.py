"""The shipped IR-SIM example's campaign finds IR-SIM's own fault, shrinks it and replays it.

``examples/irsim_crossing/crossing.exsce``: each robot works in its own room and every run passes.
``swap_assignment(robot=robot_w, with=robot_e)`` sends both across the hall, where IR-SIM's ``rvo``
(which takes the obstacle map as one round neighbour at its centroid, the hall's middle) stops
them short: no goal is reached (docs/irsim.md tells the story).  The same derivation played by the
kinematic executor passes, so the violation is IR-SIM's; and the finding's ``replay`` line plays
its run again with the same bytes."""

from __future__ import annotations

import hashlib
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = ROOT / "examples" / "irsim_crossing" / "crossing.exsce"
STEP = ["-n", "1", "-k", "1", "--max-steps", "1", "-t", "swap_assignment"]


def _explore(folder: Path, *more: str) -> subprocess.CompletedProcess[str]:
    command = [
        EXSCEC,
        "explore",
        str(SPEC),
        *STEP,
        "-o",
        str(folder / "campaign"),
        "--store",
        str(folder / "store"),
    ]
    return subprocess.run(
        [*command, *more], capture_output=True, text=True, cwd=folder, timeout=600, check=False
    )


def _digest(folder: Path) -> str:
    [bag] = list(folder.glob("*.bag"))
    return hashlib.sha256(bag.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def found(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    folder = tmp_path_factory.mktemp("irsim_campaign")
    return folder, _explore(folder, "--simulator", "irsim")


def test_the_campaign_finds_and_shrinks_the_stall(
    found: tuple[Path, subprocess.CompletedProcess[str]],
) -> None:
    _, done = found
    assert done.returncode == 1, done.stderr
    said = done.stdout
    assert "violated: robot_e waypoints_visited invariant (trial 1)" in said
    assert "smallest derivation (1 step): swap_assignment(robot=robot_w, with=robot_e)" in said
    assert "1 execution, 1 counterexample (100.0 per 100 executions), first failure after: 1" in said


def test_every_goal_of_the_smallest_derivation_made_no_progress(
    found: tuple[Path, subprocess.CompletedProcess[str]],
) -> None:
    folder, _ = found
    [derived] = list((folder / "campaign" / "runs").glob("crossing_*"))
    [prov] = list(derived.glob("*.prov.json"))
    text = prov.read_text()
    assert text.count('"exsce:goal_outcome": "no progress"') == 6  # 3 waypoints × 2 robots
    assert '"exsce:simulator": "irsim"' in text


def test_the_replay_line_plays_the_same_bag(found: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    folder, done = found
    [replay] = [line for line in done.stdout.splitlines() if line.strip().startswith("replay:")][:1]
    command = shlex.split(replay.split("replay:", 1)[1].replace("-o DIR", f"-o {folder / 'replayed'}"))
    assert command[:2] == ["exscec", "simulate"]
    again = subprocess.run([EXSCEC, *command[1:]], capture_output=True, text=True, timeout=300, check=False)
    assert again.returncode == 0, again.stderr
    derived = re.search(r"minimal/(crossing_[0-9a-f]+)\.exsce", replay)
    assert derived is not None
    assert _digest(folder / "replayed") == _digest(folder / "campaign" / "runs" / derived.group(1))


def test_the_kinematic_executor_passes_the_same_derivation(tmp_path: Path) -> None:
    done = _explore(tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 relations violated" in done.stdout
