"""Exit codes that mean one thing in every command: 0 all passed, 1 a verdict failed, 2 bad input
or usage (a spec error, no oracles, an unknown run, a bag that cannot be read), 3 a judgement that
could not be made, 70 a bug of exsce.

Real runs of the yard of tests/oracles/test_verify_e2e: four clean runs make the baseline; a
fifth passes, an over-speed run fails, and a copy of a clean run without r2's laser scans
(rewritten with rosbags) cannot be judged on r2's distance to obstacles.
"""

from __future__ import annotations

import datetime as dt
import json
import shutil
import uuid
import xml.etree.ElementTree as ET
from pathlib import Path

import click
import pytest
from click.testing import CliRunner
from rosbags.rosbag1 import Reader, Writer

from exsce_dsl.cli.common import ExitCode, reports_errors
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, RunStatus
from exsce_dsl.prov.recorder import recorded_prov_json, recorded_run
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here, run_exscec
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC


def _without_topic(bag: Path, topic: str, out: Path) -> Path:
    """A copy of ROS 1 ``bag`` without ``topic``: every other message as it was, byte for byte."""
    with Reader(bag) as reader, Writer(out) as writer:
        kept = [c for c in reader.connections if c.topic != topic]
        assert len(kept) == len(reader.connections) - 1
        added = {
            c.id: writer.add_connection(
                c.topic,
                c.msgtype,
                msgdef=c.msgdef.data,
                md5sum=c.digest,
                callerid=c.ext.callerid,  # type: ignore[union-attr]
                latching=c.ext.latching,  # type: ignore[union-attr]
            )
            for c in kept
        }
        for connection, timestamp, raw in reader.messages(connections=kept):
            writer.write(added[connection.id], timestamp, raw)
    return out


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Path]]:
    """The project folder (baseline built from four clean runs) and the bags to judge."""
    folder = tmp_path_factory.mktemp("yard_exits")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    clean = [run.bag for run in simulate(scenario, folder / "runs", 5, seed=1)]
    fast = next(iter(simulate(scenario, folder / "faults", 1, seed=2, faults=(Fault.parse("overspeed:r1"),))))
    ingested = exscec_here("ingest", *map(str, clean[:4]), "--scenario", "spec.exsce", cwd=folder)
    assert ingested.returncode == 0, ingested.stderr
    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    (folder / "blind").mkdir()
    blind = _without_topic(clean[4], "/r2/scan", folder / "blind" / "no_r2_scan.bag")
    return folder, {"clean": clean[4], "fast": fast.bag, "blind": blind, "first": clean[0]}


def test_no_oracles_exits_2_not_1(yard: tuple[Path, dict[str, Path]]) -> None:
    folder, bags = yard
    store = str(folder / "no-baseline")  # runs, but no baseline built
    ingested = exscec_here(
        "ingest", str(bags["first"]), "--scenario", "spec.exsce", "--store", store, cwd=folder
    )
    assert ingested.returncode == 0, ingested.stderr
    judged = run_exscec("verify", str(bags["fast"]), "--scenario", "spec.exsce", "--store", store, cwd=folder)
    assert judged.returncode == 2, judged.stdout + judged.stderr
    assert "error: scenario 'yard_run' has no oracles in the store" in judged.stderr
    assert "Traceback" not in judged.stderr


def test_verify_exits_0_passed_1_failed_2_bad_input_3_not_judged(yard: tuple[Path, dict[str, Path]]) -> None:
    folder, bags = yard

    def verify(*runs: str, spec: str = "spec.exsce") -> tuple[int, str, str]:
        done = run_exscec("verify", *runs, "--scenario", spec, "--no-record", cwd=folder)
        assert "Traceback" not in done.stderr
        return done.returncode, done.stdout, done.stderr

    assert verify(str(bags["clean"]))[0] == ExitCode.PASSED == 0
    code, table, said = verify(str(bags["fast"]))
    assert code == ExitCode.FAILED == 1 and "FAIL" in table and "r1-max_velocity" in table, said
    code, table, said = verify(str(bags["blind"]))
    assert code == ExitCode.INCONCLUSIVE == 3, table + said  # r2's distance to obstacles has no scans
    inconclusive = [line for line in table.splitlines() if "inconclusive" in line]
    assert inconclusive and all("r2-distance_to_obstacles" in line for line in inconclusive), table
    assert "FAIL" not in table and "0 failed, 1 inconclusive" in said
    code, _, said = verify(str(bags["blind"]), str(bags["fast"]))  # a failure outweighs the rest
    assert code == 1, said

    code, _, said = verify("0123abcd")
    assert code == ExitCode.BAD_INPUT == 2 and "the store holds no run 0123abcd; the closest ids" in said
    (folder / "broken.exsce").write_text(YARD_SPEC.replace("r1: tiago starts", "r1: tiagoo starts"))
    code, _, said = verify(str(bags["clean"]), spec="broken.exsce")
    assert code == 2 and "broken.exsce:" in said and "unknown robot type 'tiagoo'" in said
    code, _, said = verify("runs/nothing-here.bag")
    assert code == 2 and "error: no bag or bag folder runs/nothing-here.bag (nor is it a run id)" in said


