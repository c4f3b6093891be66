"""The exsce language: ``.exsce`` text in, the semantic model (:mod:`exsce_dsl.model`) out, and back.

The names other layers use are here (``from exsce_dsl.lang import load_spec``); each is imported
from its module the first time it is asked for, so that importing one name (the cached
specification, the formatter) does not import textX and every part of the language.

Where the parts are, bottom to top (a part imports only from those before it):

- ``lang/`` itself: the core the others share — the textX metamodel and parse trees (``parser``),
  offsets to lines (``locations``), quantities and comments as written (``lexical``), the
  lexical split into declarations (``chunks``), reading a file and its imports (``loader``), the
  parse cache that re-parses only the declarations an edit touched (``incremental``), and the
  bundled standard library (``stdlib/``).
- ``build/``: parse trees to the semantic model, every reference resolved and every error
  reported at its place — the specification (``specification``), what its builders share (the
  state, the duplicate-name check: ``context``; positions and orientations: ``poses``), a builder
  per declaration kind (``robots``, ``environments``, ``tasks``, ``scenarios``, ``metrics`` with
  ``expressions`` and ``signals``, ``acceptance``, ``derivation``), the checks that need a whole
  scenario (``checks``), unknown names with their did-you-mean (``references``) and the
  standard metrics.
  ``spec_cache`` keeps checked specifications in the user's cache folder.
- ``format/``: the semantic model back to ``.exsce`` text, round-trip stable (``document``, and
  per kind ``acceptance``, ``derivation``, ``metrics``), writing files (``writer``), and acceptance
  criteria as Gherkin (``gherkin``).
- ``yaml/``: the method's YAML files — scenario and task files in (``importer``, over YAML values
  that keep their place: ``located``) and out (``exporter``), oracle files both ways (``oracles``).
- ``registration``: textX's language and generator entry points.
- ``editor/``: what only the language server uses — an analysis per keystroke (``analysis``),
  each file's symbols and references (``symbols``), what may be written at a point
  (``continuations``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from exsce_dsl.lang.builders.specification import Analysis, analyse, load_spec
    from exsce_dsl.lang.builders.standard_metrics import (
        builtin_metrics,
        known_metrics,
        metric_info,
        standard_metrics,
    )
    from exsce_dsl.lang.chunks import declaration_chunks, tokens
    from exsce_dsl.lang.editor.analysis import analyse_for_editor, index_text
    from exsce_dsl.lang.editor.continuations import Continuations, continuations_at
    from exsce_dsl.lang.editor.symbols import SCOPED_KINDS, FileIndex, Reference, Symbol
    from exsce_dsl.lang.format.acceptance import expectation_text
    from exsce_dsl.lang.format.document import declared_poses, format_document, format_spec_document
    from exsce_dsl.lang.format.gherkin import export_gherkin
    from exsce_dsl.lang.format.metrics import expression_text
    from exsce_dsl.lang.format.writer import write_documents
    from exsce_dsl.lang.incremental import ParseCache
    from exsce_dsl.lang.lexical import Comment, comments
    from exsce_dsl.lang.loader import ImportScope, display_path, import_target
    from exsce_dsl.lang.spec_cache import load_spec_cached
    from exsce_dsl.lang.yaml.exporter import export_yaml, scenario_to_yaml, task_to_yaml
    from exsce_dsl.lang.yaml.importer import import_scenario_yaml, import_task_yaml
    from exsce_dsl.lang.yaml.oracles import (
        acceptance_document,
        export_oracle_file,
        export_oracle_yaml,
        import_oracles,
        is_oracle_yaml,
    )

_WHERE = {
    # reading and checking a specification
    "load_spec": "builders.specification",
    "analyse": "builders.specification",
    "Analysis": "builders.specification",
    "load_spec_cached": "spec_cache",
    "standard_metrics": "builders.standard_metrics",
    "builtin_metrics": "builders.standard_metrics",
    "metric_info": "builders.standard_metrics",
    "known_metrics": "builders.standard_metrics",
    "display_path": "loader",
    "import_target": "loader",
    "ImportScope": "loader",
    "comments": "lexical",
    "Comment": "lexical",
    # writing it back
    "format_document": "format.document",
    "format_spec_document": "format.document",
    "declared_poses": "format.document",
    "expectation_text": "format.acceptance",
    "expression_text": "format.metrics",
    "write_documents": "format.writer",
    "export_gherkin": "format.gherkin",
    # the method's YAML
    "import_scenario_yaml": "yaml.importer",
    "import_task_yaml": "yaml.importer",
    "export_yaml": "yaml.exporter",
    "scenario_to_yaml": "yaml.exporter",
    "task_to_yaml": "yaml.exporter",
    "is_oracle_yaml": "yaml.oracles",
    "import_oracles": "yaml.oracles",
    "acceptance_document": "yaml.oracles",
    "export_oracle_file": "yaml.oracles",
    "export_oracle_yaml": "yaml.oracles",
    # for editors
    "analyse_for_editor": "editor.analysis",
    "index_text": "editor.analysis",
    "FileIndex": "editor.symbols",
    "Symbol": "editor.symbols",
    "Reference": "editor.symbols",
    "SCOPED_KINDS": "editor.symbols",
    "Continuations": "editor.continuations",
    "continuations_at": "editor.continuations",
    "ParseCache": "incremental",
    "declaration_chunks": "chunks",
    "tokens": "chunks",
}
"""Each entry point, and the module (below ``exsce_dsl.lang``) that defines it."""

__all__ = [
    "SCOPED_KINDS",
    "Analysis",
    "Comment",
    "Continuations",
    "FileIndex",
    "ImportScope",
    "ParseCache",
    "Reference",
    "Symbol",
    "acceptance_document",
    "analyse",
    "analyse_for_editor",
    "builtin_metrics",
    "comments",
    "continuations_at",
    "declaration_chunks",
    "declared_poses",
    "display_path",
    "expectation_text",
    "export_gherkin",
    "export_oracle_file",
    "export_oracle_yaml",
    "export_yaml",
    "expression_text",
    "format_document",
    "format_spec_document",
    "import_oracles",
    "import_scenario_yaml",
    "import_target",
    "import_task_yaml",
    "index_text",
    "is_oracle_yaml",
    "known_metrics",
    "load_spec",
    "load_spec_cached",
    "metric_info",
    "scenario_to_yaml",
    "standard_metrics",
    "task_to_yaml",
    "tokens",
    "write_documents",
]


def __getattr__(name: str) -> Any:
    """An entry point, imported from its module when first asked for (see the module's description)."""
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
