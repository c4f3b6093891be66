"""Write a PROV document as PROV-N, PROV-JSON or PROV-XML, with prov's own serialisers.

PROV-XML needs lxml (prov's ``xml`` extra).  The RDF formats (PROV-O as
Turtle, TriG, N-Quads, JSON-LD) are the ``rdf`` layer's:
:func:`exsce_dsl.rdf.serialize` writes every format, these three included.
"""

from __future__ import annotations

from typing import Any

from prov.model import ProvDocument
from prov.serializers import DoNotExist

from exsce_dsl.errors import ExportError

__all__ = ["PROV_FORMATS", "serialize_prov"]

PROV_FORMATS: tuple[str, ...] = ("provn", "json", "xml")
"""The formats :func:`serialize_prov` writes."""


def serialize_prov(document: ProvDocument, fmt: str) -> str:
    """``document`` as text in ``fmt``, one of :data:`PROV_FORMATS`."""
    if fmt == "provn":
        return str(document.get_provn())
    if fmt == "json":
        return _prov_text(document, "json", indent=2)
    if fmt == "xml":
        return _prov_text(document, "xml")
    raise ExportError(f"unknown PROV format '{fmt}'; expected one of {', '.join(PROV_FORMATS)}")


def _prov_text(document: ProvDocument, fmt: str, **options: Any) -> str:
    try:
        serialized = document.serialize(format=fmt, **options)
    except DoNotExist as missing:  # PROV-XML needs lxml, prov's "xml" extra
        raise ExportError(f"cannot write PROV-{fmt.upper()}: {missing}") from missing
    if serialized is None:  # pragma: no cover - only with a destination
        raise ExportError(f"prov wrote no PROV-{fmt.upper()}")
    return serialized
