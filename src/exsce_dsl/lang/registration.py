"""textX registration: the exsce language and its generators, as entry points.

``textx list-languages`` shows exsce and ``textx check file.exsce`` runs the
full semantic checks (not only the syntax); ``textx generate file.exsce
--target provn`` (or provjson, provxml, turtle) writes PROV beside the file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from textx import TextXSemanticError, generator, language

from exsce_dsl.errors import SpecError


def _check_whole_spec(model: Any, metamodel: Any) -> None:
    """Model processor: run exsce's own checks, which follow imports and resolve names."""
    from exsce_dsl.lang.build import analyse

    path = getattr(model, "_tx_filename", None)
    if not path:
        return
    analysis = analyse(path)
    if analysis.errors:
        first = analysis.errors[0]
        loc = first.location
        raise TextXSemanticError(
            first.message
            + (
                f" (and {len(analysis.errors) - 1} more; see 'exscec check')"
                if len(analysis.errors) > 1
                else ""
            ),
            line=loc.line if loc else None,
            col=loc.column if loc else None,
            filename=loc.file if loc else path,
        )


@language("exsce", "*.exsce")
def exsce_language() -> Any:
    "exsce: executable scenarios for robot testing (robots, environment, mission, tasks)"
    from exsce_dsl.lang.parser import new_metamodel

    metamodel = new_metamodel()
    metamodel.register_model_processor(_check_whole_spec)
    return metamodel


def _generate(model: Any, output_path: str | None, overwrite: bool, fmt: str, suffix: str) -> None:
    # `lang` sits below `prov` and `rdf`: this entry point (called by textX, not
    # by the layers below) imports them when it runs, never at import time.
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.prov import compile_scenario
    from exsce_dsl.rdf import serialize

    source = Path(model._tx_filename)
    try:
        spec = load_spec(source)
    except SpecError as exc:
        raise TextXSemanticError(str(exc)) from None
    for scenario in spec.scenarios:
        if scenario not in spec.root_document.declarations:
            continue
        target = Path(output_path) if output_path else source.parent
        if target.suffix == "":
            target = target / f"{scenario.id}{suffix}"
        if target.exists() and not overwrite:
            raise TextXSemanticError(f"{target} exists; use --overwrite")
        target.write_text(serialize(compile_scenario(scenario), fmt), encoding="utf-8")


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
