"""Issue 51, item 6: ``exscec export --to osc2``.  What scenario_c's OSC2 scenario says, read from
its text and compared with the spec as exsce loads it (not with the writer's own values); names
that OSC2 cannot take are refused where the spec writes them, or mapped to the robot's id."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from exsce_dsl.api import export_spec
from exsce_dsl.codegen.osc2 import STARTUP, osc2_number
from exsce_dsl.errors import ExportError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import MissionType, Scenario

from tests.support.cli import exscec_here
from tests.support.hostile_specs import spec_text
from tests.support.paths import EXAMPLES

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
ORCHARD = EXAMPLES / "drones" / "orchard.exsce"

_ACTION = re.compile(r"^(?P<indent> *)(?P<actor>\w+)\.(?P<action>follow_waypoints|nav_to_pose)\(")
_TIMEOUT = re.compile(r"timeout\((?P<seconds>[0-9.]+)s\)")


def _export(spec: Path, folder: Path, scenario: str | None = None) -> str:
    (written,) = export_spec(spec, "osc2", folder, scenario)
    return written.read_text(encoding="utf-8")


def _code(text: str) -> list[str]:
    """The lines of an export that are not comments or blank, each without its trailing comment
    (the export writes ``  # `` only after code, and its literals hold no ``#`` here)."""
    lines = [line.split("  # ")[0].rstrip() for line in text.splitlines()]
    return [line for line in lines if line.strip() and not line.lstrip().startswith("#")]


def _actors(lines: list[str]) -> dict[str, str]:
    """Actor name -> the namespace its ``keep`` says."""
    found = {}
    for line, after in zip(lines, lines[1:], strict=False):
        if m := re.fullmatch(r" {4}(\w+): differential_drive_robot with:", line):
            namespace = re.fullmatch(r" {8}keep\(it\.namespace == (\".*\")\)", after)
            assert namespace, after
            found[m.group(1)] = json.loads(namespace.group(1))
    return found


def _topics(lines: list[str]) -> list[str]:
    start = lines.index("        bag_record([")
    end = next(i for i in range(start, len(lines)) if lines[i].endswith("])"))
    return [json.loads(line.strip().rstrip(",").removesuffix("])")) for line in lines[start + 1 : end + 1]]


def _mission(lines: list[str]) -> tuple[str, list[list[tuple[str, str, int, float]]]]:
    """The mission block's kind and its lanes: per action, actor, action, poses and timeout."""
    blocks = [i for i, line in enumerate(lines) if line in ("        parallel:", "        serial:")]
    start = blocks[-1]  # the first block starts the robots (init_nav2), the last runs the mission
    kind = lines[start].strip().rstrip(":")
    lanes: list[list[tuple[str, str, int, float]]] = [] if kind == "parallel" else [[]]
    for i in range(start + 1, len(lines)):
        if lines[i] == "            serial:":
            lanes.append([])
        elif m := _ACTION.match(lines[i]):
            end = next(j for j in range(i, len(lines)) if lines[j].endswith("with:"))
            poses = sum(lines[j].count("pose_3d(") for j in range(i, end + 1))
            timeout = _TIMEOUT.fullmatch(lines[end + 1].strip())
            assert timeout, lines[end + 1]
            lanes[-1].append((m["actor"], m["action"], poses, float(timeout["seconds"])))
    return kind, lanes


def _expected_lanes(scenario: Scenario) -> list[list[tuple[str, str, int]]]:
    """The mission as the spec allocates it: per robot (parallel) or as written (sequential)."""
    entries = []
    for assignment in scenario.mission.allocation:
        task = scenario.task(assignment.task)
        robot = scenario.robot(assignment.robot)
        assert task is not None and robot is not None
        waypoints = sum(len(s.waypoints) for s in task.subtasks)
        action = "follow_waypoints" if waypoints > 1 else "nav_to_pose"
        entries.append((robot.namespace, action, waypoints))
    if scenario.mission.type is MissionType.SEQUENTIAL:
        return [entries]
    return [[e for e in entries if e[0] == r.namespace] for r in scenario.robots]


def test_scenario_c_says_the_spec(tmp_path: Path) -> None:
    spec = load_spec(SCENARIO_C)
    scenario = spec.scenario()
    text = _export(SCENARIO_C, tmp_path)
    lines = _code(text)
    assert _actors(lines) == {"tiago1": "tiago1", "tiago2": "tiago2"}
    assert [r.namespace for r in scenario.robots] == ["tiago1", "tiago2"]
    kind, lanes = _mission(lines)
    assert kind == "parallel"
    assert [[a[:3] for a in lane] for lane in lanes] == _expected_lanes(scenario)
    assert [[a[:3] for a in lane] for lane in lanes] == [
        [("tiago1", "follow_waypoints", 2), ("tiago1", "nav_to_pose", 1)],
        [("tiago2", "follow_waypoints", 2), ("tiago2", "nav_to_pose", 1)],
    ]
    topics = _topics(lines)
    assert len(topics) == len(set(topics))
    for ns in ("tiago1", "tiago2"):  # what the metrics read from a Nav2 robot (DESIGN.md §1)
        for topic in ("scan", "cmd_vel", "odom", "amcl_pose", "navigate_to_pose/_action/status"):
            assert f"/{ns}/{topic}" in topics
    assert {"/tf", "/tf_static", "/clock"} <= set(topics)
    assert "/exsce/prov" not in topics  # no exsce dispatcher publishes it under scenario_execution
    assert not any("waypoint_dispatcher" in t or "move_base" in t for t in topics)
    starts = [line for line in lines if ".init_nav2(" in line]
    assert [s.split(".")[0].strip() for s in starts] == ["tiago1", "tiago2"]
    assert "44.80387496948242m, y: 37.15502166748047m" in starts[0]  # classroom_c025-w001
    scenario_timeout = _TIMEOUT.search(lines[lines.index("scenario scenario_c:") + 1])
    assert (
        scenario_timeout
        and float(scenario_timeout["seconds"]) == max(sum(a[3] for a in lane) for lane in lanes) + STARTUP
    )
    acceptance = spec.acceptance_of("scenario_c")
    assert acceptance is not None
    for criterion in acceptance.criteria:
        assert f'#   "{criterion.title}"' in text


def test_sequential_mission_is_one_serial_block(tmp_path: Path) -> None:
    scenario = load_spec(ORCHARD).scenario()
    kind, lanes = _mission(_code(_export(ORCHARD, tmp_path)))
    assert kind == "serial"
    assert [[a[:3] for a in lane] for lane in lanes] == _expected_lanes(scenario)
    assert {a[0] for a in lanes[0]} == {"m210_1", "m210_2"}


def test_task_timeouts_are_the_specs(tmp_path: Path) -> None:
    """scenario_e's tasks or mission give goal timeouts: each action's is the sum of its goals'."""
    text = (EXAMPLES / "brsu_building_c" / "scenario_c.exsce").read_text(encoding="utf-8")
    spec = tmp_path / "timed.exsce"
    spec.write_text(
        text.replace('import "', f'import "{SCENARIO_C.parent}/').replace(
            "mission mission_c parallel {", "mission mission_c parallel {\n    timeout 40 s"
        ),
        encoding="utf-8",
    )
    _, lanes = _mission(_code(_export(spec, tmp_path)))
    assert [[a[2:] for a in lane] for lane in lanes] == [[(2, 80.0), (1, 40.0)], [(2, 80.0), (1, 40.0)]]


def _hostile(tmp_path: Path, **replace: str) -> Path:
    text = spec_text()
    for old, new in replace.items():
        text = text.replace(old, new)
    path = tmp_path / "names.exsce"
    path.write_text(text, encoding="utf-8")
    return path


def _line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


@pytest.mark.parametrize(
    ("replace", "where", "said"),
    [
        ({"r2: rover": 'r-2: rover namespace ""', "r2 does": "r-2 does"}, "r-2: rover", "robot id 'r-2'"),
        ({"yard_run": "yard-run"}, "scenario yard-run", "scenario id 'yard-run'"),
        ({"r2: rover": 'm: rover namespace "/"', "r2 does": "m does"}, "m: rover", "robot id 'm'"),
    ],
)
def test_name_that_osc2_cannot_take_is_refused_where_written(
    tmp_path: Path, replace: dict[str, str], where: str, said: str
) -> None:
    spec = _hostile(tmp_path, **replace)
    assert exscec_here("check", str(spec)).returncode == 0  # a valid exsce spec
    done = exscec_here("export", str(spec), "--to", "osc2", "-o", str(tmp_path / "out"))
    assert done.returncode == 2, done.stdout + done.stderr
    assert re.search(rf"names\.exsce:{_line_of(spec, where)}:\d+: .*{re.escape(said)}", done.stderr), (
        done.stderr
    )
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_namespace_that_is_no_osc2_name_names_the_actor_by_robot_id(tmp_path: Path) -> None:
    spec = _hostile(
        tmp_path, **{'namespace "r1"': 'namespace "fleet/r1"', "r2: rover": 'r2: rover namespace "s"'}
    )
    actors = _actors(_code(_export(spec, tmp_path)))
    assert actors == {"r1": "fleet/r1", "r2": "s"}  # 's' (seconds) is an OSC2 keyword


def test_robot_without_start_pose_is_not_started(tmp_path: Path) -> None:
    """As in exsce's runs, a robot with no start pose (and so no task) takes no part."""
    spec = _hostile(tmp_path, **{"r2: rover starts at yard-d": "r2: rover", "    r2 does round_2\n": ""})
    lines = _code(_export(spec, tmp_path))
    assert set(_actors(lines)) == {"r1", "r2"}
    assert [line.split(".")[0].strip() for line in lines if ".init_nav2(" in line] == ["r1"]
    assert _mission(lines)[1] == [[("r1", "nav_to_pose", 1, 60.0)]]


def test_two_robots_one_actor_name_is_refused(tmp_path: Path) -> None:
    """r2's namespace is r1's id, at the root (r1's own namespace is no OSC2 name)."""
    spec = _hostile(
        tmp_path, **{'namespace "r1"': 'namespace "fleet/r1"', "r2: rover": 'r2: rover namespace "r1"'}
    )
    done = exscec_here("export", str(spec), "--to", "osc2", "-o", str(tmp_path / "out"))
    assert done.returncode == 2
    assert f"names.exsce:{_line_of(spec, 'r2: rover')}:" in done.stderr
    assert "robots 'r1' and 'r2' would both be the OSC2 actor 'r1'" in done.stderr


@pytest.mark.parametrize(
    ("value", "written"),
    [
        (1e-05, "0.00001"),
        (-2.5, "-2.5"),
        (3.0, "3.0"),
        (1e20, "100000000000000000000.0"),
        (0.1 + 0.2, "0.30000000000000004"),
    ],
)
def test_numbers_are_decimal_literals(value: float, written: str) -> None:
    assert osc2_number(value) == written


def test_a_number_that_is_not_finite_is_refused() -> None:
    with pytest.raises(ExportError, match="not a finite number"):
        osc2_number(float("nan"))


def test_export_to_a_file_or_a_folder(tmp_path: Path) -> None:
    to_file = exscec_here("export", str(SCENARIO_C), "--to", "osc2", "-o", str(tmp_path / "c.osc"))
    assert to_file.returncode == 0, to_file.stderr
    to_folder = exscec_here("export", str(SCENARIO_C), "--to", "osc2", "-o", str(tmp_path / "out"))
    assert to_folder.returncode == 0, to_folder.stderr
    assert (tmp_path / "c.osc").read_text() == (tmp_path / "out" / "scenario_c.osc").read_text()
    refused = exscec_here("export", str(SCENARIO_C), "--to", "yaml", "-o", str(tmp_path / "c.osc"))
    assert refused.returncode == 2 and "is a file" in refused.stderr
