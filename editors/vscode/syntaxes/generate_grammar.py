#!/usr/bin/env python3
"""Write syntaxes/exsce.tmLanguage.json, the TextMate grammar of the exsce language.

The JSON is generated so that its regular expressions are written once, by name
(NAME, NUMBER, ...), instead of being copied by hand into JSON strings.  After
changing this file, grammar/common.tx or a transformation's record, run (with the
project's environment: the derive steps' words come from the transformations' records)

    PYTHONPATH=src python3 editors/vscode/syntaxes/generate_grammar.py

and commit both files; tests/lsp/test_vscode_extension.py fails while they disagree.

The grammar follows grammar/*.tx construct by construct: each declaration is a
begin/end region (`meta.declaration.<kind>.exsce`) whose body only knows the
keywords valid there, so that a word that is a keyword in one construct and a
name in another (`start`, `value`, `pose`, ...) is coloured by where it stands.
Names follow the textX rule `Name` exactly (word characters and inner dashes,
reserved words excluded), so no keyword is ever coloured inside a name such as
`row_1-start` or `scenario_c`.

Scopes, so themes colour them:
  storage.type.<kind>              the word that declares (scenario, task, pose, ...)
  entity.name.<category>.<kind>    the declared name (category: type, function,
                                   namespace, variable)
  variable.other.<kind>            a reference to a declared name, by what it names
  keyword.control.import / .bdd    import; given, when, then, and of a criterion
  keyword.other[.transformation]   the other keywords (a derivation step's verb)
  keyword.other.unit               the unit of a quantity (m/s, cm, deg, std, %)
  support.function.builtin         the functions of metric expressions
  support.type.message             a ROS message type (geometry_msgs/msg/Twist)
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path
from typing import Any

Rule = dict[str, Any]  # a rule of the TextMate grammar, as JSON

HERE = Path(__file__).resolve().parent
GRAMMAR_JSON = HERE / "exsce.tmLanguage.json"
COMMON_TX = HERE.parents[2] / "grammar" / "common.tx"


def reserved_words() -> str:
    """The alternation of reserved words from the textX rule `Name` (grammar/common.tx)."""
    text = COMMON_TX.read_text(encoding="utf-8")
    found = re.search(r"^Name:\s*/\(\?!\(\?:([a-z|]+)\)", text, flags=re.MULTILINE)
    if found is None:
        raise SystemExit(f"{COMMON_TX}: no reserved-word list in rule Name")
    return found.group(1)


# ---------------------------------------------------------------- lexical pieces

BEFORE = r"(?<![\w-])"  # no keyword or name starts inside a name ...
AFTER = r"(?![\w-])"  # ... nor ends inside one
ID = r"[A-Za-z_][A-Za-z0-9_]*(?:-[A-Za-z0-9_]+)*"
NAME = rf"(?!(?:{reserved_words()}){AFTER}){ID}"  # textX rule Name
# Metric expressions: words without dashes (textX rule Word), a field after a dot.
WORD_EXCLUDED = "and|or|not|where|otherwise|elapsed|succeeded"
WORD = rf"(?!(?:{WORD_EXCLUDED})\b)[A-Za-z_][A-Za-z0-9_]*"
METRIC_BEFORE = r"(?<![\w.-])"

DIGITS = r"(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?"
# Units, longest first, as in the textX rules Quantity, Length, Angle, Frequency, MetricUnit.
QUANTITY_UNITS = "m/s|cm/s|km/h|rad/s|deg/s|mm|cm|km|ms|min|std|rad|deg|Hz|m|s|h|%"
METRIC_UNITS = "m/s|cm/s|km/h|rad/s|deg/s|mm|cm|km|ms|min|rad|deg|m|s|h"
UNIT_AFTER = r"(?![\w/-])"

MESSAGE_TYPE = r"(?<![\w/])[A-Za-z_][A-Za-z0-9_]*/(?:msg/)?[A-Za-z_][A-Za-z0-9_]*(?![\w/])"

# Words that start a top-level declaration or a derivation step: a region whose
# header is still being typed ends before the next one.
TOP_LEVEL = r"import|robot\s+type|environment|task|scenario|acceptance|derive|metric"
STEP_WORDS = (
    "robot task tasks start pose poses waypoints order obstacle of reassign to like at "
    "taking over by as from and"
)


def _record_words() -> tuple[str, str]:
    """The derive steps' first words and their other words, as the transformations' records
    write them (exsce_dsl/transform): those above, then any a newer record adds, so that the
    steps of a new transformation are highlighted once this file is run again."""
    sys.path.insert(0, str(HERE.parents[2] / "src"))
    from exsce_dsl.lang.transformation_syntax import step_heads, step_words

    verbs = ["remove", "add", "replace", "swap", "reverse", "substitute", "start", "move", "reallocate"]
    verbs += sorted(step_heads() - set(verbs))
    others = STEP_WORDS.split()
    others += sorted(step_words() - set(others) - set(verbs))
    return "|".join(verbs), " ".join(others)


STEP_VERBS, STEP_KEYWORDS = _record_words()


def kw(words: str) -> str:
    """One capture group of keywords (space-separated alternatives), whole words only."""
    return BEFORE + "(" + "|".join(words.split()) + ")" + AFTER


def seq(*words: str) -> str:
    """Keywords that follow each other (`remove robot`), each in its own capture group."""
    return BEFORE + r"\s+".join(f"({w})" for w in words) + AFTER


def then_name(regex: str) -> str:
    """`regex` optionally followed, on the same line, by a name in the next capture group."""
    return regex + rf"(?:\s+({NAME}))?"


# ---------------------------------------------------------------- rule builders

S = ".exsce"
KEYWORD = "keyword.other" + S


def include(name: str) -> Rule:
    return {"include": "#" + name}


def match(regex: str, name: str | None = None, **captures: str) -> Rule:
    """A match rule: `name` scopes the whole match, `_1=scope, _2=scope, ...` its groups."""
    rule: Rule = {"match": regex}
    if name:
        rule["name"] = name
    if captures:
        rule["captures"] = {k.lstrip("_"): {"name": v} for k, v in captures.items()}
    return rule


def caps(*names: str) -> Rule:
    """Captures 1, 2, ... named in order (None skips one)."""
    return {str(i): {"name": n} for i, n in enumerate(names, start=1) if n}


def keywords(words: str, scope: str = KEYWORD) -> Rule:
    return {"match": kw(words), "name": scope}


def block(kind: str, patterns: list[Rule]) -> Rule:
    """A braced body: `{ ... }`."""
    return {
        "name": f"meta.{kind}.body{S}",
        "begin": r"\{",
        "beginCaptures": {"0": {"name": "punctuation.section.block.begin.bracket.curly" + S}},
        "end": r"\}",
        "endCaptures": {"0": {"name": "punctuation.section.block.end.bracket.curly" + S}},
        "patterns": [include("comments"), *patterns],
    }


def region(
    kind: str, begin: str, captures: tuple[str, ...], header: list[Rule], body: list[Rule], stops: str
) -> Rule:
    """A construct with a header and a braced body: `task NAME { ... }`.

    It ends after its body, or, while its header is unfinished, before the next
    construct (`stops`, at the start of a line) or the enclosing body's `}`.
    """
    return {
        "name": f"meta.{kind}{S}",
        "begin": begin,
        "beginCaptures": caps(*captures),
        "end": rf"(?<=\}})|(?=^\s*(?:{stops}){AFTER})|(?=\}})",
        "patterns": [include("comments"), *header, block(kind, body)],
    }


def step(kind: str, begin: str, captures: tuple[str, ...], patterns: list[Rule]) -> Rule:
    """One step of a derivation; it ends where a line starts with the next step's verb."""
    return {
        "name": f"meta.step.{kind}{S}",
        "begin": begin,
        "beginCaptures": caps(*captures),
        "end": rf"(?=^\s*(?:{STEP_VERBS}){AFTER})|(?=\}})",
        "patterns": [include("comments"), *patterns],
    }


