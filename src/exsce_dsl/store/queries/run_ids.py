"""Run ids as people give them: a unique prefix of a run's uuid (as git takes commit prefixes),
the whole uuid, or the run's IRI.

Tables print a run's first eight characters; :func:`resolve_run` turns what was typed back into
the stored uuid with one query the store evaluates (``run_ids.rq``: ``STRSTARTS`` over the runs'
uuids, the prefix bound as a literal).  A prefix two runs share is an error listing them, an
unknown one an error naming the closest stored ids.

A prefix needs :data:`MIN_PREFIX` characters: a shorter one (a typo, a bare number) would be
ambiguous as soon as a store holds a few hundred runs (16³ = 4096 ids of three characters), and
git asks as much of commit prefixes.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.errors import AmbiguousRunError, ExsceError, UnknownRunError
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.remedies import CLOSEST_RUNS, GIVE_A_RUN_ID, NO_RUNS_AT_ALL
from exsce_dsl.store.base import Store, Term
from exsce_dsl.store.queries.library import query
from exsce_dsl.store.summary_migration import require_summaries
from exsce_dsl.store.timing import measured

__all__ = [
    "MIN_PREFIX",
    "AmbiguousRunError",
    "RunCandidate",
    "UnknownRunError",
    "is_full_uuid",
    "names_a_prefix",
    "resolve_run",
    "resolve_runs",
    "run_id_text",
]

MIN_PREFIX = 4
"""The fewest characters of a uuid a prefix may have."""

SHOWN_CANDIDATES = 10
"""At most this many runs are listed in an error."""

_UUID = re.compile(r"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}")
_ID_CHARACTERS = re.compile(r"[0-9a-f-]+")
_RUN_IRI = re.compile(r"<?(?:[^<>\s]*[/:])?run_([0-9a-fA-F-]+)(?:_bundle)?/?>?")
"""A run's IRI (``<base>runs/run_<uuid>``), its bundle's, or its prefixed name (``run:run_<uuid>``)."""


@dataclass(frozen=True)
class RunCandidate:
    """A stored run a prefix may mean."""

    uuid: str
    scenario: str
    bag: str | None

    def __str__(self) -> str:
        return f"{self.uuid}  {self.scenario}  {self.bag or '(no bag)'}"


def is_full_uuid(text: str) -> bool:
    """Whether ``text`` is a whole uuid in the stored (lower-case) form."""
    return _UUID.fullmatch(text) is not None


def names_a_prefix(text: str) -> bool:
    """Whether ``text`` must be resolved to be a stored run's id: a run's IRI, or uuid characters
    that are not a whole uuid (a prefix).  Anything else is an id as it is (or no id at all)."""
    return _RUN_IRI.fullmatch(text.strip()) is not None or (
        _ID_CHARACTERS.fullmatch(text.lower()) is not None and not is_full_uuid(text)
    )


def run_id_text(given: str) -> str:
    """The uuid, or prefix of one, that ``given`` (a uuid, a prefix or a run's IRI) stands for,
    in lower case; an :class:`ExsceError` for anything else, or a prefix that is too short."""
    text = _without_iri(given).lower()
    if not _ID_CHARACTERS.fullmatch(text):
        raise ExsceError(f"'{given}' is not a run id", remedy=GIVE_A_RUN_ID, about=str(MIN_PREFIX))
    if len(text) < MIN_PREFIX:
        raise ExsceError(
            f"run id '{given}' is too short: give at least {MIN_PREFIX} characters of the uuid "
            "(tables print 8)"
        )
    return text


def _without_iri(given: str) -> str:
    text = given.strip()
    iri = _RUN_IRI.fullmatch(text)
    return text if iri is None else iri.group(1)


def resolve_run(store: Store, given: str, namespace: str = DEFAULT_NAMESPACE) -> str:
    """The id of the one stored run ``given`` names: its uuid (or whole id), a unique prefix of
    its uuid, or its IRI.

    Raises :class:`AmbiguousRunError` (listing the runs, with their scenario and bag) when several
    runs start with the prefix, :class:`UnknownRunError` (with the closest ids) when none does.
    """
    whole = _without_iri(given)
    found = _candidates(store, whole, namespace) if whole else []
    if any(c.uuid == whole for c in found):
        return whole  # a stored id as it is (also one that is not a uuid, as the method's may be)
    prefix = run_id_text(given)
    if prefix != whole:
        found = _candidates(store, prefix, namespace)
    uuids = sorted({c.uuid for c in found})
    if len(uuids) == 1:
        return uuids[0]
    if uuids:
        raise AmbiguousRunError(
            f"run id '{given}' is ambiguous: {len(uuids)} runs start with it "
            f"(give more characters)\n{_listed(found)}",
            found,
        )
    closest = _closest(store, prefix, namespace)
    if not closest:
        raise UnknownRunError(f"the store holds no run {given}", remedy=NO_RUNS_AT_ALL)
    raise UnknownRunError(
        f"the store holds no run {given}", closest, remedy=CLOSEST_RUNS, about=_listed(closest)
    )


def resolve_runs(store: Store, given: Sequence[str], namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """Each of ``given`` resolved by :func:`resolve_run` (whole uuids looked up too), in order."""
    return [resolve_run(store, g, namespace) for g in given]


def _candidates(store: Store, prefix: str, namespace: str) -> list[RunCandidate]:
    return _rows(store, "run_ids", {"prefix": [prefix]}, namespace)


def _rows(store: Store, name: str, given: dict[str, list[str]], namespace: str) -> list[RunCandidate]:
    """The runs library query ``name`` answers (run_query resolves run ids with this module, so
    the query is run without it)."""
    library = query(name)
    require_summaries(store, namespace)
    text, bindings = library.sparql(namespace), library.bindings(given, namespace)
    rows = measured(text, lambda: store.select(text, bindings), len, name)
    return [
        RunCandidate(_text(row["run"]), _text(row["scenario_id"]), _text(row["bag"]) or None) for row in rows
    ]


def _text(term: Term | None) -> str:
    return "" if term is None else term.value


def _closest(store: Store, prefix: str, namespace: str, count: int = 3) -> list[RunCandidate]:
    """The stored runs whose uuids start most like ``prefix``: the longest shared start, then the
    fewest differing characters over the prefix's length."""
    every = _rows(store, "runs", {}, namespace)  # not a prefix of "": Virtuoso starts no string with it

    def distance(candidate: RunCandidate) -> tuple[int, int, str]:
        start = candidate.uuid[: len(prefix)]
        shared = next((i for i, (a, b) in enumerate(zip(prefix, start, strict=False)) if a != b), len(start))
        differing = sum(a != b for a, b in zip(prefix, start, strict=False)) + abs(len(prefix) - len(start))
        return (-shared, differing, candidate.uuid)

    return sorted(every, key=distance)[:count]


def _listed(candidates: Sequence[RunCandidate]) -> str:
    lines = [f"  {c}" for c in candidates[:SHOWN_CANDIDATES]]
    if len(candidates) > SHOWN_CANDIDATES:
        lines.append(f"  ... and {len(candidates) - SHOWN_CANDIDATES} more")
    return "\n".join(lines)
