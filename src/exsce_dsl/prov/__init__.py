"""IR → W3C PROV: the method's bundles for a scenario, and their serialisations.

Identifiers and namespaces are all in :mod:`exsce_dsl.prov.identifiers`.
"""

from exsce_dsl.prov.compile import compile_scenario
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces, PrefixTable
from exsce_dsl.prov.serialize import FILE_SUFFIXES, FORMATS, serialize, to_dataset

__all__ = [
    "DEFAULT_NAMESPACE",
    "FILE_SUFFIXES",
    "FORMATS",
    "Namespaces",
    "PrefixTable",
    "compile_scenario",
    "serialize",
    "to_dataset",
]
