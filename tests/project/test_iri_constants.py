"""Every W3C or exsce IRI is spelt once, in :mod:`exsce_dsl.prov.identifiers` (its ``terms``):
any other module imports the constant (a local alias is fine), never writes the IRI again.

The test reads every string literal (docstrings and f-strings included) of every module under
``src/exsce_dsl`` outside ``prov/identifiers/``; what it looks for is a piece of a namespace IRI
that only a second spelling would contain.
"""

from __future__ import annotations

import io
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "exsce_dsl"
HOME = PACKAGE / "prov" / "identifiers"

IRI_PIECES = (
    "www.w3.org/",  # RDF, RDFS, XSD, PROV, SHACL, SPARQL results, LDP
    "rdf-syntax-ns#",
    "rdf-schema#",
    "XMLSchema#",
    "sesame-project.org",  # exsce's base namespace, its shapes and Skolem IRIs
    "robot-schema.org",
    "wiki.ros.org",
)

ALLOWED: dict[str, str] = {
    # "path/under/exsce_dsl.py": "why the literal there is not an IRI constant",
}
"""Modules that may hold such a piece, each with its reason (none today)."""


def _literals(path: Path) -> list[tuple[int, str]]:
    tokens = tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline)
    kinds = {tokenize.STRING, getattr(tokenize, "FSTRING_MIDDLE", tokenize.STRING)}
    return [(t.start[0], t.string) for t in tokens if t.type in kinds]


def _second_spellings() -> list[str]:
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.is_relative_to(HOME) or path.relative_to(PACKAGE).as_posix() in ALLOWED:
            continue
        if not any(piece in path.read_text(encoding="utf-8") for piece in IRI_PIECES):
            continue  # nothing to look at closer
        for line, text in _literals(path):
            for piece in IRI_PIECES:
                if piece in text:
                    found.append(f"{path.relative_to(ROOT)}:{line}: {piece!r} in {text[:80]!r}")
    return found


def test_iri_constants_live_only_in_prov_identifiers() -> None:
    found = _second_spellings()
    assert not found, "IRI spelt outside exsce_dsl.prov.identifiers:\n" + "\n".join(found)


def test_the_check_sees_a_second_spelling(tmp_path: Path) -> None:
    """The scan finds an IRI in a plain string, an f-string and a docstring (so that an empty
    result above means something)."""
    sample = tmp_path / "sample.py"
    sample.write_text(
        '"""See http://www.w3.org/ns/prov#."""\n'
        'XSD = "http://www.w3.org/2001/XMLSchema#"\n'
        'TYPE = f"{XSD}type http://www.w3.org/1999/02/22-rdf-syntax-ns#type"\n',
        encoding="utf-8",
    )
    texts = [text for _, text in _literals(sample)]
    assert sum(any(piece in text for piece in IRI_PIECES) for text in texts) == 3


def test_allowed_modules_exist() -> None:
    for name in ALLOWED:
        assert (PACKAGE / name).is_file(), name
