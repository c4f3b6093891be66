"""The provenance store: named graphs per PROV bundle, SPARQL, typed queries."""
