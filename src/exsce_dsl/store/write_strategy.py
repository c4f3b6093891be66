"""How a kind of SPARQL server takes a write (:class:`WriteStrategy`), and a write done in steps
on a server that commits each operation on its own (:func:`write_in_steps`).

A write that one transactional request can carry is one request (:func:`~exsce_dsl.store.sparql.
write_update`): all or nothing.  Where that is not possible (Virtuoso commits each operation of a
request on its own, and compiles no ``INSERT DATA`` of more than ~1,400 triples), a write goes in
order so that readers never see half of it: the graphs the :class:`~exsce_dsl.store.base.GraphSet`
names in ``commit`` (a run's bundle, where every query that finds runs starts:
:mod:`exsce_dsl.store.run_commit`) are dropped first when replaced and written last, their last
statements in one operation, after every other graph is whole.  A write
that fails half-way removes the graphs it wrote (best effort) and says the server's error.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Protocol

from pyoxigraph import Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import GraphSet, Replace, replaced_names
from exsce_dsl.store.sparql import Skolemiser, checked_quads, graph_node, insert_data, triple_lines

__all__ = ["WriteStrategy", "write_in_steps"]


@dataclass(frozen=True)
class WriteStrategy:
    """What a server's writes may hold; the defaults are SPARQL 1.1's (no limit known)."""

    whole_requests: bool = True
    """Whether a request of several operations is one transaction (all or nothing): then a write
    is one request.  False: each operation is committed on its own, so a write goes in steps."""
    statements: int | None = None
    """The most triples one ``INSERT DATA`` operation may carry (None: no limit known)."""
    request_bytes: int | None = None
    """The most bytes of RDF one request carries (a graph posted in parts past it)."""
    graph_post: bool = False
    """Write each graph by the Graph Store Protocol (``POST`` of N-Triples to ``?graph-uri=``),
    where the store knows its Graph Store URL, rather than by ``INSERT DATA``."""

    @property
    def in_steps(self) -> bool:
        """Whether a write goes in steps (:func:`write_in_steps`) rather than as one request."""
        return not self.whole_requests


class Sender(Protocol):
    """What a write in steps needs of its store: updates, graph posts, a look at what exists."""

    label: str

    def update(self, update: str) -> None: ...

    def post_graph(self, name: str, n_triples: bytes) -> None:
        """Add these N-Triples to the graph ``name`` (Graph Store Protocol ``POST``)."""

    def existing_graphs(self, names: Sequence[str]) -> set[str]: ...

    def can_post_graphs(self) -> bool: ...


def write_in_steps(sender: Sender, graphs: GraphSet, replace: Replace, strategy: WriteStrategy, *,
                   skolem: str | None) -> None:  # fmt: skip
    """Write ``graphs`` in order: replaced commit graphs dropped first, then the other replaced
    graphs, then every other graph (in parts within ``strategy``'s limits), then the commit graphs,
    their last quads in one ``INSERT DATA`` (:func:`_commit_split`).  On failure the graphs written
    are dropped again (best effort) and a StoreError says the server's error."""
    skolemise = Skolemiser(skolem)
    checked = {name: checked_quads(quads, name) for name, quads in graphs.graphs.items()}
    commit = [name for name in checked if name in graphs.commit and checked[name]]
    lead, last = _commit_split(checked, commit, strategy.statements)
    replaced = replaced_names(graphs, replace)
    fresh = set(replaced) | (set(checked) - sender.existing_graphs(list(checked)))
    first = [name for name in replaced if name in graphs.commit]
    _drop(sender, first)
    _drop(sender, [name for name in replaced if name not in graphs.commit])
    written: list[str] = []
    try:
        for name, quads in [*((n, q) for n, q in checked.items() if n not in commit), *lead.items()]:
            if quads:
                written.append(name)
                _write_graph(sender, name, quads, strategy, skolemise)
        if last:
            written.extend(last)
            sender.update(insert_data(last, skolemise))
    except StoreError as exc:
        raise StoreError(_undone(sender, [n for n in written if n in fresh], exc)) from None


def _commit_split(
    checked: dict[str, list[Quad]], commit: Sequence[str], most: int | None
) -> tuple[dict[str, list[Quad]], dict[str, list[Quad]]]:
    """The commit graphs' quads written before the last operation, and those of the last one:
    every commit graph when they fit in one operation; else the largest one's final quads (a
    writer puts what makes its data visible there: a run's type, where every query that lists
    runs starts) with the others whole when they fit beside them (a run's summary), or alone."""
    if most is None or sum(len(checked[name]) for name in commit) <= most:
        return {}, {name: checked[name] for name in commit}
    final = max(commit, key=lambda name: len(checked[name]))
    others = [name for name in commit if name != final]
    beside = sum(len(checked[name]) for name in others)
    room = most - beside if beside < most else most
    quads = checked[final]
    lead = {} if beside < most else {name: checked[name] for name in others}
    last = {name: checked[name] for name in others} if beside < most else {}
    if len(quads) > room:
        lead[final] = quads[:-room]
    last[final] = quads[-room:]
    return lead, last


def _drop(sender: Sender, names: Sequence[str]) -> None:
    if names:
        sender.update(" ;\n".join(f"DROP SILENT GRAPH {graph_node(name)}" for name in names))


def _undone(sender: Sender, names: Sequence[str], error: StoreError) -> str:
    """The message of a write that failed half-way, once what it wrote is dropped again."""
    try:
        _drop(sender, names)
    except StoreError as again:
        left = f"could not remove what it wrote ({again.message})"
        return f"{error.message}; the write stopped half-way and {left}"
    return f"{error.message}; the write stopped half-way and removed what it wrote (nothing of it is stored)"


def _write_graph(sender: Sender, name: str, quads: Sequence[Quad], strategy: WriteStrategy,
                 skolemise: Skolemiser) -> None:  # fmt: skip
    if strategy.graph_post and sender.can_post_graphs():
        for part in _n_triples_parts(quads, skolemise, strategy.request_bytes):
            sender.post_graph(name, part)
        return
    step = strategy.statements or len(quads)
    for start in range(0, len(quads), step):
        sender.update(insert_data({name: quads[start : start + step]}, skolemise))


def _n_triples_parts(quads: Sequence[Quad], skolemise: Skolemiser, most: int | None) -> Iterator[bytes]:
    """The quads' triples as N-Triples, in parts of at most ``most`` bytes (a line never split)."""
    part: list[bytes] = []
    size = 0
    for line in triple_lines(quads, skolemise):
        data = line.encode("utf-8")
        if part and most is not None and size + len(data) > most:
            yield b"".join(part)
            part, size = [], 0
        part.append(data)
        size += len(data)
    if part:
        yield b"".join(part)
