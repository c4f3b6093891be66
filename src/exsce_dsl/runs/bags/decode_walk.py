"""The walk under :func:`~exsce_dsl.runs.bags.decode.decode`: the fields of a message type in
order, over all messages at once, each message's read position an entry of an int64 array (see
:mod:`~exsce_dsl.runs.bags.decode` for how it moves and what comes out)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from exsce_dsl.errors import DecodeError
from exsce_dsl.messages.catalogue import ARRAY, BASE, NAME, NUMERIC, MessageCatalogue
from exsce_dsl.model.messages import FieldPath, Index, Select, Step, canonical_type
from exsce_dsl.monitor_kit.monitor_core import PRESENT
from exsce_dsl.runs.bags.gather import distinct_rows, gather_values, text_words
from exsce_dsl.runs.bags.raw_messages import RawMessages

UNVECTORISED = ("wstring", "float128")
"""Base types no numpy type matches: messages holding them are decoded by rosbags."""
LENGTHS = "#lengths"
"""Key suffix, while decoding, of how many values each message's row holds (its width without padding)."""


@dataclass(frozen=True)
class Request:
    """A path still to follow from the current field: its remaining steps, and the key its
    values go under.  A probe (``equals`` set) asks whether a field has a value, for a selection."""

    steps: tuple[Step, ...]
    key: str
    path: FieldPath
    equals: str | float | None = None
    row: bool = False
    """Whether the path's values are a row per message (by the definition)."""
    text: bool = False
    """Whether the path ends at a text, whose values are codes (see :func:`decode`)."""

    def rest(self) -> Request:
        return Request(self.steps[1:], self.key, self.path, self.equals, self.row, self.text)


def _probe_key(select: Select) -> str:
    return f"#select{select.text()}"


