"""The embedded store: Oxigraph (pyoxigraph) in a folder on disk, or in memory.

Atomicity: pyoxigraph runs each ``extend`` and each ``update`` call in one
transaction (all or nothing), but ``remove_graph`` is a call of its own.  So a
write that only adds is one ``extend`` of every quad, and a write that
replaces graphs is one SPARQL Update request (``DROP SILENT GRAPH`` for each,
then one ``INSERT DATA``), which Oxigraph also runs as one transaction.  The
quads are collected and checked before the store is touched.

A folder holds a RocksDB database, which one process at a time may open for
writing; a second process that writes gets
:class:`~exsce_dsl.store.base.StoreLockedError`, naming the process that holds
it when the system says (Linux).  A second process that only reads gets a
read-only view instead (``Store.read_only``): what was committed when it
opened the store, so while an ingest runs a reader sees each run wholly or not
at all.  The folder is created on the first write: reading a store that does
not exist yet finds it empty.

A store that cannot be opened for writing — its folder on a read-only mount,
not writable, or on a full disk — is read through a read-only view as well, and
a write to it fails saying why (issue 46: such a store could not even be read).
``read_only=True`` never opens the folder for writing at all.
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Sequence
from pathlib import Path

from pyoxigraph import BlankNode, NamedNode, Quad, QueryBoolean, QuerySolutions, RdfFormat
from pyoxigraph import Store as OxStore

from exsce_dsl.errors import StoreError, StoreLockedError, StoreUnwritableError
from exsce_dsl.remedies import ANOTHER_STORE
from exsce_dsl.store.base import Bindings, GraphSet, Replace, Rows, Store, replaced_names
from exsce_dsl.store.sparql import bind, checked_quads, graph_node, write_update
from exsce_dsl.store.timing import none, one, timed_query

VIEW_ATTEMPTS = 5
"""Times a read-only view is opened before a writer's compaction racing it is an error."""

UNWRITABLE = (
    "Read-only file system",
    "Permission denied",
    "No space left on device",
    "Operation not permitted",
)
"""What RocksDB says when a store folder can be read but not written (its messages carry no errno)."""