def ref(kind: str) -> str:
    return f"variable.other.{kind}{S}"


def name_as(scope: str) -> Rule:
    """Any other name, as a reference of one kind."""
    return match(rf"{BEFORE}{NAME}", scope)


VERB = "keyword.other.transformation" + S


# ---------------------------------------------------------------- the grammar


def repository() -> dict[str, Rule]:
    r: dict[str, Rule] = {}

    # Lexical rules shared by every construct.
    r["comments"] = {
        "patterns": [
            {
                "name": "comment.block" + S,
                "begin": r"/\*",
                "beginCaptures": {"0": {"name": "punctuation.definition.comment.begin" + S}},
                "end": r"\*/",
                "endCaptures": {"0": {"name": "punctuation.definition.comment.end" + S}},
            },
            match(r"(//).*$", "comment.line.double-slash" + S, _1="punctuation.definition.comment" + S),
        ]
    }
    r["strings"] = {"patterns": [string("double", '"'), string("single", "'")]}
    r["topic-strings"] = {  # `{ns}` in a topic is the robot's namespace
        "patterns": [
            string("double", '"', [match(r"\{[A-Za-z_][A-Za-z0-9_]*\}", "constant.other.placeholder" + S)]),
            string("single", "'", [match(r"\{[A-Za-z_][A-Za-z0-9_]*\}", "constant.other.placeholder" + S)]),
        ]
    }
    r["quantity"] = match(
        rf"(?<![\w.-])([-+]?{DIGITS})(?:\s*({QUANTITY_UNITS}){UNIT_AFTER})?",
        None,
        _1="constant.numeric" + S,
        _2="keyword.other.unit" + S,
    )
    r["metric-quantity"] = match(
        rf"(?<![\w.])({DIGITS})(?:\s*({METRIC_UNITS}){UNIT_AFTER})?",
        None,
        _1="constant.numeric" + S,
        _2="keyword.other.unit" + S,
    )
    r["punctuation"] = {
        "patterns": [
            match(r"\(", "punctuation.section.parens.begin.bracket.round" + S),
            match(r"\)", "punctuation.section.parens.end.bracket.round" + S),
            match(r",", "punctuation.separator.comma" + S),
            match(r":", "punctuation.separator.colon" + S),
        ]
    }
    # Positions `(x, y[, z])`, orientations `facing 0.9` / `rpy(r, p, y)`.
    r["coordinates"] = {"patterns": [keywords("facing rpy"), include("quantity"), include("punctuation")]}
    r["ros-source"] = {  # `from package "p" path "d"`, `source package "p" path "f"`
        "patterns": [keywords("from source package path file"), include("strings")]
    }

    # import "file.exsce"
    r["import"] = match(kw("import"), "keyword.control.import" + S)

    # robot type NAME { base NAME  torso yes|no  convention nav2 ... }
    r["robot-type"] = region(
        "robot-type",
        then_name(seq("robot", "type")),
        ("storage.type.robot-type" + S, "storage.type.robot-type" + S, "entity.name.type.robot-type" + S),
        [],
        [
            match(then_name(kw("base")), None, _1=KEYWORD, _2="constant.other.base" + S),
            keywords("torso"),
            keywords("yes no", "constant.language.boolean" + S),
            # where its signals are: convention nav2, pose from tf map -> base_link, velocity on "..." TYPE
            keywords(
                "convention pose velocity scan distance navigation arrival from tf on at within and motion window"
            ),
            keywords("method nav2 move_base dispatcher none", "constant.language.convention" + S),
            keywords("planar 3d goals whole recording", "constant.language.motion" + S),
            match(MESSAGE_TYPE, "support.type.message" + S),
            include("topic-strings"),
            include("quantity"),
        ],
        TOP_LEVEL,
    )

    # environment NAME { map/world/area/obstacle ... }
    pose = match(then_name(kw("pose")), None, _1="storage.type.pose" + S, _2="entity.name.variable.pose" + S)
    r["environment"] = region(
        "environment",
        then_name(kw("environment")),
        ("storage.type.environment" + S, "entity.name.type.environment" + S),
        [],
        [
            match(then_name(kw("map")), None, _1="storage.type.map" + S, _2="entity.name.variable.map" + S),
            match(
                then_name(kw("world")), None, _1="storage.type.world" + S, _2="entity.name.variable.world" + S
            ),
            region(
                "area",
                then_name(kw("area")),
                ("storage.type.area" + S, "entity.name.namespace.area" + S),
                [],
                [pose, keywords("at"), include("coordinates")],
                "area|map|world|obstacle",
            ),
            match(
                then_name(kw("obstacle")),
                None,
                _1="storage.type.obstacle" + S,
                _2="entity.name.variable.obstacle" + S,
            ),
            keywords("model at size"),
            include("ros-source"),
            include("coordinates"),
        ],
        TOP_LEVEL,
    )

    # task NAME { source ...  timeout 2 min  subtask { visit ... }  visit a, b facing 1.0, (x, y) }
    waypoints = [keywords("visit"), include("coordinates"), name_as(ref("pose"))]
    r["task"] = region(
        "task",
        then_name(kw("task")),
        ("storage.type.task" + S, "entity.name.function.task" + S),
        [],
        [
            include("ros-source"),
            keywords("timeout"),
            region("subtask", kw("subtask"), ("storage.type.subtask" + S,), [], waypoints, "subtask|visit"),
            *waypoints,
        ],
        TOP_LEVEL,
    )

    # scenario NAME in ENV { robots { r: TYPE namespace "n" starts at POSE }  mission M K { timeout 90 s ... } }
    r["assignments"] = {  # ROBOT does TASK then TASK
        "patterns": [
            match(rf"{BEFORE}({NAME})(?=\s+does{AFTER})", None, _1=ref("robot")),
            keywords("does then"),
            name_as(ref("task")),
        ]
    }
    r["scenario"] = region(
        "scenario",
        then_name(kw("scenario")),
        ("storage.type.scenario" + S, "entity.name.type.scenario" + S),
        [match(then_name(kw("in")), None, _1=KEYWORD, _2=ref("environment"))],
        [
            region(
                "robots",
                kw("robots"),
                (KEYWORD,),
                [],
                [
                    match(
                        rf"{BEFORE}({NAME})\s*(:)(?:\s*({NAME}))?",
                        None,
                        _1="entity.name.variable.robot" + S,
                        _2="punctuation.separator.colon" + S,
                        _3=ref("robot-type"),
                    ),
                    match(then_name(seq("starts", "at")), None, _1=KEYWORD, _2=KEYWORD, _3=ref("pose")),
                    keywords("namespace starts at"),
                    include("strings"),
                    include("coordinates"),
                    name_as(ref("pose")),
                ],
                "robots|mission",
            ),
            region(
                "mission",
                then_name(kw("mission")),
                ("storage.type.mission" + S, "entity.name.function.mission" + S),
                [keywords("parallel sequential", "storage.modifier.mission-kind" + S)],
                [keywords("timeout"), include("quantity"), include("assignments")],
                "robots|mission",
            ),
        ],
        TOP_LEVEL,
    )

    # acceptance for SCENARIO { scenario "title" { given ... when ... then ... and ... } }
    criterion_body = [
        keywords("given when then and", "keyword.control.bdd" + S),
        # What a name is follows from the words around it.
        match(rf"{BEFORE}({NAME})(?=\s+at\s+its{AFTER})", None, _1=ref("robot")),
        match(rf"{BEFORE}({NAME})(?=\s+does{AFTER})", None, _1=ref("robot")),
        match(then_name(kw("does")), None, _1=KEYWORD, _2=ref("task")),
        match(rf"{BEFORE}({NAME})(?=\s+runs{AFTER})", None, _1=ref("mission")),
        match(rf"{BEFORE}({NAME})(?=\s+{NAME}\s+(?:stays|is){AFTER})", None, _1=ref("robot")),
        match(rf"{BEFORE}({NAME})(?=\s+(?:stays|is){AFTER})", None, _1=ref("metric")),
        match(rf"{BEFORE}({NAME})(?=\s+reaches{AFTER})", None, _1=ref("robot")),
        match(then_name(kw("reaches")), None, _1=KEYWORD, _2=ref("pose")),
        match(
            kw("during before after") + rf"(?:\s+({NAME}){AFTER}(?!\s+reaches{AFTER}))?",
            None,
            _1=KEYWORD,
            _2=ref("task"),
        ),
        match(then_name(kw("of")), None, _1=KEYWORD, _2=ref("scenario")),
        keywords(
            "at least baseline runs its start pose each robot stays below above is invariant "
            "around within increasing decreasing from by"
        ),
        include("quantity"),
        name_as("variable.other" + S),
    ]
    r["acceptance"] = region(
        "acceptance",
        kw("acceptance"),
        ("storage.type.acceptance" + S,),
        [match(then_name(kw("for")), None, _1=KEYWORD, _2=ref("scenario"))],
        [
            region(
                "criterion",
                kw("scenario"),
                ("storage.type.criterion" + S,),
                [include("strings")],
                criterion_body,
                "scenario",
            )
        ],
        TOP_LEVEL,
    )

    # derive NAME from BASE { steps }
    def verbs(*words: str) -> tuple[str, ...]:
        return (VERB,) + (KEYWORD,) * (len(words) - 1)

    steps = [
        step(
            "remove-robot",
            then_name(seq("remove", "robot")),
            (*verbs("remove", "robot"), ref("robot")),
            [
                match(then_name(seq("reassign", "to")), None, _1=KEYWORD, _2=KEYWORD, _3=ref("robot")),
                keywords("reassign to"),
                name_as(ref("robot")),
            ],
        ),
        step(
            "remove-tasks",
            then_name(seq("remove", "tasks", "of")),
            (*verbs("remove", "tasks", "of"), ref("robot")),
            [name_as(ref("robot"))],
        ),
        step(
            "remove-task",
            then_name(seq("remove", "task")),
            (*verbs("remove", "task"), ref("task")),
            [match(then_name(kw("from")), None, _1=KEYWORD, _2=ref("robot")), name_as(ref("task"))],
        ),
        step(
            "remove-start-pose",
            then_name(seq("remove", "start", "pose", "of")),
            (*verbs("remove", "start", "pose", "of"), ref("robot")),
            [name_as(ref("robot"))],
        ),
        step(
            "add-robot",
            then_name(seq("add", "robot")),
            (*verbs("add", "robot"), "entity.name.variable.robot" + S),
            [
                match(then_name(kw("like")), None, _1=KEYWORD, _2=ref("robot")),
                match(then_name(kw("at")), None, _1=KEYWORD, _2=ref("pose")),
                match(then_name(seq("taking", "over")), None, _1=KEYWORD, _2=KEYWORD, _3=ref("robot")),
                keywords("like at taking over"),
                name_as("variable.other" + S),
            ],
        ),
        step(
            "add-task",
            then_name(seq("add", "task")),
            (*verbs("add", "task"), ref("task")),
            [
                match(then_name(kw("to")), None, _1=KEYWORD, _2=ref("robot")),
                keywords("to at"),
                include("quantity"),
                name_as("variable.other" + S),
            ],
        ),
        step(
            "replace-robot",
            then_name(seq("replace", "robot")),
            (*verbs("replace", "robot"), ref("robot")),
            [
                match(then_name(kw("by")), None, _1=KEYWORD, _2="entity.name.variable.robot" + S),
                match(then_name(kw("like")), None, _1=KEYWORD, _2=ref("robot")),
                keywords("by like"),
                name_as("variable.other" + S),
            ],
        ),
        step(
            "swap-tasks",
            then_name(seq("swap", "tasks", "of")),
            (*verbs("swap", "tasks", "of"), ref("robot")),
            [keywords("and"), name_as(ref("robot"))],
        ),
        step(
            "swap-start-poses",
            then_name(seq("swap", "start", "poses", "of")),
            (*verbs("swap", "start", "poses", "of"), ref("robot")),
            [keywords("and"), name_as(ref("robot"))],
        ),
        step(
            "reverse-waypoints",
            then_name(seq("reverse", "waypoints", "of")),
            (*verbs("reverse", "waypoints", "of"), ref("task")),
            [
                match(then_name(kw("as")), None, _1=KEYWORD, _2="entity.name.function.task" + S),
                name_as(ref("task")),
            ],
        ),
        step(
            "reverse-task-order",
            seq("reverse", "task", "order"),
            verbs("reverse", "task", "order"),
            [match(then_name(kw("of")), None, _1=KEYWORD, _2=ref("robot")), name_as(ref("robot"))],
        ),
        step(
            "substitute-task",
            then_name(seq("substitute", "task")),
            (*verbs("substitute", "task"), ref("task")),
            [keywords("by"), name_as(ref("task"))],
        ),
        step(
            "start-at",
            then_name(kw("start")),
            (VERB, ref("robot")),
            [match(then_name(kw("at")), None, _1=KEYWORD, _2=ref("pose")), name_as("variable.other" + S)],
        ),
        step(
            "move-obstacle",
            then_name(seq("move", "obstacle")),
            (*verbs("move", "obstacle"), ref("obstacle")),
            [keywords("to"), include("quantity"), include("punctuation")],
        ),
        step("reallocate", kw("reallocate"), (VERB,), [block("reallocate", [include("assignments")])]),
        # A step still being written.
        keywords(STEP_VERBS.replace("|", " "), VERB),
        keywords(STEP_KEYWORDS),
        include("quantity"),
        include("punctuation"),
        name_as("variable.other" + S),
    ]
    r["derive"] = region(
        "derive",
        then_name(kw("derive")),
        ("storage.type.derive" + S, "entity.name.type.scenario" + S),
        [match(then_name(kw("from")), None, _1=KEYWORD, _2=ref("scenario"))],
        steps,
        TOP_LEVEL,
    )

    # metric NAME for each robot | each pair of robots (a, b) | mission [per segment] { ... }
    def metric_kw(words: str, scope: str = KEYWORD) -> Rule:
        # A field after a dot (`msg.value`) is not a keyword.
        return match(METRIC_BEFORE + "(" + "|".join(words.split()) + ")" + AFTER + r"(?!\s*\.)", scope)

    r["expression"] = {
        "patterns": [
            match(
                METRIC_BEFORE + r"(duration|count)(?=\s+where\b)",
                None,
                _1="support.function.builtin" + S,
            ),
            match(
                METRIC_BEFORE
                + r"(min|max|mean|sum|first|last|integral|change|path_length|norm|abs|sqrt|len|speed|derivative)(?=\s*\()",
                None,
                _1="support.function.builtin" + S,
            ),
            match(METRIC_BEFORE + r"(elapsed|succeeded)\b", None, _1="variable.language" + S),
            metric_kw("where"),
            metric_kw("and or not", "keyword.operator.logical" + S),
            match(r"<=|>=|==|!=|<|>", "keyword.operator.comparison" + S),
            include("metric-quantity"),
            match(r"[-+*/]", "keyword.operator.arithmetic" + S),
            match(
                rf"(\.)\s*({WORD})",
                None,
                _1="punctuation.accessor.dot" + S,
                _2="variable.other.property" + S,
            ),
            match(METRIC_BEFORE + WORD, "variable.other" + S),
            include("punctuation"),
        ]
    }
    r["metric"] = region(
        "metric",
        then_name(kw("metric")),
        ("storage.type.metric" + S, "entity.name.function.metric" + S),
        [
            keywords("for each robot pair of robots mission per segment"),
            match(rf"{BEFORE}({WORD}){AFTER}", None, _1="variable.parameter.pair" + S),
            include("punctuation"),
        ],
        [
            match(
                METRIC_BEFORE + rf"(unit){AFTER}(?:\s+({METRIC_UNITS}){UNIT_AFTER})?",
                None,
                _1=KEYWORD,
                _2="keyword.other.unit" + S,
            ),
            match(METRIC_BEFORE + r"(safe)\s+(below|above)" + AFTER, None, _1=KEYWORD, _2=KEYWORD),
            match(
                METRIC_BEFORE + rf"(reads){AFTER}(?:\s+({WORD})\s*(:)?)?",
                None,
                _1=KEYWORD,
                _2="entity.name.variable.read" + S,
                _3="punctuation.separator.colon" + S,
            ),
            # reads pose: robot pose (a signal of the robot, wherever its type says it is)
            match(
                r"(?<=:)\s*(robot)\s+(pose|velocity|distance|scan|goals)" + AFTER,
                None,
                _1=KEYWORD,
                _2=KEYWORD,
            ),
            match(MESSAGE_TYPE, "support.type.message" + S),
            metric_kw("on value otherwise safe below above unit reads"),
            include("topic-strings"),
            include("expression"),
        ],
        TOP_LEVEL,
    )
    return r