class Walker:
    """The fields of a message type walked over all messages at once: the bytes read at each
    message's position, the requested values put under their keys."""

    def __init__(self, catalogue: MessageCatalogue, messages: RawMessages, cdr: bool) -> None:
        self.catalogue = catalogue
        self.buffer = messages.buffer
        self.starts = messages.starts
        self.ends = messages.ends
        self.width = messages.width
        self.cdr = cdr
        self.texts: dict[str, int] = {}
        """Every text a text path met, in the order of their codes."""
        self.order = "<"
        if cdr:
            if len(messages) and int((messages.ends - messages.starts).min()) < 4:
                raise DecodeError("a CDR message shorter than its 4-byte encapsulation header")
            kinds = self.buffer[messages.starts[:, None] + np.arange(2)]
            if np.all(kinds == 0):
                self.order = ">"
            elif not (np.all(kinds[:, 0] == 0) and np.all(kinds[:, 1] == 1)):
                raise DecodeError("messages are not plain CDR (encapsulation kind 0 or 1)")

    # -------------------------------------------------------------- reading
    def _check(self, pos: np.ndarray, rows: np.ndarray, width: np.ndarray | int) -> None:
        if len(pos) and np.any(pos + width > self.ends[rows]):
            raise DecodeError("a message is shorter than its definition says")

    def read(self, code: str, pos: np.ndarray, rows: np.ndarray, count: int | None = None) -> np.ndarray:
        """The ``code`` values at byte positions ``pos`` of messages ``rows``: one each, or
        ``count`` consecutive ones each (a 2-D result)."""
        size = np.dtype(code).itemsize
        many = 1 if count is None else count
        if self.width is not None and len(pos) == len(self.starts) and len(pos):
            offset = pos - self.starts[rows]
            at = int(offset[0])
            if np.all(offset == at) and np.array_equal(rows, np.arange(len(rows))):
                first = int(self.starts[0])
                table = self.buffer[first : first + len(rows) * self.width].reshape(len(rows), self.width)
                values = table[:, at : at + size * many].view(code)
                return values[:, 0] if count is None else values
        return gather_values(self.buffer, np.dtype(code), pos, count)

    def _code(self, basetype: str) -> str:
        kind = NUMERIC[basetype]
        return kind if kind[1] == "1" else f"{self.order}{kind}"

    def _align(self, pos: np.ndarray, origin: np.ndarray, size: int) -> np.ndarray:
        if not self.cdr or size == 1:
            return pos
        aligned: np.ndarray = origin + (pos - origin + size - 1) // size * size
        return aligned

    def _count(self, pos: np.ndarray, origin: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A u32 length prefix at ``pos`` (aligned in CDR): (counts, position after it)."""
        pos = self._align(pos, origin, 4)
        self._check(pos, rows, 4)
        return self.read(f"{self.order}u4", pos, rows).astype(np.int64), pos + 4

    # -------------------------------------------------------------- walking
    def struct(
        self,
        msgtype: str,
        pos: np.ndarray,
        origin: np.ndarray,
        rows: np.ndarray,
        requests: list[Request],
        out: dict[str, np.ndarray],
        need_end: bool = False,
    ) -> np.ndarray:
        """Walk the fields of ``msgtype`` for messages ``rows`` at ``pos``; returns where it ends."""
        fields = self.catalogue.fields_of(msgtype)
        pending = {r.steps[0] for r in requests if r.steps}
        for name, desc in fields:
            if not need_end and not pending:
                break
            mine = [r.rest() for r in requests if r.steps and r.steps[0] == name]
            pos = self.field(desc, pos, origin, rows, mine, out)
            pending.discard(name)
        return pos

    def field(
        self,
        desc: Any,
        pos: np.ndarray,
        origin: np.ndarray,
        rows: np.ndarray,
        requests: list[Request],
        out: dict[str, np.ndarray],
    ) -> np.ndarray:
        kind, detail = int(desc[0]), desc[1]
        if kind == NAME:
            return self.struct(canonical_type(detail), pos, origin, rows, requests, out, need_end=True)
        if kind == BASE:
            return self._base(detail[0], pos, origin, rows, requests, out)
        element, length = detail
        if kind == ARRAY:
            counts = np.full(len(pos), int(length), dtype=np.int64)
        else:
            counts, pos = self._count(pos, origin, rows)
        if int(element[0]) == BASE and element[1][0] not in ("string", "wstring"):
            return self._numbers(element[1][0], counts, pos, origin, rows, requests, out)
        return self._elements(element, counts, pos, origin, rows, requests, out)

    def _base(
        self,
        basetype: str,
        pos: np.ndarray,
        origin: np.ndarray,
        rows: np.ndarray,
        requests: list[Request],
        out: dict[str, np.ndarray],
    ) -> np.ndarray:
        if basetype in UNVECTORISED:
            raise DecodeError(f"{basetype} fields are not vectorised")
        if basetype == "string":
            lengths, pos = self._count(pos, origin, rows)
            self._check(pos, rows, lengths)
            for request in requests:
                if isinstance(request.equals, str):
                    out[request.key] = self._text_equals(pos, lengths, request.equals)
                elif request.text:
                    _put(out, request, self._text_codes(pos, lengths))
            after: np.ndarray = pos + lengths
            return after
        size = np.dtype(NUMERIC[basetype]).itemsize
        pos = self._align(pos, origin, size)
        self._check(pos, rows, size)
        if requests:
            values = self.read(self._code(basetype), pos, rows).astype(np.float64)
            for request in requests:
                if request.equals is None:
                    _put(out, request, values)
                elif not isinstance(request.equals, str):
                    out[request.key] = values == request.equals
        return pos + size

    def _text_equals(self, pos: np.ndarray, lengths: np.ndarray, text: str) -> np.ndarray:
        """Whether each string (its bytes at ``pos``, ``lengths`` long) is ``text``."""
        wanted = np.frombuffer(text.encode(), dtype=np.uint8)
        same = lengths == len(wanted) + (1 if self.cdr else 0)  # CDR counts the terminating NUL
        if len(wanted) and same.any():
            rows = np.flatnonzero(same)
            found = self.buffer[pos[rows][:, None] + np.arange(len(wanted))]
            same[rows] = np.all(found == wanted, axis=1)
        return np.asarray(same, dtype=bool)

    def _text_codes(self, pos: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """Each string's code in :attr:`texts` (as float64): the strings are gathered as padded
        rows of bytes, the distinct rows found with numpy, and only those decoded."""
        sizes = np.maximum(lengths - (1 if self.cdr else 0), 0)  # CDR counts the terminating NUL
        width = int(sizes.max(initial=0))
        table = text_words(self.buffer, pos, sizes, -(-width // 8)).view(np.uint8)[:, :width]
        rows = np.concatenate([table, sizes.astype("<u4").view(np.uint8).reshape(-1, 4)], 1)
        first, inverse = distinct_rows(rows)
        codes = np.empty(len(first), dtype=np.float64)
        for i, row in enumerate(rows[first]):
            raw = bytes(row)
            size = int.from_bytes(raw[width:], "little")
            codes[i] = self.texts.setdefault(raw[:size].decode("utf-8", "replace"), len(self.texts))
        result: np.ndarray = codes[inverse]
        return result

    def _numbers(
        self,
        basetype: str,
        counts: np.ndarray,
        pos: np.ndarray,
        origin: np.ndarray,
        rows: np.ndarray,
        requests: list[Request],
        out: dict[str, np.ndarray],
    ) -> np.ndarray:
        """An array of numbers: its values, an element, or its length."""
        if basetype in UNVECTORISED:
            raise DecodeError(f"{basetype} fields are not vectorised")
        size = np.dtype(NUMERIC[basetype]).itemsize
        pos = np.where(counts > 0, self._align(pos, origin, size), pos)  # CDR aligns only elements there are
        self._check(pos, rows, counts * size)
        code = self._code(basetype)
        for request in requests:
            if request.path.length and not request.steps:
                _put(out, request, counts.astype(np.float64))
            elif request.steps and isinstance(request.steps[0], Index):
                which = _element(counts, request.steps[0])
                found = which >= 0
                values = np.full(len(pos), np.nan)
                values[found] = self.read(code, pos[found] + which[found] * size, rows[found])
                _put(out, request, values, found)
            else:
                _put(out, request, self._rows_of(code, pos, rows, counts, size), lengths=counts)
        after: np.ndarray = pos + counts * size
        return after

    def _rows_of(
        self, code: str, pos: np.ndarray, rows: np.ndarray, counts: np.ndarray, size: int
    ) -> np.ndarray:
        """One row of values per message, NaN-padded to the longest."""
        width = int(counts.max()) if len(counts) else 0
        kind = np.dtype(code)
        dtype = kind.newbyteorder("=") if kind.kind == "f" else np.dtype(np.float64)
        if len(counts) and np.all(counts == width):
            values = self.read(code, pos, rows, width)
            return values if values.dtype == dtype else values.astype(dtype)
        table = np.full((len(counts), width), np.nan, dtype=dtype)
        total = int(counts.sum())
        if total:
            owner = np.repeat(np.arange(len(counts)), counts)
            column = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
            table[owner, column] = self.read(code, pos[owner] + column * size, rows[owner])
        return table

    def _elements(
        self,
        element: Any,
        counts: np.ndarray,
        pos: np.ndarray,
        origin: np.ndarray,
        rows: np.ndarray,
        requests: list[Request],
        out: dict[str, np.ndarray],
    ) -> np.ndarray:
        """An array of messages or of strings, walked one element index at a time."""
        width = int(counts.max()) if len(counts) else 0
        for request in requests:
            if request.path.length and not request.steps:
                _put(out, request, counts.astype(np.float64))
        inner = [r for r in requests if r.steps]
        selects = list(dict.fromkeys(r.steps[0] for r in inner if isinstance(r.steps[0], Select)))
        columns: list[dict[str, np.ndarray]] = []
        pos = pos.copy()
        for k in range(width):
            active = np.flatnonzero(counts > k)
            if int(element[0]) == BASE:  # strings: only their lengths matter
                if element[1][0] != "string":
                    raise DecodeError(f"{element[1][0]} fields are not vectorised")
                lengths, after = self._count(pos[active], origin[active], rows[active])
                self._check(after, rows[active], lengths)
                pos[active] = after + lengths
                continue
            sub = [r if isinstance(r.steps[0], str) else r.rest() for r in inner]
            probes = [
                Request(s.field, _probe_key(s), FieldPath(s.field), s.value)
                for s in selects
                if isinstance(s, Select)
            ]
            local: dict[str, np.ndarray] = {}
            pos[active] = self.struct(
                canonical_type(element[1]),
                pos[active],
                origin[active],
                rows[active],
                [*sub, *probes],
                local,
                need_end=True,
            )
            columns.append({key: _spread(values, active, len(pos)) for key, values in local.items()})
        for request in inner:
            _collect(request, columns, counts, out)
        return pos


def _element(counts: np.ndarray, index: Index) -> np.ndarray:
    """Which element ``index`` picks in each message, -1 where there is none."""
    which = np.full(len(counts), index.position, dtype=np.int64)
    if index.position < 0:
        which = counts + index.position
    return np.where((which >= 0) & (which < counts), which, -1)


def _spread(values: np.ndarray, active: np.ndarray, n: int) -> np.ndarray:
    """Values of the ``active`` messages placed among ``n`` (NaN, or False, elsewhere)."""
    if values.dtype == bool:
        full = np.zeros((n, *values.shape[1:]), dtype=bool)
    else:
        dtype = values.dtype if values.dtype.kind == "f" else np.dtype(np.float64)
        full = np.full((n, *values.shape[1:]), np.nan, dtype=dtype)
    full[active] = values
    return full


def _collect(
    request: Request,
    columns: list[dict[str, np.ndarray]],
    counts: np.ndarray,
    out: dict[str, np.ndarray],
) -> None:
    """A request's values from the element columns: all of them, or the picked one."""
    first = request.steps[0]
    n = len(counts)
    stack = [c.get(request.key) for c in columns]
    if isinstance(first, str):  # a field of every element: one row per message
        values = np.full((n, len(stack)), np.nan)
        for k, column in enumerate(stack):
            if column is not None:
                values[:, k] = column
        _put(out, request, values, lengths=counts)
        return
    if isinstance(first, Index):
        which = _element(counts, first)
    else:
        assert isinstance(first, Select)
        hits = [c.get(_probe_key(first), np.zeros(n, dtype=bool)) for c in columns]
        table = np.stack(hits, axis=1) if hits else np.zeros((n, 0), dtype=bool)
        which = np.where(table.any(axis=1), table.argmax(axis=1), -1) if len(hits) else np.full(n, -1)
    given = [c for c in stack if c is not None]
    if request.row:  # an array in the picked element: one row a message, NaN-padded
        width = max((c.shape[1] for c in given), default=0)
        dtype = np.result_type(*given) if given else np.dtype(np.float64)
        picked = np.full((n, width), np.nan, dtype=dtype)
    else:
        picked = np.full(n, np.nan)
    present = which >= 0
    lengths = np.zeros(n, dtype=np.int64)
    for k, column in enumerate(stack):
        take = which == k
        if column is not None:
            if picked.ndim == 2:
                picked[take, : column.shape[1]] = column[take]
                held = np.nan_to_num(columns[k].get(request.key + LENGTHS, np.zeros(n)))
                lengths[take] = held[take].astype(np.int64)
            else:
                picked[take] = column[take]
        inner = columns[k].get(request.key + PRESENT)
        if inner is not None:
            present[take] &= inner[take]
    if picked.ndim == 2:
        picked = picked[:, : int(lengths.max(initial=0))]
        _put(out, request, picked, present, lengths)
    else:
        _put(out, request, picked, present)


def _put(
    out: dict[str, np.ndarray],
    request: Request,
    values: np.ndarray,
    present: np.ndarray | None = None,
    lengths: np.ndarray | None = None,
) -> None:
    """A request's values under its key, with their row lengths and, for a path that picks
    (an element, a selection), whether each message had a value."""
    out[request.key] = values
    if lengths is not None:
        out[request.key + LENGTHS] = lengths
    if request.path.picks:
        mask = np.ones(len(values), dtype=bool) if present is None else present
        previous = out.get(request.key + PRESENT)
        out[request.key + PRESENT] = mask if previous is None else mask & previous
