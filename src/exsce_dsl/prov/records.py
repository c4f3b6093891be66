"""Building PROV documents record by record, fast: the writer that runs, oracles and derivations share.

Records are made directly from names minted in registered namespaces and from
plain values, which is what prov's ``bundle.activity``, ``bundle.used``... would
make of them after checking every argument (several times slower; a run of the
method has a few hundred records, and thousands of runs are ingested).
``checked=True`` goes through prov's API instead; the tests keep the two equal.
"""

from __future__ import annotations

import datetime
from collections import defaultdict
from collections.abc import Iterable
from typing import Any

from prov.constants import (
    PROV,
    PROV_ATTR_ACTIVITY,
    PROV_ATTR_AGENT,
    PROV_ATTR_ALTERNATE1,
    PROV_ATTR_ALTERNATE2,
    PROV_ATTR_COLLECTION,
    PROV_ATTR_ENDTIME,
    PROV_ATTR_ENTITY,
    PROV_ATTR_GENERATED_ENTITY,
    PROV_ATTR_INFORMANT,
    PROV_ATTR_INFORMED,
    PROV_ATTR_PLAN,
    PROV_ATTR_STARTER,
    PROV_ATTR_STARTTIME,
    PROV_ATTR_TRIGGER,
    PROV_ATTR_USED_ENTITY,
)
from prov.identifier import Namespace, QualifiedName
from prov.model import (
    ProvActivity,
    ProvAgent,
    ProvAlternate,
    ProvAssociation,
    ProvBundle,
    ProvCommunication,
    ProvDerivation,
    ProvDocument,
    ProvEnd,
    ProvEntity,
    ProvGeneration,
    ProvMembership,
    ProvRecord,
    ProvStart,
    ProvUsage,
)
from prov.model.records import TypedValueSet

from exsce_dsl.errors import ExsceError, SourceLocation
from exsce_dsl.prov.identifiers import Namespaces, PrefixTable, Term

__all__ = ["Attributes", "BundleWriter", "DocumentWriter"]

Attributes = dict[QualifiedName, Any]
"""A record's other attributes, keyed by qualified name."""

_PROV_ATTR_ENDER = PROV["ender"]


def _new_value_set() -> TypedValueSet:
    return TypedValueSet.__new__(TypedValueSet)


class DocumentWriter:
    """One PROV document: its namespaces (one object per IRI) and the owners of its identifiers."""

    def __init__(self, names: Namespaces, checked: bool = False) -> None:
        self.names = names
        self.checked = checked
        self.prefixes = PrefixTable(names)
        self.document = ProvDocument()
        self._shared: dict[str, Namespace] = {}
        self._document_ns: dict[str, Namespace] = {}
        self._owners: dict[QualifiedName, str] = {}

    def shared_namespace(self, prefix: str, iri: str) -> Namespace:
        namespace = self._shared.get(iri)
        if namespace is None:
            namespace = self._shared[iri] = Namespace(prefix, iri)
        return namespace

    def document_namespace(self, prefix: str) -> Namespace:
        """A fixed namespace, declared at document level."""
        registered = self._document_ns.get(prefix)
        if registered is None:
            namespace = self.shared_namespace(prefix, self.names.fixed[prefix])
            registered = self._document_ns[prefix] = self.document.add_namespace(namespace)
        return registered

    def element_namespace(self, element_id: str, iri: str, kind: str) -> Namespace:
        """An element's namespace, declared at document level (for bundle identifiers)."""
        prefix = self.prefixes.prefix(element_id, iri, kind)
        return self.document.add_namespace(self.shared_namespace(prefix, iri))

    def claim(self, identifier: QualifiedName, what: str, location: SourceLocation | None = None) -> None:
        """Record that ``what`` is written as ``identifier``; no two things may share one
        (``location``: where ``what`` is written in the specification, for the error)."""
        owner = self._owners.get(identifier)
        if owner is None:
            self._owners[identifier] = what
        elif owner == what:
            raise ExsceError(
                f"{what} twice would be written as {identifier.provn_representation()}; "
                "each needs an identifier of its own",
                location,
            )
        else:
            raise ExsceError(
                f"{what} and {owner} would both be written as {identifier.provn_representation()}; "
                "rename one of them",
                location,
            )

    def bundle(
        self, identifier: QualifiedName, what: str, location: SourceLocation | None = None
    ) -> BundleWriter:
        """The writer of a new bundle, claimed for ``what``."""
        self.claim(identifier, what, location)
        return BundleWriter(self, identifier)


