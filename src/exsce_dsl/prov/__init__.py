"""IR → W3C PROV: the method's bundles for a scenario, PROV-N/JSON/XML, and source locations.

Identifiers and namespaces are all in :mod:`exsce_dsl.prov.identifiers`.  The
RDF formats (PROV-O) are the ``rdf`` layer's (:mod:`exsce_dsl.rdf`).
"""

from exsce_dsl.prov.compile import compile_scenario
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces, PrefixTable
from exsce_dsl.prov.locations import source_locations
from exsce_dsl.prov.serialize import PROV_FORMATS, serialize_prov

__all__ = [
    "DEFAULT_NAMESPACE",
    "PROV_FORMATS",
    "Namespaces",
    "PrefixTable",
    "compile_scenario",
    "serialize_prov",
    "source_locations",
]
