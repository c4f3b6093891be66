"""``exscec ingest``: bags into the store, as fast as the command line needs it.

What the command does before it reads the first bag is kept small (``tests/cli/test_import_cost.py``):
the specification comes from the user's cache folder, and the store is opened on a thread of its
own while what reads the bags is imported.  :func:`~exsce_dsl.api.ingest` is the same for a store
the caller holds open.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.model import Scenario
    from exsce_dsl.model.document import Specification
    from exsce_dsl.runs import IngestResult


def load_cached(path: str | Path) -> Specification:
    """A checked specification, from the user's cache folder when the files have not changed
    since (else loaded and cached)."""
    from exsce_dsl.lang import load_spec_cached

    return load_spec_cached(path)


@dataclass(frozen=True)
class IngestTally:
    """What became of the bags of one ingest."""

    ingested: int
    replaced: int
    skipped: int
    failed: int


def ingest_files(
    store_url: str | None, scenario: Scenario, bags: Sequence[str | Path], *, jobs: int = 1,
    on_result: Callable[[IngestResult], None] | None = None, dask_address: str | None = None,
    replace: bool = False, strict: bool = False,
) -> tuple[list[IngestResult], IngestTally]:  # fmt: skip
    """``exscec ingest``: each bag's metrics and run PROV, as runs of ``scenario``, into the store
    ``store_url`` names (see :func:`~exsce_dsl.api.ingest`); ``on_result`` gets each bag's result
    as it is done."""
    from exsce_dsl.store import StoreOpening

    opening = StoreOpening(store_url)  # the store opens while what reads the bags is imported
    from exsce_dsl.runs import IngestStatus, ingest_bags

    with opening.store() as store:
        results = ingest_bags(
            [Path(b) for b in bags],
            scenario,
            store,
            jobs,
            on_result,
            dask_address=dask_address or None,
            replace=replace,
            strict=strict,
        )
    tally = IngestTally(
        ingested=sum(r.status is IngestStatus.INGESTED for r in results),
        replaced=sum(r.status is IngestStatus.REPLACED for r in results),
        skipped=sum(r.status is IngestStatus.SKIPPED for r in results),
        failed=sum(r.failed for r in results),
    )
    return results, tally
