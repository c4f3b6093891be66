"""Packaged resources: grammars, templates, the RDF vocabulary and SHACL shapes.

They ship inside the wheel (``exsce_dsl/grammar``, ``exsce_dsl/templates``);
in a source checkout grammars and templates are read from the top-level
folders of the same names.  The vocabulary and shapes live inside the package
itself (``exsce_dsl/rdf/``), in a checkout as in the wheel.  Nothing is
fetched from the network.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # importlib.resources.abc is Python 3.11+
    from importlib.resources.abc import Traversable


def resource_dir(name: str) -> Path:
    """The folder of packaged resources called ``name`` (e.g. ``grammar``)."""
    packaged = Path(str(files("exsce_dsl"))) / name
    if packaged.is_dir():
        return packaged
    checkout = Path(__file__).resolve().parents[2] / name
    if checkout.is_dir():
        return checkout
    raise FileNotFoundError(f"exsce resource folder '{name}' is missing from the installation")


def grammar_file() -> Path:
    return resource_dir("grammar") / "exsce.tx"


def package_file(*parts: str) -> Traversable:
    """A file or folder inside the package: ``package_file("rdf", "shapes", "spec.ttl")``."""
    found = files("exsce_dsl")
    for part in parts:
        found = found / part
    return found
