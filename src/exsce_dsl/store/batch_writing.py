"""Many runs into a store, committed in groups through Oxigraph's bulk loader.

:func:`~exsce_dsl.store.writing.add_prov` writes a run in one transaction of its own,
near pyoxigraph's transactional insert (about 40,000 triples/s here).  An ingest of a
folder, or a campaign, writes run after run; :class:`RunWriter` takes them as they
come and commits them in groups:

* the caller's thread turns each PROV document into N-Quads and derives its segment
  index (Python's work); a loader thread hands each group to Oxigraph
  (:meth:`~exsce_dsl.store.embedded.EmbeddedStore.load_nquads`), which parses and
  indexes without Python's lock, so the two overlap: a group of :data:`BULK_FROM`
  statements or more through the bulk loader, a smaller one in one transaction;
* a group is what arrived while the group before it was loading (a group commit).
  When runs come slower than the store takes them (a real bag takes longer to
  analyse than to write), each run is committed alone as soon as it is ready; when
  they come faster, groups grow, up to :data:`MAX_GROUP_QUADS`.

**Crash semantics.**  Each group is one transaction, or one bulk load, which
Oxigraph 0.5 commits in one step too: it builds the sorted files of every index
and adds them to RocksDB together at the end (``oxigraph load``: "either the file
is fully loaded into the store or not at all").  A run is never split between
groups.  So every group, hence every run, is in the store wholly or not at all,
after a crash too, and a reader (a read-only view in another process) sees whole
groups.  A killed writer loses the group being loaded and the runs not yet handed
over: they are absent, and the same ingest again writes them (a bag's run is known
by its content).  No journal is needed, as it would be around a loader that
commits piece by piece; ``tests/store/test_batch_writing.py`` kills writers at
random points, through either path, and checks that each run is whole or absent.

What does not fit goes through :func:`add_prov` (its merge and conflict
rules), after every group before it has been committed, so that order is kept: a
document with statements outside its bundles, and one whose graphs the store (or a
group in flight) holds already.  On a store other than the embedded one every
document goes through :func:`add_prov`: a SPARQL endpoint's writes are one request
per run.
"""

from __future__ import annotations

import threading
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from types import TracebackType

from prov.model import ProvDocument
from pyoxigraph import RdfFormat, serialize

from exsce_dsl.errors import ExsceError, StoreError
from exsce_dsl.rdf.prov_o import nquad_lines, quads_of_lines
from exsce_dsl.store.base import Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.indexes import index_graphs
from exsce_dsl.store.writing import WriteReport, add_prov

__all__ = ["BULK_FROM", "MAX_GROUP_QUADS", "RunWriter", "Written"]

BULK_FROM = 15_000
"""Statements of a group (about eight runs) from which it goes through the bulk loader.  Each bulk
load costs about as much as writing a run in a transaction, before its statements; a smaller group
is one transaction (``Store.load``: all or nothing too)."""

MAX_GROUP_QUADS = 250_000
"""Statements of a group at most (about 130 runs): bounds memory, and keeps each load one batch of
Oxigraph's loader (10⁶ quads)."""


@dataclass(frozen=True)
class Written:
    """What became of one document given to :meth:`RunWriter.add`: its report, or why nothing of
    it was written."""

    key: object
    report: WriteReport | None
    error: ExsceError | None = None


@dataclass
class _Prepared:
    key: object
    nquads: bytes
    report: WriteReport
    names: frozenset[str]


