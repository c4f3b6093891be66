"""textX registration of the exsce language, as an entry point.

``textx list-languages`` shows exsce and ``textx check file.exsce`` runs the
full semantic checks (not only the syntax).  The generators are registered by
the layers that own what they write: PROV in :mod:`exsce_dsl.rdf.registration`,
code in :mod:`exsce_dsl.codegen.registration`.
"""

from __future__ import annotations

from typing import Any

from textx import TextXSemanticError, language


def _check_whole_spec(model: Any, metamodel: Any) -> None:
    """Model processor: run exsce's own checks, which follow imports and resolve names."""
    from exsce_dsl.lang.builders.specification import analyse

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
                f" (and {len(analysis.errors) - 1} more; exsce's checker lists them all)"
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
