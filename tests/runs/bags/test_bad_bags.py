"""Bags that cannot be read (issue 17): a clear error naming the bag and the reason, exit status 1,
no traceback, nothing written to the store; the same under ``python -O``, where asserts are gone.

Each bad bag is made here, at test time, from a small valid bag (:mod:`tests.support.bad_bags`), and ingested by
the real ``exscec`` into a copy of a store that holds the scenario only; the store's graphs and
quads are counted before and after.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import BagError, UnsupportedBag
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.bags.files import check_bag_file
from exsce_dsl.runs.bags.ros1 import read_topics
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

from tests.support import bad_bags

EXSCEC = str(Path(sys.executable).with_name("exscec"))
SPEC = bad_bags.SPEC

# what each kind of bad bag must be told by (written out by hand: the contract, not the code's words)
REASONS: dict[str, tuple[str, ...]] = {
    "empty .bag": ("the file is empty",),
    "empty .mcap": ("the file is empty",),
    "empty ROS 2 folder": ("an empty folder, not a ROS 2 bag",),
    "ROS 1 without messages": ("holds no messages",),
    "ROS 1 connections without messages": ("holds no messages",),
    "MCAP without messages": ("holds no messages",),
    "ROS 2 without messages": ("holds no messages",),
    "ROS 1 index records of version 2": ("not a standard ROS 1 bag", "index records are of version 2"),
    "ROS 1 unknown record before a chunk's index": ("not a standard ROS 1 bag", "unknown op 0x42"),
    "ROS 1 format 1.2": ("old format 1.2", "rosbag fix"),
    "ROS 1 unindexed": ("not indexed", "rosbag reindex"),
    "ROS 1 truncated mid-chunk": ("truncated", "rosbag reindex"),
    "ROS 1 truncated in its header": ("truncated", "runs past the end of the file"),
    "ROS 1 bag named .mcap": ("a ROS 1 bag, but named", "rename it to end in .bag"),
    "ROS 2 folder without metadata.yaml": ("without its metadata.yaml", "ros2 bag reindex"),
    "ROS 2 metadata.yaml nested deep": ("metadata.yaml does not parse",),
    "ROS 2 metadata.yaml a FIFO": ("metadata.yaml", "not a regular file"),
    "garbage named .bag": ("not a bag",),
    "MCAP truncated in the middle": ("MCAP file is truncated", "mcap recover"),
    "MCAP truncated before its footer": ("MCAP file is truncated",),
    "MCAP compressed chunk corrupted": ("corruption",),
    "MCAP chunk checksum mismatch": ("checksum mismatch",),
    "MCAP compressed whole (.mcap.zstd)": ("compressed as a whole (zstd)", "zstd -d"),
    "MCAP compressed whole, named .mcap": ("compressed as a whole (zstd)", "zstd -d"),
    "ROS 1 compressed whole (.bag.bz2)": ("compressed as a whole (bzip2)", "bzip2 -dc"),
    "ROS 1 compressed whole (.bag.zst)": ("compressed as a whole (zstd)", "zstd -d"),
    "ROS 1 compressed whole (.bag.gz)": ("compressed as a whole (gzip)", "gzip -dc"),
    "ROS 2 protobuf serialization": ("not serialized as CDR", "/tiago1/robot_pose (protobuf)"),
    "ROS 1 garbage message definition": ("definition of geometry_msgs/msg/Twist", "does not parse"),
    "MCAP garbage schema": ("definition of geometry_msgs/msg/Twist", "does not parse"),
}


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    return bad_bags.small_bags(tmp_path_factory.mktemp("small"))


@pytest.fixture(scope="module")
def scenario_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store holding scenario_c only: what every ingest below adds first anyway."""
    path = tmp_path_factory.mktemp("stores") / "scenario-only"
    with EmbeddedStore(path) as store:
        add_prov(store, compile_scenario(load_spec(SPEC).scenario()))
    return path


def _contents(store: Path) -> tuple[dict[str, int], int]:
    """Quads per named graph, and all quads."""
    with EmbeddedStore(store) as opened:
        return opened.graph_sizes(), len(opened.quads())


def _ingest(bags: list[Path], store: Path, optimised: bool) -> subprocess.CompletedProcess[str]:
    python = [sys.executable, "-O"] if optimised else [sys.executable]
    command = [*python, EXSCEC, "ingest", *map(str, bags), "--scenario", str(SPEC), "--store", str(store)]
    return subprocess.run(command, capture_output=True, text=True, timeout=120)


def test_every_kind_has_its_reason() -> None:
    assert sorted(REASONS) == sorted(bad_bags.MAKERS)


def test_the_small_bags_are_good(small: dict[str, Path], scenario_store: Path, tmp_path: Path) -> None:
    """The bags the bad ones are made from ingest: what fails below fails because of the damage."""
    for bag in small.values():
        check_bag_file(bag)
    store = tmp_path / "store"
    shutil.copytree(scenario_store, store)
    done = _ingest([small["ros1"], small["ros2"], small["mcap"]], store, optimised=False)
    assert done.returncode == 0 and "3 ingested, 0 skipped, 0 failed" in done.stderr, done.stderr


@dataclass(frozen=True)
class Refusal:
    """How one bad bag fared: the ingest that was given it, and the line that names it."""

    bag: Path
    ingest: subprocess.CompletedProcess[str]
    line: str