class BundleWriter:
    """One bundle of the document, with each namespace it uses registered once."""

    def __init__(self, writer: DocumentWriter, identifier: QualifiedName) -> None:
        self._writer = writer
        self.bundle: ProvBundle = writer.document.bundle(identifier)
        self._checked = writer.checked
        self._namespaces: dict[str, Namespace] = {}
        self._written: set[QualifiedName] = set()

    def namespace(self, prefix: str, iri: str) -> Namespace:
        registered = self._namespaces.get(iri)
        if registered is None:
            registered = self.bundle.add_namespace(self._writer.shared_namespace(prefix, iri))
            self._namespaces[iri] = registered
        return registered

    def fixed(self, prefix: str) -> Namespace:
        return self.namespace(prefix, self._writer.names.fixed[prefix])

    def of_element(self, element_id: str, iri: str, kind: str) -> Namespace:
        """The namespace of an element's parts (``tiago1:``, ``run_30af607a:``...)."""
        return self.namespace(self._writer.prefixes.prefix(element_id, iri, kind), iri)

    def term(self, term: Term) -> QualifiedName:
        if term.prefix == "prov":
            return PROV[term.local]
        return self.fixed(term.prefix)[term.local]

    def _add(
        self,
        kind: type[ProvRecord],
        identifier: QualifiedName | None,
        attributes: Iterable[tuple[QualifiedName, Any]],
    ) -> None:
        """A record as prov's constructor makes it, one value per attribute, built in place."""
        record = kind.__new__(kind)
        record._bundle = self.bundle
        record._identifier = identifier
        values: defaultdict[QualifiedName, TypedValueSet] = defaultdict(TypedValueSet)
        for name, value in attributes:
            if value is not None:
                typed = _new_value_set()
                typed._index = {(type(value), value): value}
                values[name] = typed
        record._attributes = values
        self.bundle._add_record(record)

    # -- elements ----------------------------------------------------------

    def entity(self, identifier: QualifiedName, attributes: Attributes) -> None:
        if self._checked:
            self.bundle.entity(identifier, attributes)
        else:
            self._add(ProvEntity, identifier, attributes.items())

    def entity_once(self, identifier: QualifiedName, attributes: Attributes) -> bool:
        """Write the entity unless this writer wrote it already; True if it was written."""
        if identifier in self._written:
            return False
        self._written.add(identifier)
        self.entity(identifier, attributes)
        return True

    def activity(
        self,
        identifier: QualifiedName,
        attributes: Attributes,
        start: datetime.datetime | None = None,
        end: datetime.datetime | None = None,
    ) -> None:
        if self._checked:
            self.bundle.activity(identifier, start, end, attributes)
        else:
            self._add(
                ProvActivity,
                identifier,
                ((PROV_ATTR_STARTTIME, start), (PROV_ATTR_ENDTIME, end), *attributes.items()),
            )

    def agent(self, identifier: QualifiedName, attributes: Attributes) -> None:
        if self._checked:
            self.bundle.agent(identifier, attributes)
        else:
            self._add(ProvAgent, identifier, attributes.items())

    # -- relations ---------------------------------------------------------

    def alternate(self, one: QualifiedName, other: QualifiedName) -> None:
        """``alternateOf(one, other)``: two entities that present aspects of the same thing."""
        if self._checked:
            self.bundle.alternate(one, other)
        else:
            self._add(ProvAlternate, None, ((PROV_ATTR_ALTERNATE1, one), (PROV_ATTR_ALTERNATE2, other)))

    def member(self, collection: QualifiedName, entity: QualifiedName) -> None:
        if self._checked:
            self.bundle.membership(collection, entity)
        else:
            self._add(ProvMembership, None, ((PROV_ATTR_COLLECTION, collection), (PROV_ATTR_ENTITY, entity)))

    def derivation(
        self,
        generated: QualifiedName,
        used: QualifiedName,
        attributes: Attributes,
        activity: QualifiedName | None = None,
        identifier: QualifiedName | None = None,
    ) -> None:
        if self._checked:
            self.bundle.derivation(
                generated, used, activity, identifier=identifier, other_attributes=attributes or None
            )
        else:
            self._add(
                ProvDerivation,
                identifier,
                (
                    (PROV_ATTR_GENERATED_ENTITY, generated),
                    (PROV_ATTR_USED_ENTITY, used),
                    (PROV_ATTR_ACTIVITY, activity),
                    *attributes.items(),
                ),
            )

    def used(
        self,
        activity: QualifiedName,
        entity: QualifiedName,
        attributes: Attributes | None = None,
        identifier: QualifiedName | None = None,
    ) -> None:
        if self._checked:
            self.bundle.usage(activity, entity, identifier=identifier, other_attributes=attributes or None)
        else:
            pairs = ((PROV_ATTR_ACTIVITY, activity), (PROV_ATTR_ENTITY, entity))
            self._add(ProvUsage, identifier, (*pairs, *attributes.items()) if attributes else pairs)

    def generated(self, entity: QualifiedName, activity: QualifiedName) -> None:
        """``wasGeneratedBy(entity, activity)``."""
        if self._checked:
            self.bundle.generation(entity, activity)
        else:
            self._add(ProvGeneration, None, ((PROV_ATTR_ENTITY, entity), (PROV_ATTR_ACTIVITY, activity)))

    def informed(self, informed: QualifiedName, informant: QualifiedName) -> None:
        """``wasInformedBy(informed, informant)``."""
        if self._checked:
            self.bundle.communication(informed, informant)
        else:
            self._add(
                ProvCommunication, None, ((PROV_ATTR_INFORMED, informed), (PROV_ATTR_INFORMANT, informant))
            )

    def started(
        self,
        activity: QualifiedName,
        trigger: QualifiedName | None = None,
        starter: QualifiedName | None = None,
        attributes: Attributes | None = None,
    ) -> None:
        """``wasStartedBy(activity, trigger, starter)``."""
        if self._checked:
            self.bundle.start(activity, trigger, starter, other_attributes=attributes or None)
        else:
            pairs = (
                (PROV_ATTR_ACTIVITY, activity),
                (PROV_ATTR_TRIGGER, trigger),
                (PROV_ATTR_STARTER, starter),
            )
            self._add(ProvStart, None, (*pairs, *attributes.items()) if attributes else pairs)

    def ended(
        self,
        activity: QualifiedName,
        trigger: QualifiedName | None = None,
        ender: QualifiedName | None = None,
        attributes: Attributes | None = None,
    ) -> None:
        """``wasEndedBy(activity, trigger, ender)``."""
        if self._checked:
            self.bundle.end(activity, trigger, ender, other_attributes=attributes or None)
        else:
            pairs = ((PROV_ATTR_ACTIVITY, activity), (PROV_ATTR_TRIGGER, trigger), (_PROV_ATTR_ENDER, ender))
            self._add(ProvEnd, None, (*pairs, *attributes.items()) if attributes else pairs)

    def associated(
        self, activity: QualifiedName, agent: QualifiedName, plan: QualifiedName | None = None
    ) -> None:
        """``wasAssociatedWith(activity, agent, plan)``."""
        if self._checked:
            self.bundle.association(activity, agent, plan)
        else:
            self._add(
                ProvAssociation,
                None,
                ((PROV_ATTR_ACTIVITY, activity), (PROV_ATTR_AGENT, agent), (PROV_ATTR_PLAN, plan)),
            )
