"""The user's cache runs and unpickles nothing it did not write itself (issue 46, item 7).

Generated monitors found in the cache are executed and checked specifications unpickled, so an
entry is used only when it is the user's own regular file, in private folders, and its HMAC under
the user's key matches; a folder others may write is refused with one warning.
"""

from __future__ import annotations

import os
import pickle
import stat
import warnings
from pathlib import Path

import pytest

from exsce_dsl import monitor_code
from exsce_dsl.errors import CacheWarning
from exsce_dsl.lang import code_cache, load_spec, standard_metrics
from exsce_dsl.lang.spec_cache import load_spec_cached
from exsce_dsl.messages import typestore_cache
from exsce_dsl.user_cache import KEY_NAME, MAGIC, cache_folder, read_cached, write_cached

from tests.support.cli import run_exscec
from tests.support.map_files import write_map
from tests.support.paths import EXAMPLES
from tests.support.yard_spec import YARD_SPEC

NOBODY = 65534


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("EXSCE_CACHE", str(folder))
    monkeypatch.delenv("EXSCE_MSG_PATH", raising=False)
    return folder


class _Plant:
    """Unpickled, it writes the marker file: what a swapped entry would run."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple[object, tuple[object, ...]]:
        return (Path.write_text, (self.marker, "ran"))


def _swaps(entry: Path, payload: bytes) -> list[bytes]:
    """What another hand could put at ``entry``: the bare payload, and the payload behind the
    header with a made-up code."""
    return [payload, MAGIC + bytes(32) + payload, MAGIC + os.urandom(32) + payload]


def test_cached_monitor_swapped_is_not_run(cache: Path, tmp_path: Path) -> None:
    metrics = tuple(standard_metrics())
    monitor_code.load_monitors(metrics, "swap.exsce")  # the real entry, and the user's key
    (entry,) = cache.glob("monitors-*.py")
    marker = tmp_path / "marker"
    payload = f"open({str(marker)!r}, 'w').write('ran')\nRobotMetrics = None\n".encode()
    for swapped in _swaps(entry, payload):
        entry.write_bytes(swapped)
        monitor_code._load.cache_clear()
        module = monitor_code.load_monitors(metrics, "swap.exsce")
        assert not marker.exists()
        assert module.RobotMetrics is not None  # rendered afresh from the metrics
    # the user's own valid entry, but writable by others, or another user's, or a link to one
    for spoil in (
        lambda: entry.chmod(0o666),
        lambda: os.chown(entry, NOBODY, NOBODY),
        lambda: (entry.rename(tmp_path / "elsewhere.py"), entry.symlink_to(tmp_path / "elsewhere.py")),
    ):
        entry.unlink(missing_ok=True)
        write_cached(entry, payload)
        assert read_cached(entry) == payload  # the code matches: only the file's state is wrong
        spoil()
        assert read_cached(entry) is None
        monitor_code._load.cache_clear()
        monitor_code.load_monitors(metrics, "swap.exsce")
        assert not marker.exists()


def test_spec_pickle_swapped_is_not_unpickled(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    spec = tmp_path / "yard.exsce"
    spec.write_text(YARD_SPEC)
    write_map(tmp_path, "map", size=400)
    monkeypatch.chdir(tmp_path)
    expected = load_spec(spec)
    assert load_spec_cached(spec) == expected
    entries = sorted((cache / "specs").glob("*.pickle"))
    assert entries
    marker = tmp_path / "marker"
    payload = code_cache.FORMAT + pickle.dumps(_Plant(marker))
    for swapped in _swaps(entries[0], payload):
        for entry in entries:
            entry.write_bytes(swapped)
        assert load_spec_cached(spec) == expected
        assert code_cache.cached_standard_metrics(lambda: tuple(standard_metrics()))
        assert not marker.exists()


def test_world_writable_cache_refused_with_warning(cache: Path) -> None:
    cache.mkdir()
    cache.chmod(0o777)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert cache_folder() is None
        assert typestore_cache.standard_fielddefs("ros2_humble")["std_msgs/msg/Header"]
        assert cache_folder() is None
    assert [w.category for w in caught] == [CacheWarning]  # one warning, however often asked
    assert "may be written by other users" in str(caught[0].message)
    assert list(cache.iterdir()) == []  # nothing written into it
    # the command works without it, saying so once
    spec = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
    done = run_exscec("check", str(spec))
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("warning: the cache folder") == 1, done.stderr
    assert "Traceback" not in done.stderr
    assert list(cache.iterdir()) == []


@pytest.mark.parametrize("mode", [0o770, 0o707])
def test_group_or_world_writable_or_foreign_cache_is_not_used(cache: Path, mode: int) -> None:
    cache.mkdir(mode=0o700)
    write_cached(cache / "entry", b"kept")
    assert read_cached(cache / "entry") == b"kept"
    cache.chmod(mode)
    with pytest.warns(CacheWarning):
        assert read_cached(cache / "entry") is None
    cache.chmod(0o700)
    os.chown(cache, NOBODY, NOBODY)
    with pytest.warns(CacheWarning, match="another user"):
        assert read_cached(cache / "entry") is None


def test_cache_folders_are_private(cache: Path) -> None:
    previous = os.umask(0)  # whatever the user's umask, the folders are made 0700
    try:
        write_cached(cache / "specs" / "entry.pickle", b"data")
    finally:
        os.umask(previous)
    assert stat.S_IMODE(cache.stat().st_mode) == 0o700
    assert stat.S_IMODE((cache / "specs").stat().st_mode) == 0o700
    assert stat.S_IMODE((cache / "specs" / "entry.pickle").stat().st_mode) == 0o600
    assert read_cached(cache / "specs" / "entry.pickle") == b"data"
    # a subfolder others may write is not read from
    (cache / "specs").chmod(0o777)
    assert read_cached(cache / "specs" / "entry.pickle") is None


def test_cache_key_is_0600(cache: Path) -> None:
    previous = os.umask(0)
    try:
        write_cached(cache / "entry", b"data")
    finally:
        os.umask(previous)
    key = cache / KEY_NAME
    assert stat.S_IMODE(key.stat().st_mode) == 0o600
    assert len(key.read_bytes()) == 32
    first = key.read_bytes()
    write_cached(cache / "other", b"more")
    assert key.read_bytes() == first  # made once, kept
    # an entry is bound to its name: moved to another name, it is no entry
    (cache / "entry").replace(cache / "moved")
    assert read_cached(cache / "moved") is None
    # a key others may read is refused, and with it every entry
    key.chmod(0o644)
    with pytest.warns(CacheWarning, match="key"):
        assert read_cached(cache / "other") is None