def test_the_other_commands_use_the_same_codes(yard: tuple[Path, dict[str, Path]], tmp_path: Path) -> None:
    folder, bags = yard
    assert run_exscec("check", "spec.exsce", cwd=folder).returncode == 0
    (folder / "broken.exsce").write_text(YARD_SPEC.replace("r1: tiago starts", "r1: tiagoo starts"))
    broken = run_exscec("check", "broken.exsce", cwd=folder)
    assert broken.returncode == 2 and "1 error" in broken.stderr

    truncated = tmp_path / "truncated.bag"
    truncated.write_bytes(bags["clean"].read_bytes()[:5000])
    store = str(tmp_path / "store")
    ingest = run_exscec("ingest", str(truncated), "--scenario", "spec.exsce", "--store", store, cwd=folder)
    assert ingest.returncode == 2 and "0 ingested, 0 skipped, 1 failed" in ingest.stderr, ingest.stderr
    ingest = run_exscec(
        "ingest", str(bags["clean"]), "--scenario", "spec.exsce", "--store", store, cwd=folder
    )
    assert ingest.returncode == 0, ingest.stderr
    refused = run_exscec("baseline", "spec.exsce", "--store", store, cwd=folder)  # 1 run; 4 are asked
    assert refused.returncode == 2 and "its baseline needs 4" in refused.stderr, refused.stderr

    listed = json.loads(run_exscec("runs", "-f", "json", "--store", store, cwd=folder).stdout)
    uuid = listed["results"]["bindings"][0]["run"]["value"]
    known = run_exscec("query", "run_metric_values", "-p", f"run={uuid[:8]}", "--store", store, cwd=folder)
    assert known.returncode == 0 and uuid in known.stdout, known.stderr
    other = "0000" if not uuid.startswith("0000") else "ffff"
    unknown = run_exscec("query", "run_metric_values", "-p", f"run={other}", "--store", store, cwd=folder)
    assert unknown.returncode == 2 and f"the store holds no run {other}" in unknown.stderr
    assert uuid in unknown.stderr  # the closest id, the only one
    usage = run_exscec("verify", "--scenario", "spec.exsce", cwd=folder)  # click's own: no RUNS
    assert usage.returncode == 2 and "Missing argument" in usage.stderr
    shutil.rmtree(store)


def _cut_short(bag: Path, folder: Path, scenario: Scenario) -> Path:
    """``bag`` copied into ``folder`` with the run-time PROV of a mission cancelled half-way
    beside it, as ``exscec execute`` leaves an interrupted run (its first goal only)."""
    folder.mkdir()
    copy = folder / bag.name
    shutil.copyfile(bag, copy)
    start = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
    robot = scenario.robots[0]
    assert robot.start_pose is not None  # the goal does not matter here: only the run's status does
    action = Action(ActionId(robot.id, 1, 1, 1), robot.start_pose, robot.start_pose, ActionStatus.ABORTED,
                    start, start + dt.timedelta(seconds=5), outcome="cancelled")  # fmt: skip
    run = recorded_run(str(uuid.uuid4()), scenario.id, start, start + dt.timedelta(seconds=5), copy.name,
                       [action], RunStatus.CANCELLED)  # fmt: skip
    copy.with_suffix(".prov.json").write_text(recorded_prov_json(run, scenario), encoding="utf-8")
    return copy


