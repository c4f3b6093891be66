"""A store that can be read but not written — on a read-only mount, or on a full disk — answers
queries, and a write to it is a clear error (issue 46, item 9: it could not even be read).

The tests run as root, for whom ``chmod a-w`` stops no write, so the store is made read-only the
honest way: a read-only bind mount (or a full tmpfs) in a private mount namespace
(``unshare -m``), where the real ``exscec`` runs; they are skipped where that is not allowed.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.open import open_store

G = "http://example.org/run-graph"
EXSCEC = str(Path(sys.executable).with_name("exscec"))
COUNT = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"


def _store_with_data(folder: Path) -> Path:
    path = folder / "store"
    store = EmbeddedStore(path)
    quads = [
        Quad(
            NamedNode("http://example.org/s"),
            NamedNode("http://example.org/p"),
            Literal(str(i)),
            NamedNode(G),
        )
        for i in range(3)
    ]
    store.write(GraphSet({G: quads}))
    store.close()
    return path


def _in_namespace(setup: str, *commands: list[str]) -> list[subprocess.CompletedProcess[str]]:
    """Each command run after ``setup`` in one private mount namespace; skips when the system
    allows no such namespace (not root, or no CAP_SYS_ADMIN in a container)."""
    if shutil.which("unshare") is None or os.geteuid() != 0:
        pytest.skip("needs unshare -m as root")
    probe = subprocess.run(["unshare", "-m", "true"], capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.skip(f"no private mount namespace here: {probe.stderr.strip()}")
    separator = "\n=====exsce=====\n"
    script = setup + "".join(
        f' && {{ {shlex.join(c)}; echo "rc=$?"; echo {shlex.quote(separator)}; echo {shlex.quote(separator)} >&2; }}'
        for c in commands
    )
    done = subprocess.run(["unshare", "-m", "sh", "-c", script], capture_output=True, text=True, timeout=120)
    outs, errs = done.stdout.split(separator)[:-1], done.stderr.split(separator)[:-1]
    assert len(outs) == len(commands), done.stderr
    results = []
    for command, out, err in zip(commands, outs, errs, strict=True):
        text, _, code = out.rstrip().rpartition("rc=")
        results.append(subprocess.CompletedProcess(command, int(code), text, err))
    return results


def test_read_only_store_answers_queries(tmp_path: Path) -> None:
    store = _store_with_data(tmp_path)
    mount = shlex.quote(str(tmp_path))
    sparql, graphs, runs, clear = _in_namespace(
        f"mount --bind {mount} {mount} && mount -o remount,bind,ro {mount} && touch {mount}/x 2>/dev/null; "
        f"test ! -e {mount}/x",  # the mount is really read-only
        [EXSCEC, "sparql", "--store", str(store), COUNT],
        [EXSCEC, "store", "graphs", "--store", str(store)],
        [EXSCEC, "runs", "--store", str(store)],
        [EXSCEC, "store", "clear", "--yes", "--store", str(store)],
    )
    assert sparql.returncode == 0, sparql.stderr
    assert sparql.stdout.split()[-1] == "3"
    assert graphs.returncode == 0 and G in graphs.stdout, graphs.stderr
    assert runs.returncode == 0, runs.stderr
    # a writing command: a clear error, exit 2, no traceback, the data kept
    assert clear.returncode == 2
    assert f"cannot write to the store at {store}: read-only file system" in clear.stderr
    assert "Traceback" not in clear.stderr
    with open_store(str(store), read_only=True) as after:
        assert after.ask(f"ASK {{ GRAPH <{G}> {{ ?s ?p ?o }} }}")


def test_full_disk_store_answers_queries(tmp_path: Path) -> None:
    _store_with_data(tmp_path / "original")
    full = tmp_path / "full"
    full.mkdir()
    where = shlex.quote(str(full))
    (sparql, clear) = _in_namespace(
        f"mount -t tmpfs -o size=4m tmpfs {where} && cp -r {shlex.quote(str(tmp_path / 'original' / 'store'))} "
        f"{where}/store && {{ dd if=/dev/zero of={where}/fill bs=64k 2>/dev/null; true; }}",
        [EXSCEC, "sparql", "--store", str(full / "store"), COUNT],
        [EXSCEC, "store", "clear", "--yes", "--store", str(full / "store")],
    )
    assert sparql.returncode == 0, sparql.stderr
    assert sparql.stdout.split()[-1] == "3"
    assert clear.returncode == 2 and "no space left on device" in clear.stderr


def test_a_store_opened_read_only_writes_nothing(tmp_path: Path) -> None:
    store = _store_with_data(tmp_path)
    before = {p.name: p.stat().st_mtime_ns for p in store.iterdir()}
    with open_store(str(store), read_only=True) as reading:
        assert reading.graph_names() == {G}
        with pytest.raises(StoreError, match="opened read-only"):
            reading.clear()
    assert {p.name: p.stat().st_mtime_ns for p in store.iterdir()} == before


def test_a_reader_does_not_stop_a_writer(tmp_path: Path) -> None:
    """A read command holds no lock: an ingest may open the store for writing meanwhile."""
    store = _store_with_data(tmp_path)
    with open_store(str(store), read_only=True) as reading:
        assert reading.ask(f"ASK {{ GRAPH <{G}> {{ ?s ?p ?o }} }}")
        writer = EmbeddedStore(store)
        assert not writer.held_elsewhere
        writer.clear()
        writer.close()
