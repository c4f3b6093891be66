"""The checked specifications kept in the user's cache folder: found again only while nothing
they were made from has changed (the files imported, the maps, the user's message definitions,
exsce's own code), never for a specification with errors, and not at all when turned off."""

from __future__ import annotations

import os
import pickle
from collections.abc import Mapping
from pathlib import Path

import pytest

from exsce_dsl.errors import SpecError
from exsce_dsl.lang import code_cache, load_spec, spec_cache
from exsce_dsl.lang.builders import specification as build
from exsce_dsl.lang.builders.standard_metrics import _parse_standard_metrics
from exsce_dsl.lang.code_cache import code_fingerprint
from exsce_dsl.lang.spec_cache import load_spec_cached
from exsce_dsl.model import Specification
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.user_cache import read_cached

from tests.support.map_files import write_map

ENVIRONMENT = """\
environment yard {
  map yard_map file "yard.yaml"

  area pad {
    pose pad-p1 at (1.0, 1.0)
    pose pad-p2 at (2.0, 1.0)
  }
}
"""

SCENARIO = """\
import "environment.exsce"

robot type quad {
  base quadrotor
  torso no
}

task hop {
  visit pad-p2
}

scenario yard_run in yard {
  robots {
    drone1: quad starts at pad-p1
  }
  mission hop_once sequential {
    drone1 does hop
  }
}
"""

WHEELS = (
    'metric wheel_speed for each robot {\n  reads w: robot_msgs/Wheels on "/{ns}/wheels"\n'
    "  value max(w.wheels[3].speed)\n}\n"
)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("EXSCE_CACHE", str(folder))
    monkeypatch.delenv("EXSCE_MSG_PATH", raising=False)
    return folder


