"""``exscec report``: a static HTML report of the store, in two steps so that the caller can show
progress: what the report shows is gathered, then its pages are drawn."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.report.contents import ReportContents


def gather_report(store_url: str | None, specs: Sequence[str | Path] = ()) -> ReportContents:
    """Everything the report shows, read from the store (opened read-only); ``specs`` give the
    occupancy grids to draw paths on and the units of the metrics they declare."""
    from exsce_dsl.api.store import open_store
    from exsce_dsl.report.contents import gather

    with open_store(store_url, read_only=True) as store:
        return gather(store, [Path(s) for s in specs])


def write_report(
    contents: ReportContents, folder: str | Path, progress: Callable[[int], None] | None = None
) -> Path:
    """Write the report into ``folder`` (its pages replaced when the new report is complete) and
    return its index page; ``progress`` is told of each run drawn."""
    from exsce_dsl.report.html import write_report as write

    return write(contents, Path(folder), progress)