class RunWriter:
    """Writes PROV documents (runs) to ``store`` in group commits; ``on_written`` hears of each
    document once it is committed (or failed), in the order given, on the caller's thread (during
    :meth:`add` and :meth:`close`).  Groups of ``bulk_from`` statements or more go through the
    bulk loader.  Use it in a ``with`` block."""

    def __init__(
        self, store: Store, on_written: Callable[[Written], None] | None = None, *, bulk_from: int = BULK_FROM
    ) -> None:
        self._store = store
        self._bulk_from = bulk_from
        self._bulk = store if isinstance(store, EmbeddedStore) else None
        self._on_written = on_written
        self._lock = threading.Condition()
        self._pending: list[_Prepared] = []
        self._pending_quads = 0
        self._loading = False
        self._in_flight: set[str] = set()  # graphs handed over and not yet committed
        self._finished: list[Written] = []
        self._closed = False
        self._loader: threading.Thread | None = None
        if self._bulk is not None:
            self._loader = threading.Thread(target=self._load_groups, name="exsce-run-writer", daemon=True)
            self._loader.start()

    # -- the caller's side -------------------------------------------------------------

    def add(self, document: ProvDocument, key: object = None) -> None:
        """Write ``document`` (its bundles as named graphs, with its segment index) in a coming
        group; a document the bulk path cannot take is written through :func:`add_prov` now."""
        self._tell()
        try:
            prepared = self._prepared(document, key) if self._bulk is not None else None
        except ExsceError as exc:  # a name RDF cannot hold, a store that cannot be read
            self.flush()
            self._finish(Written(key, None, exc))
            self._tell()
            return
        if prepared is None:
            self.flush()
            try:
                self._finish(Written(key, add_prov(self._store, document)))
            except ExsceError as exc:
                self._finish(Written(key, None, exc))
            self._tell()
            return
        with self._lock:
            while self._pending and self._pending_quads + _size(prepared) > MAX_GROUP_QUADS:
                self._lock.wait()  # the loader takes the pending group first
            self._pending.append(prepared)
            self._pending_quads += _size(prepared)
            self._in_flight |= prepared.names
            self._lock.notify_all()

    def flush(self) -> None:
        """Return when every document given so far is committed (or failed)."""
        with self._lock:
            while self._pending or self._loading:
                self._lock.wait()
        self._tell()

    def close(self) -> None:
        """Commit what was given, stop the loader, and tell what is left."""
        self.flush()
        with self._lock:
            self._closed = True
            self._lock.notify_all()
        if self._loader is not None:
            self._loader.join()
        self._tell()

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, value: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.close()

    def _prepared(self, document: ProvDocument, key: object) -> _Prepared | None:
        """The document as N-Quads with its segment index and the report of its write; None when
        it must go through add_prov (statements outside bundles; graphs the store has already)."""
        if document.get_records():  # statements outside any bundle: add_prov says why it refuses them
            return None
        lines = nquad_lines(document, blank_prefix=f"b{uuid.uuid4().hex}x")
        quads = quads_of_lines(lines)
        bundles = [b.identifier.uri for b in document.bundles if b.identifier is not None and b.records]
        index = index_graphs({"": quads})
        with self._lock:
            in_flight = set(self._in_flight)
        existing = self._store.existing_graphs([*bundles, *index]) | (in_flight & {*bundles, *index})
        if any(name in existing for name in bundles):
            return None
        new_index = [quad for name, graph in index.items() if name not in existing for quad in graph]
        text = "".join(lines).encode()
        if new_index:
            text += serialize(new_index, format=RdfFormat.N_QUADS) or b""
        added = tuple(bundles)
        report = WriteReport(
            location=self._store.location, added=added, statements=len(quads) + len(new_index)
        )
        return _Prepared(key, text, report, frozenset(added) | frozenset(index))

    def _finish(self, written: Written) -> None:
        with self._lock:
            self._finished.append(written)

    def _tell(self) -> None:
        with self._lock:
            finished, self._finished = self._finished, []
        if self._on_written is not None:
            for written in finished:
                self._on_written(written)

    # -- the loader's side -------------------------------------------------------------

    def _load_groups(self) -> None:
        assert self._bulk is not None
        while True:
            with self._lock:
                while not self._pending and not self._closed:
                    self._lock.wait()
                if not self._pending:
                    return
                group, self._pending, self._pending_quads = self._pending, [], 0
                self._loading = True
                self._lock.notify_all()
            error: StoreError | None = None
            try:
                bulk = sum(_size(run) for run in group) >= self._bulk_from
                self._bulk.load_nquads(b"".join(run.nquads for run in group), bulk=bulk)
            except StoreError as exc:
                error = exc
            except Exception as exc:  # noqa: BLE001 - the group's failure, told for each of its runs
                error = StoreError(f"cannot write to the store at {self._store.location}: {exc}")
            with self._lock:
                for run in group:
                    self._finished.append(
                        Written(run.key, None, error) if error else Written(run.key, run.report)
                    )
                    self._in_flight -= run.names
                self._loading = False
                self._lock.notify_all()


def _size(prepared: _Prepared) -> int:
    return prepared.report.statements
