"""Deriving a scenario as ``exscec derive`` does: the new file's text, its acceptance criteria
from the store (``--expect``), and its scenario, generation and oracles added to the store.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from exsce_dsl.derive.expect import RELATIVE_TOLERANCE, derived_criteria
from exsce_dsl.lang import declared_poses, format_document
from exsce_dsl.model import Acceptance, Scenario
from exsce_dsl.model.document import Specification
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.oracles import compile_learnt, learn_baseline
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.store import Store, WriteReport, add_prov
from exsce_dsl.transform import Derived, Request, derive, derived_document


@dataclass(frozen=True)
class DerivedSpec:
    """A derived scenario and the file that declares it."""

    base: Scenario
    derived: Derived
    target: Path
    """Where the file is meant to be written (its import of the base's file is relative to it)."""
    text: str
    """The new ``.exsce`` file, formatted."""
    criteria: Acceptance | None
    """Its acceptance criteria, when asked for and the store gave any."""
    notes: tuple[str, ...] = ()
    """What its criteria leave out and why (a robot given no tasks has no performance clause); the
    text has them as comments before its acceptance block."""

    @property
    def scenario(self) -> Scenario:
        return self.derived.scenario


def derive_spec(
    spec: Specification,
    spec_path: str | Path,
    requests: Sequence[Request],
    *,
    new_id: str | None = None,
    scenario_id: str | None = None,
    target: str | Path | None = None,
    expect_from: Store | None = None,
    tolerance: float = RELATIVE_TOLERANCE,
    include_all: bool = False,
) -> DerivedSpec:
    """A scenario of ``spec`` (read from ``spec_path``) transformed by ``requests`` in order
    (``("remove_robot", {"robot": "tiago2", "reassign": "tiago1"})``), as the text of a new file
    for ``target`` (default: beside ``spec_path``, named after the new scenario).  With
    ``expect_from``, the file also holds the acceptance criteria the stored runs imply
    (``tolerance``: percent of the expected change), from the good runs (every run with
    ``include_all``: see :mod:`exsce_dsl.oracles.good_runs`)."""
    base = spec.scenario(scenario_id)
    derived = derive(base, requests, new_id, {t.id: t for t in spec.tasks})
    path = Path(spec_path)
    where = Path(target) if target is not None else path.with_name(f"{derived.scenario.id}.exsce")
    document = derived_document(derived, path, where)
    criteria: Acceptance | None = None
    notes: tuple[str, ...] = ()
    if expect_from is not None:
        found = derived_criteria(
            expect_from,
            base,
            derived.scenario,
            spec.acceptance_of(base.id),
            tolerance,
            include_all=include_all,
        )
        notes = found.notes
        if found.acceptance.criteria:
            criteria = found.acceptance
            document = replace(document, declarations=(*document.declarations, criteria))
    text = with_notes(format_document(document, declared_poses(spec.environments)), notes, criteria)
    return DerivedSpec(base, derived, where, text, criteria, notes)


def with_notes(text: str, notes: Sequence[str], criteria: Acceptance | None) -> str:
    """``text`` with each note as a comment before its acceptance block (at its end without one)."""
    if not notes:
        return text
    comments = "".join(f"// note: {n}\n" for n in notes)
    block = f"acceptance for {criteria.scenario} {{\n" if criteria is not None else None
    if block is None or block not in text:
        return f"{text}\n{comments}"
    return text.replace(block, comments + block, 1)


@dataclass(frozen=True)
class StoredDerivation:
    """What adding a derived scenario to the store wrote."""

    scenario: WriteReport
    generation: WriteReport
    oracles: tuple[Oracle, ...] = ()
    oracles_written: WriteReport | None = None


def add_derivation(
    store: Store, derived: DerivedSpec, generation: bool = True, *, include_all: bool = False
) -> StoredDerivation:
    """Add the base and the derived scenario, the generation (one activity per step; not with
    ``generation=False``: the store has another way to the same scenario) and, when the derived
    file has acceptance criteria, its oracles (from the base's good runs; every run with
    ``include_all``)."""
    add_prov(store, compile_scenario(derived.base))
    scenario = add_prov(store, compile_scenario(derived.scenario))
    made = compile_derivation(derived.derived.derivation)
    generated = add_prov(store, made) if generation else WriteReport(store.location)
    if derived.criteria is None:
        return StoredDerivation(scenario, generated)
    base = derived.base
    learnt = learn_baseline(
        store, derived.criteria, derived.scenario, {base.id: base}, include_all=include_all
    )
    written = add_prov(store, compile_learnt(derived.scenario.id, learnt.oracles, learnt.runs), replace=True)
    return StoredDerivation(scenario, generated, learnt.oracles, written)
