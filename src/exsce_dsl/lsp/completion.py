"""Completion by context: the keywords the grammar allows at the point, and the names of
what may be referred to there (poses where a waypoint goes, robots of the scenario in its
mission, a scenario's metrics in its acceptance criteria, relations, transformations, and in
a metric the topics it reads, their messages' fields and message types: :mod:`.fields`).

The grammar says *whether* a name may come (:mod:`exsce_dsl.lang.editor.continuations`); the words
before the point say *which kind* of name.  Names come from the files' indexes, which
keep a file's last complete parse while its text does not parse.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from lsprotocol import types

from exsce_dsl.lang import Continuations, Symbol, builtin_metrics
from exsce_dsl.lsp.derive_steps import current_step, next_types, snippet
from exsce_dsl.lsp.navigation import Names
from exsce_dsl.oracles import relation, relation_names
from exsce_dsl.transform import TRANSFORMATIONS

LIMIT = 300
"""At most this many items; the list is marked incomplete beyond (the client asks again)."""

_BLOCK_WORDS = frozenset(
    {"robots", "mission", "scenario", "environment", "area", "task", "subtask", "acceptance", "derive"}
    | {"reallocate", "metric", "robot"}
)
# How each relation of the oracles is written in acceptance criteria.
_RELATION_PHRASES = {
    "below_max": "stays below ",
    "above_min": "stays above ",
    "invariant": "is invariant",
    "increasing": "is increasing",
    "decreasing": "is decreasing",
}

_ITEM_KINDS = {
    "robot type": types.CompletionItemKind.Class,
    "environment": types.CompletionItemKind.Module,
    "area": types.CompletionItemKind.Folder,
    "pose": types.CompletionItemKind.Constant,
    "obstacle": types.CompletionItemKind.Struct,
    "task": types.CompletionItemKind.Function,
    "scenario": types.CompletionItemKind.Module,
    "robot": types.CompletionItemKind.Variable,
    "mission": types.CompletionItemKind.Event,
    "metric": types.CompletionItemKind.Field,
}
_OFFERED_KINDS = {
    "field": types.CompletionItemKind.Field,
    "read": types.CompletionItemKind.Variable,
    "robot": types.CompletionItemKind.Variable,
    "type": types.CompletionItemKind.Class,
}


@dataclass(frozen=True)
class WantedName:
    """A kind of name that fits, said in scenario ``scope`` (robots, missions) or of
    environment ``environment`` (poses, obstacles)."""

    kind: str
    scope: str | None = None
    environment: str | None = None


def wanted_names(allowed: Continuations, names: Names) -> list[WantedName]:
    """Which kinds of names fit at the point, from the words before it."""
    before = allowed.before
    if not before:
        return []
    declaration = allowed.declaration
    if declaration == "scenario":
        return _in_scenario(before, names)
    if declaration == "task":
        return [WantedName("pose")] if before[-1] in ("visit", ",") else []
    if declaration == "acceptance":
        return _in_acceptance(before)
    if declaration == "derive":
        return _in_derivation(before, names)
    return []


def _blocks(before: Sequence[str]) -> list[str]:
    """The blocks open at the point, outermost first, each by the word that opens it."""
    stack: list[str] = []
    for i, token in enumerate(before):
        if token == "{":
            stack.append(next((before[j] for j in range(i - 1, -1, -1) if before[j] in _BLOCK_WORDS), ""))
        elif token == "}" and stack:
            stack.pop()
    return stack


def _in_scenario(before: Sequence[str], names: Names) -> list[WantedName]:
    last = before[-1]
    name = before[1] if len(before) > 1 else None
    environment = before[3] if len(before) > 3 else None
    if len(before) == 3 and last == "in":
        return [WantedName("environment")]
    blocks = _blocks(before)
    if last == ":" and blocks[-1:] == ["robots"]:
        return [WantedName("robot type")]
    if last == "at" and before[-2] == "starts":
        return [WantedName("pose", environment=environment)]
    if blocks[-1:] == ["mission"]:
        if last in ("does", "then"):
            return [WantedName("task")]
        return [WantedName("robot", name)]
    return []


def _in_acceptance(before: Sequence[str]) -> list[WantedName]:
    last, previous = before[-1], before[-2] if len(before) > 1 else ""
    scenario = before[2] if len(before) > 2 else None
    if len(before) == 2 and last == "for":
        return [WantedName("scenario")]
    table = {
        "given": [WantedName("robot", scenario)],
        "when": [WantedName("robot", scenario), WantedName("mission", scenario)],
        "does": [WantedName("task")],
        "then": [WantedName("robot", scenario), WantedName("metric")],
        "and": [WantedName("robot", scenario), WantedName("metric")],
        "before": [WantedName("robot", scenario), WantedName("task")],
        "after": [WantedName("robot", scenario), WantedName("task")],
        "during": [WantedName("task")],
        "reaches": [WantedName("pose")],
        "of": [WantedName("scenario")],
    }
    if last in table:
        return table[last]
    if previous in ("then", "and") or (last == "robot" and previous == "each"):
        return [WantedName("metric")]
    return []


def _in_derivation(before: Sequence[str], names: Names) -> list[WantedName]:
    derived = before[1] if len(before) > 1 else None
    if len(before) == 4 and before[-1] == "from":
        return [WantedName("scenario")]
    environment = _environment_of(names, before[3]) if len(before) > 3 else None
    # the robots the steps add, and the base's (known from the text while this file is not indexed yet)
    robots = [WantedName("robot", derived), WantedName("robot", before[3] if len(before) > 3 else None)]
    by_type = {
        "robot": robots,
        "allocation robot": robots,
        "task": [WantedName("task")],
        "allocation task": [WantedName("task")],
        "pose": [WantedName("pose", environment=environment)],
        "obstacle": [WantedName("obstacle", environment=environment)],
    }
    wanted: list[WantedName] = []
    for kind in sorted(next_types(current_step(before))):
        wanted.extend(w for w in by_type.get(kind, []) if w not in wanted)
    return wanted


def _environment_of(names: Names, scenario: str) -> str | None:
    seen: set[str] = set()
    current: str | None = scenario
    while current is not None and current not in seen:
        seen.add(current)
        for symbol in names.symbols("scenario", current):
            environment = symbol.fact("environment")
            if environment is not None:
                return environment
        current = names.base_of(current)
    return None


def candidates(wanted: WantedName, names: Names, all_symbols: Sequence[Symbol]) -> list[Symbol]:
    """The declarations that fit ``wanted``."""
    found = [s for s in all_symbols if s.kind == wanted.kind]
    if wanted.kind in ("robot", "mission"):
        scopes: list[str] = []
        scope = wanted.scope
        while scope is not None and scope not in scopes:
            scopes.append(scope)
            scope = names.base_of(scope)
        return [s for s in found if s.scope in scopes]
    if wanted.environment is not None:
        mine = [s for s in found if s.scope == wanted.environment]
        found = mine or found
    return names.nearest(found)


def _matches(typed: str, name: str) -> bool:
    """Whether the letters typed appear in ``name`` in order (as editors filter)."""
    if not typed:
        return True
    rest = iter(name.lower())
    return all(char in rest for char in typed.lower())


def _detail(symbol: Symbol) -> str:
    if symbol.kind == "pose":
        return f"pose in {symbol.fact('area')} at {symbol.fact('at')}"
    if symbol.kind == "metric":
        unit = symbol.fact("unit")
        return f"metric of {symbol.fact('of')}" + (f", in {unit}" if unit else "")
    if symbol.kind == "task":
        return f"task: {symbol.fact('waypoints') or symbol.fact('subtask 1') or ''}"
    if symbol.kind == "robot":
        return f"robot ({symbol.fact('type') or symbol.fact('like') or ''}) of {symbol.scope}"
    return symbol.kind


def complete(
    allowed: Continuations,
    names: Names,
    typed: str,
    replace: types.Range,
    snippets: bool,
    offered: Sequence[tuple[str, str, str]] = (),
) -> types.CompletionList:
    """The completion list at a point: names that fit, then keywords, relations, transformations.
    ``offered``: (label, kind, detail) items that fit too (a metric's fields, its reads)."""
    items: list[types.CompletionItem] = []
    seen: set[tuple[str, str]] = set()
    all_symbols = [s for index in names.indexes for s in index.all_symbols()]

    def add(
        label: str,
        kind: types.CompletionItemKind,
        detail: str,
        sort: str,
        insert: str | None = None,
        snippet: bool = False,
    ) -> None:
        text = insert or label
        if (label, detail) in seen or not (_matches(typed, label) or _matches(typed, text)):
            return
        seen.add((label, detail))
        items.append(
            types.CompletionItem(
                label=label,
                kind=kind,
                detail=detail,
                sort_text=f"{sort}{label}",
                filter_text=text if insert else None,
                text_edit=types.TextEdit(replace, text),
                insert_text_format=types.InsertTextFormat.Snippet if snippet else None,
            )
        )

    for label, what, detail in offered:
        add(label, _OFFERED_KINDS.get(what, types.CompletionItemKind.Text), detail, "0")
    if allowed.name or not allowed.known:
        for wanted in wanted_names(allowed, names):
            for symbol in candidates(wanted, names, all_symbols):
                kind = _ITEM_KINDS.get(symbol.kind, types.CompletionItemKind.Text)
                add(symbol.name, kind, _detail(symbol), "0")
            if wanted.kind == "metric":
                for name, info in builtin_metrics().items():
                    if not names.symbols("metric", name):
                        add(name, types.CompletionItemKind.Field, f"built-in metric: {info.meaning}", "0")
    for keyword in allowed.keywords:
        add(keyword, types.CompletionItemKind.Keyword, "keyword", "1")
    if allowed.declaration == "acceptance" and {"stays", "is"} & set(allowed.keywords):
        for name in relation_names():
            if name in _RELATION_PHRASES:
                phrase = _RELATION_PHRASES[name]
                params = ", ".join(sorted(relation(name).parameters))
                add(name, types.CompletionItemKind.Operator, f"relation {name}({params})", "2", insert=phrase)
    if allowed.declaration == "derive" and "remove" in allowed.keywords:
        for name, record in TRANSFORMATIONS.items():
            written, plain = snippet(record)
            kind = types.CompletionItemKind.Snippet
            add(name, kind, record.help, "2", insert=written if snippets else plain, snippet=snippets)
    incomplete = len(items) > LIMIT
    items.sort(key=lambda item: item.sort_text or item.label)
    return types.CompletionList(is_incomplete=incomplete, items=items[:LIMIT])
