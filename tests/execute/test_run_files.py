"""A run's files are named as the method names them (its tutorial §6.1.2:
``2023-06-13T15-48-07_scenario_c_run-e30df0b6.bag``, ``.prov.json``, ``.rosparams``), ``simulate``
names its bags the same way, and a run is put in place whole or not at all."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.run_files import RunFiles
from exsce_dsl.lang import load_spec
from exsce_dsl.model.runs import run_name
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

RUN = "e30df0b6-0a1b-11ee-9c4d-0242ac120002"
START = dt.datetime(2023, 6, 13, 15, 48, 7, tzinfo=dt.timezone.utc)
METHOD = "2023-06-13T15-48-07_scenario_c_run-e30df0b6"


def test_the_methods_name_for_its_published_run() -> None:
    assert run_name(START, "scenario_c", RUN) == METHOD
    files = RunFiles.of(Path("runs"), "scenario_c", RUN, START)
    assert [p.as_posix() for p in files.all()] == [
        f"runs/{METHOD}.rosparams",
        f"runs/{METHOD}.prov.json",
        f"runs/{METHOD}.bag",
    ]


def test_the_start_is_written_in_utc() -> None:
    bonn = dt.timezone(dt.timedelta(hours=2))
    assert run_name(dt.datetime(2023, 6, 13, 17, 48, 7, 900_000, tzinfo=bonn), "scenario_c", RUN) == METHOD


@pytest.mark.parametrize(
    ("scenario", "run", "start", "said"),
    [
        ("../etc/passwd", RUN, START, r"scenario id '\.\./etc/passwd' cannot name a run's files"),
        ("scenario c", RUN, START, "cannot name a run's files"),
        ("scenario_c/x", RUN, START, "cannot name a run's files"),
        ("-rf", RUN, START, "cannot name a run's files"),
        ("scenario_c", "e30df0b6", START, "run id 'e30df0b6' is not a uuid"),
        ("scenario_c", RUN, START.replace(tzinfo=None), "has no time zone"),
    ],
)
def test_what_cannot_name_a_file_is_refused(scenario: str, run: str, start: dt.datetime, said: str) -> None:
    with pytest.raises(ExsceError, match=said):
        RunFiles.of(Path("runs"), scenario, run, start)


def test_simulate_names_its_bags_the_same_way(tmp_path: Path) -> None:
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenarios[0]
    [played] = simulate(scenario, tmp_path, runs=1, seed=3)
    files = RunFiles.of(tmp_path, "scenario_c", played.run_id, played.start)
    assert played.bag == files.bag and files.prov.exists()
    assert played.bag.name == f"2026-01-04T00-00-00_scenario_c_run-{played.run_id[:8]}.bag"  # EPOCH + 3 days


def test_a_run_is_put_in_place_whole_and_its_hidden_folder_goes(tmp_path: Path) -> None:
    files = RunFiles.of(tmp_path, "scenario_c", RUN, START)
    staged = files.staged()
    assert staged.folder == tmp_path / f".{METHOD}.partial" and staged.folder.is_dir()
    for path, text in zip(staged.all(), ("params", "prov", "bag"), strict=True):
        path.write_text(text)
    files.bag.write_text("an older run under the same name")
    assert files.put_in_place() == list(files.all())
    assert [p.read_text() for p in files.all()] == ["params", "prov", "bag"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in files.all())


def test_a_discarded_run_leaves_nothing_and_a_new_try_starts_empty(tmp_path: Path) -> None:
    files = RunFiles.of(tmp_path, "scenario_c", RUN, START)
    files.staged().bag.write_text("half a bag")
    assert list(files.staged().folder.iterdir()) == []  # what an earlier try left is gone
    files.staged().bag.write_text("half a bag")
    files.discard_staged()
    assert list(tmp_path.iterdir()) == []
    assert files.put_in_place() == [] and list(tmp_path.iterdir()) == []
