"""Build the semantic model from parse trees, resolving every reference.

References are resolved here rather than by textX so that *every* unknown
name is reported (with a did-you-mean), not only the first one.  Each kind of
declaration has its builder (:mod:`.environments`, :mod:`.robots`, :mod:`.tasks`,
:mod:`.scenarios`, :mod:`.metrics`, :mod:`.derivation`, :mod:`.acceptance`), sharing
one :class:`~exsce_dsl.lang.builders.context.BuildContext`; checks that need the whole
scenario live in :mod:`exsce_dsl.lang.builders.checks`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from exsce_dsl.errors import Diagnostic, Severity, SpecError, diagnostic_order
from exsce_dsl.lang.builders.acceptance import build_all_acceptance
from exsce_dsl.lang.builders.checks import check_environment_map, check_scenario
from exsce_dsl.lang.builders.context import BuildContext
from exsce_dsl.lang.builders.derivation import build_derivations
from exsce_dsl.lang.builders.environments import build_environment
from exsce_dsl.lang.builders.metrics import build_metric
from exsce_dsl.lang.builders.references import UnknownNames
from exsce_dsl.lang.builders.robots import build_robot_type
from exsce_dsl.lang.builders.scenarios import build_scenario
from exsce_dsl.lang.builders.standard_metrics import reserved_metric_names
from exsce_dsl.lang.builders.tasks import build_task, task_pose_candidates
from exsce_dsl.lang.loader import ANYWHERE, ImportScope, Parse, read_sources
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Document, Import, Specification


@dataclass
class Analysis:
    """What :func:`analyse` found: the model if it is valid, and every diagnostic."""

    spec: Specification | None
    diagnostics: list[Diagnostic] = field(default_factory=list)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.is_error]


def load_spec(path: str | Path, overlay: Mapping[str, str] | None = None) -> Specification:
    """Parse, resolve and check a specification; raise :class:`SpecError` listing every error
    (and the notes about them)."""
    return load_spec_reading(path, overlay)[0]


def load_spec_reading(
    path: str | Path, overlay: Mapping[str, str] | None = None
) -> tuple[Specification, tuple[str, ...]]:
    """:func:`load_spec`, also naming the ``.exsce`` files it read (the root first), for
    :mod:`exsce_dsl.lang.spec_cache`."""
    sources = read_sources(path, overlay)
    analysis = analyse_files(sources.files, sources.diagnostics, sources.broken)
    if analysis.errors or analysis.spec is None:
        told = [d for d in analysis.diagnostics if d.is_error or d.severity is Severity.NOTE]
        raise SpecError(told or analysis.diagnostics)
    return analysis.spec, tuple(f.path for f in sources.files)


def analyse(
    path: str | Path, overlay: Mapping[str, str] | None = None, scope: ImportScope = ANYWHERE
) -> Analysis:
    """Like :func:`load_spec`, but return diagnostics instead of raising (for editors and ``check``);
    ``scope`` says which files may be imported."""
    sources = read_sources(path, overlay, scope=scope)
    return analyse_files(sources.files, sources.diagnostics, sources.broken)


def analyse_files(
    files: list[ParsedFile],
    diagnostics: list[Diagnostic],
    broken: Mapping[str, str] | None = None,
    parse: Parse | None = None,
) -> Analysis:
    """:func:`analyse` of files already parsed (the root first), with the problems found reading
    them; ``broken`` has the text of each file with a syntax error (the names they seem to
    declare are not reported unknown: see :mod:`exsce_dsl.lang.builders.references`), and ``parse``
    reads the files not imported where an unknown name may be declared."""
    diagnostics = list(diagnostics)
    unknown = UnknownNames(files, broken, parse)
    ctx = BuildContext(files, unknown)
    spec = _build(ctx) if files else None
    diagnostics.extend(ctx.diagnostics)
    diagnostics.extend(unknown.notes(diagnostics))
    unique = sorted(set(diagnostics), key=diagnostic_order)
    has_errors = any(d.is_error for d in unique)
    return Analysis(None if has_errors else spec, unique)


def _build(ctx: BuildContext) -> Specification:
    """Every declaration of ``ctx.files``, in the order each kind needs the others built."""
    for pf in ctx.files:
        for decl in pf.tree.declarations:
            if decl.__class__.__name__ not in ("Acceptance", "Derivation"):
                ctx.declare(pf, decl)
    for name, d in ctx.declared["RobotType"].items():
        ctx.robot_types[name] = build_robot_type(ctx, d)
    for name, d in ctx.declared["Environment"].items():
        ctx.environments[name] = build_environment(ctx, d)
    reserved = reserved_metric_names()
    for name, d in ctx.declared["Metric"].items():
        metric = build_metric(d.file, d.obj, ctx.metric_problem, reserved, name_location=d.name_location)
        if metric is not None:
            ctx.metrics[name] = metric
    ctx.task_poses = task_pose_candidates(ctx)
    for name, d in ctx.declared["Task"].items():
        task = build_task(ctx, d)
        if task is not None:
            ctx.tasks[name] = task
    for name, d in ctx.declared["Scenario"].items():
        scenario = build_scenario(ctx, d)
        if scenario is not None:
            ctx.scenarios[name] = replace(scenario, metrics=tuple(ctx.metrics.values()))
    for env in ctx.environments.values():
        ctx.diagnostics.extend(check_environment_map(env))
    for scenario in ctx.scenarios.values():
        ctx.diagnostics.extend(check_scenario(scenario))
    ctx.derived = build_derivations(
        ctx.files,
        ctx.scenarios,
        ctx.declared["Scenario"],
        ctx.tasks,
        lambda message, at: ctx.error(message, at, code="derivation"),
        ctx.unknown,
    )
    ctx.acceptance = build_all_acceptance(
        ctx.files,
        ctx.scenarios,
        ctx.declared["Scenario"],
        lambda message, at: ctx.error(message, at, code="acceptance"),
        ctx.unknown,
    )
    return Specification(ctx.files[0].path, tuple(_document(ctx, pf) for pf in ctx.files))


def _document(ctx: BuildContext, pf: ParsedFile) -> Document:
    imports = tuple(Import(i.path, pf.span(i)) for i in pf.tree.imports)
    tables: dict[str, Mapping[str, Any]] = {
        "RobotType": ctx.robot_types,
        "Environment": ctx.environments,
        "Task": ctx.tasks,
        "Scenario": ctx.scenarios,
        "Metric": ctx.metrics,
    }
    declarations: list[Any] = []
    for decl in pf.tree.declarations:
        kind = decl.__class__.__name__
        if kind == "Acceptance":
            if id(decl) in ctx.acceptance:
                declarations.append(ctx.acceptance[id(decl)])
            continue
        if kind == "Derivation":
            if id(decl) in ctx.derived:
                declarations.append(ctx.derived[id(decl)])
            continue
        declared = ctx.declared[kind].get(decl.name)
        built = tables[kind].get(decl.name)
        if built is not None and declared is not None and declared.obj is decl:
            declarations.append(built)
    return Document(pf.path, imports, tuple(declarations))