def string(kind: str, quote: str, inner: list[Rule] | None = None) -> Rule:
    return {
        "name": f"string.quoted.{kind}{S}",
        "begin": quote,
        "beginCaptures": {"0": {"name": "punctuation.definition.string.begin" + S}},
        "end": quote,
        "endCaptures": {"0": {"name": "punctuation.definition.string.end" + S}},
        "patterns": [match(r"\\.", "constant.character.escape" + S), *(inner or [])],
    }


def grammar() -> Rule:
    return {
        "$schema": "https://raw.githubusercontent.com/martinring/tmlanguage/master/tmlanguage.json",
        "name": "exsce",
        "scopeName": "source.exsce",
        "fileTypes": ["exsce"],
        "comment": "Generated by syntaxes/generate_grammar.py from grammar/*.tx; do not edit by hand.",
        "patterns": [
            include("comments"),
            include("import"),
            include("robot-type"),
            include("environment"),
            include("task"),
            include("scenario"),
            include("acceptance"),
            include("derive"),
            include("metric"),
            include("strings"),
        ],
        "repository": repository(),
    }


def render() -> str:
    return json.dumps(grammar(), indent=2, ensure_ascii=False) + "\n"


def main() -> None:
    GRAMMAR_JSON.write_text(render(), encoding="utf-8")
    print(f"wrote {GRAMMAR_JSON}")


if __name__ == "__main__":
    main()
