"""Which run a bag is in the store, as a run of one scenario: its id, and whether it is stored.

A bag's run has the bag's own id (:func:`~exsce_dsl.model.runs.run_uuid`, from its
content) under the first scenario the store holds it as, and an id from its content and the
scenario's IRI (:func:`~exsce_dsl.model.runs.run_uuid` of both) under any other.  So a
store holds one run per bag and scenario, the ids of runs of one scenario are what they always
were, and a run keeps its id when it is analysed again.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.model.runs import run_uuid
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.store import Store, run_scenarios

__all__ = ["BagRun", "bag_runs"]


@dataclass(frozen=True)
class BagRun:
    """A bag as a run of one scenario."""

    run_id: str
    """The id its run has in the store, or will have once ingested."""
    stored: bool
    """Whether the store holds it as a run of this scenario."""
    others: tuple[str, ...] = ()
    """The other scenarios (ids) whose run has the bag's own id."""

    @property
    def own_id(self) -> bool:
        """Whether the run has the bag's own id (the store's first run of the bag)."""
        return not self.others


def bag_runs(
    store: Store, digests: Sequence[str | None], scenario_id: str, namespace: str = DEFAULT_NAMESPACE
) -> list[BagRun | None]:
    """For each bag (by its content hash; None for a bag that could not be hashed) its run as a
    run of scenario ``scenario_id``, in one query."""
    scenario_iri = Namespaces(namespace).fixed[ids.EXSCE] + scenario_id
    pairs = {d: (run_uuid(d), run_uuid(d, scenario_iri)) for d in digests if d is not None}
    held = run_scenarios(store, [run for pair in pairs.values() for run in pair], namespace)
    found: list[BagRun | None] = []
    for digest in digests:
        if digest is None:
            found.append(None)
            continue
        own, qualified = pairs[digest]
        first = held.get(own, ())
        if not first or scenario_id in first:
            found.append(BagRun(own, bool(first)))
        else:
            found.append(BagRun(qualified, qualified in held, tuple(first)))
    return found