@pytest.fixture(scope="module", params=[False, True], ids=["python", "python -O"])
def refusals(
    request: pytest.FixtureRequest,
    small: dict[str, Path],
    scenario_store: Path,
    tmp_path_factory: pytest.TempPathFactory,
) -> tuple[dict[str, Refusal], tuple[dict[str, int], int], tuple[dict[str, int], int]]:
    """Every kind of bad bag given to one ``exscec ingest`` (each is refused on its own), under
    ``python`` and ``python -O``; with the store's contents before and after.  Bags of the same
    content (the empty ones) are skipped as one another's copies within a call, so those go again
    in a call of their own until every bag was refused."""
    folder = tmp_path_factory.mktemp("bad")
    bags = {}
    for number, (kind, make) in enumerate(bad_bags.MAKERS.items()):
        (folder / f"kind{number:02d}").mkdir()
        bags[kind] = make(small, folder / f"kind{number:02d}")
    store = folder / "store"
    shutil.copytree(scenario_store, store)
    before = _contents(store)
    found: dict[str, Refusal] = {}
    while len(found) < len(bags):
        pending = [kind for kind in bags if kind not in found]
        done = _ingest([bags[kind] for kind in pending], store, request.param)
        said = (done.stderr + done.stdout).splitlines()
        for kind in pending:
            named = [line for line in said if line.startswith(f"error: {bags[kind]}: ")]
            if named:
                (line,) = named
                found[kind] = Refusal(bags[kind], done, line)
        assert len(found) > len(bags) - len(pending), done.stderr  # each call refuses some bag
    return found, before, _contents(store)


@pytest.mark.parametrize("kind", list(bad_bags.MAKERS))
def test_a_bad_bag_is_refused_with_its_reason_and_nothing_is_written(
    kind: str, refusals: tuple[dict[str, Refusal], tuple[dict[str, int], int], tuple[dict[str, int], int]]
) -> None:
    found, before, after = refusals
    refusal = found[kind]  # the bag, by the name it was given, on a line of its own
    said = refusal.ingest.stderr + refusal.ingest.stdout
    assert refusal.ingest.returncode == 2, said
    for reason in REASONS[kind]:
        assert reason in refusal.line, refusal.line
    assert "Traceback" not in said and "internal error" not in said, said
    line = refusal.line.removeprefix(f"error: {refusal.bag}: ")
    assert "9223372036" not in line and not re.search(r"(?<![\w.])-\d", line), line  # no sentinel times
    assert re.search(r"^0 ingested, \d+ skipped, [1-9]\d* failed$", said, re.MULTILINE), said
    assert after == before


def test_a_bad_bag_does_not_stop_the_good_ones(
    small: dict[str, Path], scenario_store: Path, tmp_path: Path
) -> None:
    bad = bad_bags.ros1_index_version_2(small, tmp_path)
    store = tmp_path / "store"
    shutil.copytree(scenario_store, store)
    done = _ingest([bad, small["ros1"]], store, optimised=True)
    assert done.returncode == 2 and "1 ingested, 0 skipped, 1 failed" in done.stderr, done.stderr
    assert f"error: {bad}: not a standard ROS 1 bag" in done.stderr


def test_an_unknown_record_after_a_chunks_index_is_read_past(small: dict[str, Path], tmp_path: Path) -> None:
    """Between one chunk's index records and the next chunk nothing is read: a record there is harmless."""
    bag = bad_bags.ros1_record_between_chunks(small, tmp_path)
    scenario = load_spec(SPEC).scenario()
    check_bag_file(bag)
    assert [(v.metric, v.robot, v.action, v.value) for v in analyse_bag(bag, scenario).run.metrics] == [
        (v.metric, v.robot, v.action, v.value) for v in analyse_bag(small["ros1"], scenario).run.metrics
    ]


def test_a_nonstandard_ros1_index_is_unsupported_not_a_buffer_error(
    small: dict[str, Path], tmp_path: Path
) -> None:
    """Regression: an error inside the index reader closed the map while numpy views of it were alive
    (``BufferError: cannot close exported pointers exist``, without the bag's name)."""
    bag = bad_bags.ros1_index_version_2(small, tmp_path)
    with pytest.raises(UnsupportedBag, match="version"):
        read_topics(bag, {"/tiago1/nav_vel", "/tiago1/robot_pose"}, lambda *_: False)


def test_an_error_raised_by_the_decoder_reaches_the_caller(small: dict[str, Path]) -> None:
    """Whatever the decoder raises comes out of the reader as itself, the map closed behind it."""

    class Refused(Exception):
        pass

    def refuse(*_: object) -> bool:
        raise Refused("no")

    with pytest.raises(Refused):
        read_topics(small["ros1"], {"/tiago1/nav_vel"}, refuse)


@settings(max_examples=150, deadline=None)
@given(
    fmt=st.sampled_from(["ros1", "mcap"]),
    cut=st.floats(0.0, 1.0),
    flips=st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(1, 255)), max_size=6),
    zeros=st.one_of(st.none(), st.floats(0.0, 1.0)),
)
def test_a_cut_or_damaged_bag_passes_the_check_or_gets_a_bag_error(
    small: dict[str, Path],
    tmp_path_factory: pytest.TempPathFactory,
    fmt: str,
    cut: float,
    flips: list[tuple[float, int]],
    zeros: float | None,
) -> None:
    """Whatever is cut off or overwritten, the check says BagError or nothing: never an error of its own
    (struct.error, IndexError, UnicodeDecodeError, ...)."""
    raw = bytearray(small[fmt].read_bytes())
    raw = raw[: max(1, int(len(raw) * cut))]
    for where, mask in flips:
        raw[int(where * (len(raw) - 1))] ^= mask
    if zeros is not None:
        at = int(zeros * (len(raw) - 1))
        raw[at : at + 4096] = bytes(len(raw[at : at + 4096]))
    bag = tmp_path_factory.getbasetemp() / f"damaged{small[fmt].suffix}"
    bag.write_bytes(bytes(raw))
    try:
        check_bag_file(bag)
    except BagError as exc:
        assert exc.message.startswith(f"{bag}: ")
