"""textX generators of PROV, as entry points.

``textx generate file.exsce --target provn`` (or provjson, provxml, trig) writes
each scenario of the file beside it, the same document ``exscec compile``
writes: a derived scenario comes with its generation bundle.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from textx import TextXSemanticError, generator

from exsce_dsl.errors import SpecError
from exsce_dsl.model import Scenario
from exsce_dsl.model.derived import DerivedScenario


def _generate(model: Any, output_path: str | None, overwrite: bool, fmt: str, suffix: str) -> None:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.prov.spec import compile_spec_scenario
    from exsce_dsl.rdf import serialize

    source = Path(model._tx_filename)
    try:
        spec = load_spec(source)
    except SpecError as exc:
        raise TextXSemanticError(str(exc)) from None
    for declared in spec.root_document.declarations:  # the file's own scenarios, not its imports'
        scenario = declared.scenario if isinstance(declared, DerivedScenario) else declared
        if not isinstance(scenario, Scenario):
            continue
        target = Path(output_path) if output_path else source.parent
        if target.suffix == "":
            target = target / f"{scenario.id}{suffix}"
        if target.exists() and not overwrite:
            raise TextXSemanticError(f"{target} exists; use --overwrite")
        target.write_text(serialize(compile_spec_scenario(spec, scenario), fmt), encoding="utf-8")


def _prov_generator(target: str, fmt: str, suffix: str, description: str) -> Any:
    """A textX generator ``exsce -> target`` writing each scenario of the file as ``fmt``."""

    def generate(
        metamodel: Any, model: Any, output_path: str | None, overwrite: bool, debug: bool, **custom_args: Any
    ) -> None:
        _generate(model, output_path, overwrite, fmt, suffix)

    generate.__doc__ = description
    generate.__name__ = f"{target}_generator"
    return generator("exsce", target)(generate)


provn_generator = _prov_generator("provn", "provn", ".provn", "exsce scenario to PROV-N")
provjson_generator = _prov_generator("provjson", "json", ".prov.json", "exsce scenario to PROV-JSON")
provxml_generator = _prov_generator("provxml", "xml", ".prov.xml", "exsce scenario to PROV-XML")
trig_generator = _prov_generator(
    "trig", "trig", ".trig", "exsce scenario to PROV-O (TriG, one named graph per bundle)"
)
