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

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.lang.builders.specification import analyse, load_spec
    from exsce_dsl.lang.builders.standard_metrics import builtin_metrics, metric_info, standard_metrics
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
    from exsce_dsl.lang.transformation_syntax import step_heads
    from exsce_dsl.lang.yaml.exporter import export_yaml, scenario_to_yaml, task_to_yaml
    from exsce_dsl.lang.yaml.importer import import_scenario_yaml, import_task_yaml
    from exsce_dsl.lang.yaml.oracles import (
        acceptance_document,
        export_oracle_file,
        export_oracle_yaml,
        import_oracles,
        is_oracle_yaml,
    )
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
