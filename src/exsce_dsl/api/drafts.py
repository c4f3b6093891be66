"""Starting from a bag: a specification drafted from what it holds (``exscec init --from-bag``)."""

from __future__ import annotations

from pathlib import Path

from exsce_dsl.runs import SpecDraft, default_spec_path, draft_spec


def init_from_bag(bag: str | Path, out: str | Path | None = None, force: bool = False) -> SpecDraft:
    """``exscec init --from-bag BAG [-o OUT] [--force]``: write a specification that checks and
    ingests as written (robots, conventions, places, tasks, mission, map and safety limits found
    in ``bag``); ``out`` defaults to ``<bag stem>.exsce`` in the current folder.  An existing file
    is replaced only with ``force``."""
    path = Path(bag)
    target = Path(out) if out is not None else default_spec_path(path, Path("."))
    return draft_spec(path, target, force)