def test_a_run_cut_short_is_never_passed(yard: tuple[Path, dict[str, Path]], tmp_path: Path) -> None:
    """A run whose .prov.json says its mission was cancelled: what it met is not judged, what it
    broke fails; the store says it is incomplete."""
    folder, bags = yard
    scenario = load_spec(folder / "spec.exsce").scenario()
    clean = next(iter(simulate(scenario, tmp_path / "runs", 1, seed=3))).bag
    cut = _cut_short(clean, tmp_path / "cut", scenario)
    overspeed = (Fault.parse("overspeed:r1"),)
    fast = next(iter(simulate(scenario, tmp_path / "fast", 1, seed=4, faults=overspeed))).bag
    fast_cut = _cut_short(fast, tmp_path / "fast_cut", scenario)  # a bag of its own: not stored yet
    shutil.copytree(folder / ".exsce" / "store", tmp_path / "store")  # the yard's runs and baseline
    store = ["--store", str(tmp_path / "store"), "--no-record"]
    junit = tmp_path / "cut.xml"
    judged = run_exscec(
        "verify", str(cut), "--scenario", "spec.exsce", *store, "--junit", str(junit), cwd=folder
    )
    assert judged.returncode == ExitCode.INCONCLUSIVE, judged.stdout + judged.stderr
    assert "pass" not in judged.stdout.replace("passed", "")
    assert "mission was cancelled" in judged.stdout, judged.stdout  # as ingest found it in the run's PROV
    rows = [line for line in judged.stdout.splitlines()[1:] if line.strip()]
    assert len(rows) == 11 and all("inconclusive: " in line for line in rows), judged.stdout
    report = ET.parse(junit).getroot()  # each clause a test skipped as inconclusive: none passed
    suite = report.find("testsuite")
    assert suite is not None and len(suite.findall("testcase")) == 11
    counts = ("tests", "failures", "errors", "skipped")
    assert (
        tuple(report.get(k) for k in counts) == tuple(suite.get(k) for k in counts) == ("11", "0", "0", "11")
    )
    messages = [case.find("skipped").get("message", "") for case in suite.findall("testcase")]  # type: ignore[union-attr]
    assert all(
        m.startswith("inconclusive: ") and "mission was cancelled" in m for m in messages
    )
    assert not report.findall(".//error") and not report.findall(".//failure")
    judged = run_exscec("verify", str(fast_cut), "--scenario", "spec.exsce", *store, "--json", cwd=folder)
    assert judged.returncode == ExitCode.FAILED, judged.stdout + judged.stderr
    outcomes = {v["oracle"]: (v["verdict"], v["shortfalls"]) for v in json.loads(judged.stdout)}
    assert outcomes["r1-max_velocity"] == ("failed", ["cut_short"])  # broken in what was recorded
    assert outcomes["r1-task_duration"] == ("inconclusive", ["cut_short"])  # not the whole run's
    assert {verdict for verdict, _ in outcomes.values()} == {"failed", "inconclusive"}
    listed = json.loads(exscec_here("runs", "-f", "json", *store[:2], cwd=folder).stdout)
    statuses = {
        row["bag"]["value"]: row.get("mission_status", {}).get("value")
        for row in listed["results"]["bindings"]
    }
    assert statuses[cut.name] == statuses[fast_cut.name] == "cancelled", statuses


def test_a_bug_exits_70_with_a_word_and_no_traceback() -> None:
    @click.command()
    @reports_errors
    def broken() -> None:
        raise ZeroDivisionError("division by zero")

    done = CliRunner().invoke(broken, [])
    assert done.exit_code == ExitCode.INTERNAL_ERROR == 70
    assert "internal error: ZeroDivisionError: division by zero (run with --debug" in done.output
    assert "Traceback" not in done.output


@pytest.mark.parametrize(
    ("command", "codes"),
    [
        ((), ("0", "1", "2", "3", "70", "130", "141")),
        (("verify",), ("0", "1", "2", "3", "70")),
        (("explore",), ("0", "1", "2", "3", "70", "130")),
        (("execute",), ("0", "1", "2", "3", "70", "130")),
        (("baseline",), ("0", "2", "70")),
        (("ingest",), ("0", "2", "70")),
        (("check",), ("0", "2", "70")),
        (("fmt",), ("0", "1", "2", "70")),
    ],
)
def test_the_help_says_the_exit_codes(command: tuple[str, ...], codes: tuple[str, ...]) -> None:
    shown = run_exscec(*command, "--help")
    assert shown.returncode == 0
    listed = shown.stdout[shown.stdout.index("Exit status") :].splitlines()[1:]
    assert tuple(line.split()[0] for line in listed if line.strip()) == codes, shown.stdout
