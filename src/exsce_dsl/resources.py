"""Packaged resources: grammars, templates (and later shapes and queries).

They ship inside the wheel (``exsce_dsl/grammar``, ``exsce_dsl/templates``);
in a source checkout they are read from the top-level folders of the same
names.  Nothing is fetched from the network.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path


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