class EmbeddedStore(Store):
    """``path=None`` keeps the data in memory (tests, benchmarks)."""

    def __init__(self, path: Path | str | None = None, *, read_only: bool = False) -> None:
        self.path = Path(path) if path is not None else None
        self.location = str(path) if path is not None else "memory:"
        self._store: OxStore | None = None
        self._empty: OxStore | None = None
        self._view: OxStore | None = None
        self._unwritable: str | None = "it was opened read-only" if read_only else None
        """Why the folder cannot be opened for writing, once known: reads use a read-only view."""
        if self.path is None:
            self._store = OxStore()
        elif self.path.exists() and not read_only:
            try:
                self._open()
            except (StoreLockedError, StoreUnwritableError):
                pass  # reads use a read-only view; writes say who holds the store, or why not

    # -- opening -------------------------------------------------------------

    def _open(self) -> OxStore:
        assert self.path is not None
        path = self.path
        if path.exists() and not path.is_dir():
            raise StoreError(f"cannot open the store at {path}: it is a file, not a store folder")
        if path.is_dir() and any(path.iterdir()) and not (path / "CURRENT").exists():
            raise StoreError(
                f"cannot open the store at {path}: the folder is not empty and holds no Oxigraph store"
            )
        if self._unwritable is not None:
            said = f"cannot write to the store at {path}: {self._unwritable} (reading it works)"
            raise StoreUnwritableError(said)
        try:
            path.mkdir(parents=True, exist_ok=True)
            self._store = OxStore(str(path))
        except OSError as exc:
            if "lock" in str(exc).lower():
                raise StoreLockedError(_locked_message(path, exc), str(path), remedy=ANOTHER_STORE) from None
            reason = next((r for r in UNWRITABLE if r in str(exc)), None)
            if reason is not None and (path / "CURRENT").exists():
                self._unwritable = reason.lower()
                return self._open()  # raises, saying why
            raise StoreError(f"cannot open the store at {path}: {exc}") from None
        self._empty = None
        return self._store

    def _reader(self) -> OxStore:
        """The store to read from: an empty one while the folder does not exist yet, a read-only
        view while another process has it open."""
        if self._store is not None:
            return self._store
        if self._view is not None:
            return self._view
        if self.path is not None and self.path.exists():  # made since, or reopened after close()
            try:
                return self._open()
            except (StoreLockedError, StoreUnwritableError):
                return self._read_only_view()
        if self._empty is None:
            self._empty = OxStore()
        return self._empty

    def _read_only_view(self) -> OxStore:
        """A read-only view of a store another process writes.  The writer may compact while the
        view opens, deleting a file the view's manifest still names (RocksDB says "Corruption: ...
        No such file"): the view is then opened again on the newer manifest, a few times."""
        assert self.path is not None
        attempt = 0
        while True:
            try:
                self._view = OxStore.read_only(str(self.path))
                return self._view
            except OSError as exc:
                raise StoreError(f"cannot read the store at {self.path}: {exc}") from None
            except RuntimeError as exc:  # pyoxigraph's error for RocksDB's Corruption status
                attempt += 1
                if "No such file" not in str(exc) or attempt == VIEW_ATTEMPTS:
                    raise StoreError(f"cannot read the store at {self.path}: {exc}") from None
                time.sleep(0.05 * attempt)

    def _writer(self) -> OxStore:
        return self._store if self._store is not None else self._open()

    def open_for_writing(self) -> None:
        """Open (or make) the store folder now rather than at the first write; when it cannot be
        opened, the first write says why, as it would have."""
        if self.path is not None:
            try:
                self._writer()
            except StoreError:
                pass

    @property
    def held_elsewhere(self) -> bool:
        """The folder is a store that another process (or another EmbeddedStore) has open."""
        if self._store is not None or self.path is None or not self.path.exists():
            return False
        try:
            self._open()
        except StoreLockedError:
            return True
        except StoreUnwritableError:
            return False  # read through a view; a write says why it cannot be
        return False

    def _exists(self) -> bool:
        return self._store is not None or (self.path is not None and self.path.exists())

    # -- writing -------------------------------------------------------------

    def write(self, graphs: GraphSet, *, replace: Replace = False) -> None:
        replaced = replaced_names(graphs, replace)
        if replaced:
            text = write_update(graphs, replace)
            if text:
                self._run_update(self._writer(), text)
            return
        quads = _with_fresh_blank_nodes(graphs)
        if not quads:
            return
        try:
            self._writer().extend(quads)
        except OSError as exc:
            raise StoreError(f"cannot write to the store at {self.location}: {exc}") from None

    def load_nquads(self, nquads: bytes, *, bulk: bool) -> None:
        """Add N-Quads, all of them or none, without Python's lock held while Oxigraph parses and
        indexes: through the bulk loader (which Oxigraph 0.5 commits in one step; fast for many
        runs, with a cost of its own for each call) or in one transaction.  The caller has
        checked what it loads (:mod:`exsce_dsl.store.batch_writing`)."""
        load = self._writer().bulk_load if bulk else self._writer().load
        try:
            load(nquads, format=RdfFormat.N_QUADS, lenient=True)
        except SyntaxError as exc:
            raise StoreError(f"invalid N-Quads for the store at {self.location}: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise StoreError(f"cannot write to the store at {self.location}: {exc}") from None

    @timed_query(none)
    def update(self, update: str, bindings: Bindings | None = None) -> None:
        self._run_update(self._writer(), bind(update, bindings))

    def _run_update(self, store: OxStore, text: str) -> None:
        try:
            store.update(text)
        except SyntaxError as exc:
            raise StoreError(f"invalid SPARQL update: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise StoreError(f"the update failed on the store at {self.location}: {exc}") from None

    def remove_graphs(self, names: Sequence[str]) -> None:
        if not names or not self._exists():
            return
        text = " ;\n".join(f"DROP SILENT GRAPH {graph_node(name)}" for name in names)
        self._run_update(self._writer(), text)

    def clear(self) -> None:
        if self._exists():
            self._run_update(self._writer(), "DROP ALL")

    # -- reading -------------------------------------------------------------

    def query(self, query: str, bindings: Bindings | None = None) -> object:
        """The raw pyoxigraph answer (solutions, boolean or triples), for the endpoint."""
        try:
            return self._reader().query(bind(query, bindings))
        except SyntaxError as exc:
            raise StoreError(f"invalid SPARQL query: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise StoreError(f"the query failed on the store at {self.location}: {exc}") from None

    def select(self, query: str, bindings: Bindings | None = None) -> Rows:
        return self._solutions(query, bindings, None)[0]

    def select_first(self, query: str, most: int, bindings: Bindings | None = None) -> tuple[Rows, bool]:
        return self._solutions(query, bindings, most)

    @timed_query(lambda found: len(found[0]))
    def _solutions(self, query: str, bindings: Bindings | None, most: int | None) -> tuple[Rows, bool]:
        """The rows of a SELECT (the first ``most``, pulled lazily) and whether there were more."""
        result = self.query(query, bindings)
        if not isinstance(result, QuerySolutions):
            raise StoreError("not a SELECT query")
        variables = tuple(v.value for v in result.variables)
        taken = result if most is None else itertools.islice(result, most + 1)
        try:
            rows = tuple(tuple(solution[v] for v in variables) for solution in taken)
        except (OSError, RuntimeError, ValueError) as exc:
            raise StoreError(f"the query failed on the store at {self.location}: {exc}") from None
        if most is not None and len(rows) > most:
            return Rows(variables, rows[:most]), True
        return Rows(variables, rows), False

    @timed_query(one)
    def ask(self, query: str, bindings: Bindings | None = None) -> bool:
        result = self.query(query, bindings)
        if not isinstance(result, QueryBoolean):
            raise StoreError("not an ASK query")
        return bool(result)

    def graph_names(self) -> set[str]:
        store = self._reader()
        return {
            g.value
            for g in store.named_graphs()
            if isinstance(g, NamedNode) and next(iter(store.quads_for_pattern(None, None, None, g)), None)
        }

    def graph(self, name: str) -> list[Quad]:
        return list(self._reader().quads_for_pattern(None, None, None, graph_node(name)))

    def existing_graphs(self, names: Sequence[str]) -> set[str]:
        store = self._reader()
        return {
            name
            for name in names
            if next(iter(store.quads_for_pattern(None, None, None, graph_node(name))), None) is not None
        }

    def graph_sizes(self) -> dict[str, int]:
        store = self._reader()
        sizes = {}
        for g in store.named_graphs():
            if isinstance(g, NamedNode):
                n = sum(1 for _ in store.quads_for_pattern(None, None, None, g))
                if n:
                    sizes[g.value] = n
        return sizes

    def quads(self) -> list[Quad]:
        return [q for q in self._reader() if isinstance(q.graph_name, NamedNode)]

    @property
    def oxigraph(self) -> OxStore:
        """The pyoxigraph store itself (created if it does not exist yet), for the endpoint."""
        return self._writer()

    def close(self) -> None:
        """Flush and release the folder, so that another process may open it."""
        if self._store is not None and self.path is not None:
            try:
                self._store.flush()
            except OSError:  # pragma: no cover - nothing more to do on the way out
                pass
        self._store = None
        self._empty = None
        self._view = None


def _with_fresh_blank_nodes(graphs: GraphSet) -> list[Quad]:
    """The quads of ``graphs``, each in its graph, with a new blank node for each label."""
    fresh: dict[str, BlankNode] = {}

    def renamed(node: BlankNode) -> BlankNode:
        found = fresh.get(node.value)
        if found is None:
            found = fresh[node.value] = BlankNode()
        return found

    quads = []
    for name, graph_quads in graphs.graphs.items():
        graph = graph_node(name)
        for q in checked_quads(graph_quads, name):
            s, o = q.subject, q.object
            if isinstance(s, BlankNode):
                s = renamed(s)
            elif not isinstance(o, BlankNode) and q.graph_name == graph:
                quads.append(q)  # as it is: most quads
                continue
            if isinstance(o, BlankNode):
                o = renamed(o)
            quads.append(Quad(s, q.predicate, o, graph))
    return quads


def _locked_message(path: Path, exc: OSError) -> str:
    holder = lock_holder(path)
    if "current process" in str(exc):
        who = "this process has it open already (close the other EmbeddedStore first)"
    elif holder is not None:
        who = f"it is open in {holder}"
    else:
        who = "another process has it open"
    return f"the store at {path} is in use: {who}.  An embedded store can be opened by one process at a time"


def lock_holder(path: Path) -> str | None:
    """``pid N (command)`` of the process holding the store's RocksDB lock, if the system tells."""
    try:
        inode = os.stat(path / "LOCK").st_ino
        with open("/proc/locks", encoding="ascii") as locks:
            lines = locks.read().splitlines()
    except OSError:
        return None
    for line in lines:
        fields = [f for f in line.split() if f != "->"]
        # "1: POSIX  ADVISORY  WRITE 12345 08:01:1234567 0 EOF"
        if len(fields) >= 6 and fields[5].rsplit(":", 1)[-1] == str(inode):
            pid = fields[4]
            try:
                command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode().strip()
            except OSError:
                command = ""
            return f"pid {pid} ({command[:120]})" if command else f"pid {pid}"
    return None