@pytest.fixture
def yard(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scenario importing an environment with a map, in the working folder."""
    folder = tmp_path / "yard"
    folder.mkdir()
    write_map(folder, "yard")  # 5 m by 5 m, all free
    (folder / "environment.exsce").write_text(ENVIRONMENT)
    (folder / "scenario.exsce").write_text(SCENARIO)
    monkeypatch.chdir(folder)
    return folder / "scenario.exsce"


@pytest.fixture
def loads(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The paths the cache had to load (and check) for want of a current entry."""
    loaded: list[str] = []
    real = build.load_spec_reading

    def counted(
        path: str | Path, overlay: Mapping[str, str] | None = None
    ) -> tuple[Specification, tuple[str, ...]]:
        loaded.append(str(path))
        return real(path, overlay)

    monkeypatch.setattr(build, "load_spec_reading", counted)
    return loaded


def test_a_spec_loaded_twice_is_checked_once_and_is_the_same(
    cache: Path, yard: Path, loads: list[str]
) -> None:
    first = load_spec_cached(yard)
    second = load_spec_cached(yard)
    assert loads == [str(yard)]
    assert first == second == load_spec(yard)
    assert repr(second.scenario().environment.map) == repr(load_spec(yard).scenario().environment.map)
    # locations are not compared by ==: they must come back too
    assert second.scenario().location == load_spec(yard).scenario().location
    assert [p.name for p in (cache / "specs").iterdir() if not p.name.startswith("stdlib")] != []


def test_editing_an_imported_file_misses(cache: Path, yard: Path, loads: list[str]) -> None:
    load_spec_cached(yard)
    environment = yard.with_name("environment.exsce")
    environment.write_text(ENVIRONMENT.replace("(2.0, 1.0)", "(2.5, 1.0)"))
    moved = load_spec_cached(yard)
    assert len(loads) == 2
    (pose,) = [p for p in moved.scenario().environment.poses() if p.id == "pad-p2"]
    assert pose.position.x == 2.5


def test_an_imported_file_that_went_away_misses(cache: Path, yard: Path, loads: list[str]) -> None:
    load_spec_cached(yard)
    yard.with_name("environment.exsce").unlink()
    with pytest.raises(SpecError, match="not found"):
        load_spec_cached(yard)


def test_editing_the_map_image_misses(cache: Path, yard: Path, loads: list[str]) -> None:
    load_spec_cached(yard)
    # the same size, so only the content tells: pad-p2 at (2.0, 1.0) = cell (40, 20) now occupied
    write_map(yard.parent, "yard", occupied=(35, 15, 45, 25))
    with pytest.raises(SpecError, match="pad-p2"):
        load_spec_cached(yard)
    assert len(loads) == 2


def test_editing_the_map_yaml_misses(cache: Path, yard: Path, loads: list[str]) -> None:
    load_spec_cached(yard)
    map_yaml = yard.with_name("yard.yaml")
    map_yaml.write_text(map_yaml.read_text().replace("origin: [0.0, 0.0, 0.0]", "origin: [1.5, 0.0, 0.0]"))
    with pytest.raises(SpecError, match="pad-p1"):  # now outside the map
        load_spec_cached(yard)


def _wheels(folder: Path, length: int) -> None:
    (folder / "robot_msgs" / "msg").mkdir(parents=True, exist_ok=True)
    (folder / "robot_msgs" / "msg" / "Wheels.msg").write_text(f"Wheel[{length}] wheels\n")
    (folder / "robot_msgs" / "msg" / "Wheel.msg").write_text("float64 speed\n")


def test_editing_a_msg_definition_misses(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, loads: list[str]
) -> None:
    msgs = tmp_path / "msgs"
    _wheels(msgs, 4)
    monkeypatch.setenv("EXSCE_MSG_PATH", str(msgs))
    spec = tmp_path / "m.exsce"
    spec.write_text(WHEELS)
    load_spec_cached(spec)
    load_spec_cached(spec)
    assert len(loads) == 1
    _wheels(msgs, 2)  # the same size: only the content tells
    with pytest.raises(SpecError, match=r"w.wheels has 2 elements: \[3\] is not one of them"):
        load_spec_cached(spec)


def test_a_msg_definition_added_or_another_msg_path_misses(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, loads: list[str]
) -> None:
    spec = tmp_path / "m.exsce"
    spec.write_text(WHEELS)
    msgs = tmp_path / "msgs"
    msgs.mkdir()
    monkeypatch.setenv("EXSCE_MSG_PATH", str(msgs))
    assert load_spec_cached(spec).metrics  # an unknown type: a warning, no error
    _wheels(msgs, 2)  # now defined, and [3] is out of range
    with pytest.raises(SpecError, match="w.wheels has 2 elements"):
        load_spec_cached(spec)
    other = tmp_path / "other"
    _wheels(other, 4)
    monkeypatch.setenv("EXSCE_MSG_PATH", str(other))
    assert load_spec_cached(spec).metrics
    monkeypatch.delenv("EXSCE_MSG_PATH")
    assert load_spec_cached(spec).metrics
    assert len(loads) == 4


def test_another_working_folder_is_another_entry(
    cache: Path, yard: Path, loads: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    here = load_spec_cached(yard).scenario().location
    monkeypatch.chdir(yard.parent.parent)
    there = load_spec_cached(yard).scenario().location
    assert len(loads) == 2
    assert here is not None and there is not None and here.file != there.file


def test_a_spec_with_errors_is_never_kept(cache: Path, yard: Path, loads: list[str]) -> None:
    yard.write_text(SCENARIO.replace("visit pad-p2", "visit pad-p9"))
    for _ in range(2):
        with pytest.raises(SpecError, match="pad-p9"):
            load_spec_cached(yard)
    assert len(loads) == 2
    yard.write_text(SCENARIO)
    assert load_spec_cached(yard).scenario().id == "yard_run"


def test_a_damaged_entry_is_made_again(cache: Path, yard: Path, loads: list[str]) -> None:
    load_spec_cached(yard)
    for entry in (cache / "specs").iterdir():
        entry.write_bytes(entry.read_bytes()[:100])
    again = load_spec_cached(yard)
    assert len(loads) == 2
    assert again == load_spec(yard)


def test_an_empty_exsce_cache_turns_it_off(
    tmp_path: Path, yard: Path, loads: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("EXSCE_CACHE", "")
    load_spec_cached(yard)
    load_spec_cached(yard)
    assert len(loads) == 2
    assert not (tmp_path / "cache").exists()


def test_the_code_fingerprint_follows_exsce_s_own_files(monkeypatch: pytest.MonkeyPatch) -> None:
    """A changed grammar (or any file of the package) is another fingerprint, hence other entries."""
    grammar = Path(spec_cache.__file__).resolve().parents[3] / "grammar" / "common.tx"
    if not grammar.is_file():  # an installed wheel: the grammar is inside the package
        grammar = Path(spec_cache.__file__).resolve().parents[1] / "grammar" / "common.tx"
    before = grammar.stat()
    code_fingerprint.cache_clear()
    first = code_fingerprint()
    try:
        os.utime(grammar, ns=(before.st_atime_ns, before.st_mtime_ns + 1_000_000_000))
        code_fingerprint.cache_clear()
        assert code_fingerprint() != first
    finally:
        os.utime(grammar, ns=(before.st_atime_ns, before.st_mtime_ns))
        code_fingerprint.cache_clear()
    assert code_fingerprint() == first


def test_the_standard_library_is_parsed_once_per_installation(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    made: list[int] = []

    def parse() -> tuple[MetricDefinition, ...]:
        made.append(1)
        return _parse_standard_metrics()

    first = code_cache.cached_standard_metrics(parse)
    second = code_cache.cached_standard_metrics(parse)
    assert made == [1]
    assert first == second and [m.name for m in first] == [m.name for m in _parse_standard_metrics()]
    (entry,) = (cache / "specs").glob("stdlib-metrics-*.pickle")
    content = read_cached(entry)
    assert content is not None and pickle.loads(content[len(code_cache.FORMAT) :]) == first
