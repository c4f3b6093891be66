"""PROV in RDF: the PROV-O mapping, the exsce vocabulary, SHACL shapes and validation.

* :func:`to_quads` — a PROV document as pyoxigraph quads, one named graph per
  bundle (what the store writes); :func:`to_dataset` — the same as an rdflib
  ``Dataset``; :func:`serialize` — the document in every format exsce writes.
* ``vocabulary.ttl`` — every class and property exsce writes, with labels,
  comments and their place under PROV-O; ``shapes/*.ttl`` — SHACL shapes of
  spec graphs, run graphs, metrics, oracles and derivations (all shipped in
  the package, read with :mod:`importlib.resources`).
* :func:`validate` — SHACL over the union of the named graphs;
  :func:`check_scenario_shapes` — a scenario's violations as diagnostics at
  the DSL elements they concern.
"""

from exsce_dsl.rdf.prov_o import prefixes_of, to_quads
from exsce_dsl.rdf.serialize import (
    FILE_SUFFIXES,
    FORMATS,
    RDF_FORMATS,
    as_dataset,
    as_graph,
    serialize,
    to_dataset,
)
from exsce_dsl.rdf.shacl import Violation, check_scenario_shapes, check_spec_shapes, validate

__all__ = [
    "FILE_SUFFIXES",
    "FORMATS",
    "RDF_FORMATS",
    "Violation",
    "as_dataset",
    "as_graph",
    "check_scenario_shapes",
    "check_spec_shapes",
    "prefixes_of",
    "serialize",
    "to_dataset",
    "to_quads",
    "validate",
]
