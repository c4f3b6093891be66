"""The VS Code extension in editors/vscode: its grammar, snippets, client and package.

With node and npm: ``npm ci`` once (kept while package-lock.json is unchanged), the
annotated grammar tests, the snapshots of the shipped examples, the client's unit
tests, and ``vsce package``, whose .vsix must hold everything VS Code loads.
Without them those tests fail: the README's test command needs Node.js >= 20 and npm.

In Python: what ties the extension to the language — every keyword of grammar/*.tx is
highlighted and asserted in a grammar test, the TextMate grammar is the one its
generator writes, and the snippets and the grammar tests are specifications
``exscec check`` accepts.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pytest

from exsce_dsl.lang.transformation_syntax import step_words
from exsce_dsl.model.expressions import FUNCTIONS

from tests.support.cli import run_exscec
from tests.support.paths import ROOT

VSCODE = ROOT / "editors" / "vscode"
GRAMMAR_JSON = VSCODE / "syntaxes" / "exsce.tmLanguage.json"
GRAMMAR_TESTS = sorted((VSCODE / "test" / "grammar").glob("*.test.exsce"))
# The folders of .exsce files that test/snapshots.js keeps snapshots of.
SHIPPED_EXAMPLES = ["examples/brsu_building_c", "examples/drones", "src/exsce_dsl/lang/stdlib"]
# Scopes that colour a word as a keyword of the language.
KEYWORD_SCOPES = ("keyword.", "storage.type.", "storage.modifier.", "constant.language.")


# ---------------------------------------------------------------- node side


def _node_tools() -> tuple[str, str]:
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.fail("node and npm are needed for the VS Code extension's tests (Node.js >= 20)")
    return node, npm


def _run(
    *args: str, env: dict[str, str] | None = None, timeout: int = 300
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        list(args),
        cwd=VSCODE,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "NO_COLOR": "1", "FORCE_COLOR": "0", **(env or {})},
    )


def _relative(path: Path) -> str:
    """A path as the node tools, run in editors/vscode, are given it and print it."""
    return path.relative_to(VSCODE).as_posix()


@pytest.fixture(scope="module")
def node_modules() -> Path:
    """editors/vscode/node_modules as package-lock.json has it: `npm ci`, unless done for this lock."""
    _, npm = _node_tools()
    modules = VSCODE / "node_modules"
    stamp = modules / ".exsce-package-lock.sha256"
    lock = hashlib.sha256((VSCODE / "package-lock.json").read_bytes()).hexdigest()
    if not (stamp.is_file() and stamp.read_text().strip() == lock):
        result = _run(npm, "ci", "--no-audit", "--no-fund", timeout=600)
        assert result.returncode == 0, f"npm ci failed:\n{result.stdout}\n{result.stderr}"
        stamp.write_text(lock + "\n")
    return modules


@pytest.fixture(scope="module")
def node() -> str:
    return _node_tools()[0]


def _assertions(test_file: Path) -> list[tuple[str, list[str], list[str]]]:
    """The assertions of a vscode-tmgrammar-test file: (text under the carets, scopes, excluded scopes)."""
    found = []
    source = ""
    for line in test_file.read_text(encoding="utf-8").splitlines()[1:]:
        carets = re.match(r"//(\s*)(\^+)\s+(.*)$", line)
        arrow = re.match(r"//\s*<(~*)(-+)\s+(.*)$", line)
        if carets:
            start = 2 + len(carets.group(1))
            width, scopes = len(carets.group(2)), carets.group(3)
        elif arrow:
            start, width, scopes = len(arrow.group(1)), len(arrow.group(2)), arrow.group(3)
        else:
            source = line
            continue
        wanted, _, unwanted = scopes.partition(" - ")
        found.append((source[start : start + width], wanted.split(), unwanted.split()))
    return found


def test_grammar_tests_pass(node_modules: Path) -> None:
    assert len(GRAMMAR_TESTS) >= 6
    result = _run(str(node_modules / ".bin" / "vscode-tmgrammar-test"), *map(_relative, GRAMMAR_TESTS))
    assert result.returncode == 0, result.stdout + result.stderr
    for test_file in GRAMMAR_TESTS:
        assert f"✓ {_relative(test_file)} run successful" in result.stdout, result.stdout
    assertions = sum(len(_assertions(test_file)) for test_file in GRAMMAR_TESTS)
    assert assertions >= 300, f"only {assertions} scope assertions"


def test_snapshots_of_the_shipped_examples_hold(node_modules: Path, node: str) -> None:
    examples = sorted(
        path.relative_to(ROOT).as_posix()
        for folder in SHIPPED_EXAMPLES
        for path in (ROOT / folder).rglob("*.exsce")
    )
    assert len(examples) >= 14
    result = _run(node, "test/snapshots.js")
    assert result.returncode == 0, result.stdout + result.stderr
    for example in examples:
        assert f"✓ {example} run successfully" in result.stdout, result.stdout


def _lsp_server() -> dict[str, str]:
    """EXSCE_SERVER_COMMAND for the client's tests: this environment's exscec, whose `lsp` they start."""
    assert run_exscec("lsp", "--help").returncode == 0
    return {"EXSCE_SERVER_COMMAND": str(Path(sys.executable).with_name("exscec"))}


def test_client_unit_tests_pass(node_modules: Path, node: str) -> None:
    unit_tests = sorted(map(_relative, (VSCODE / "test" / "unit").glob("*.test.js")))
    result = _run(node, "--test", *unit_tests, env=_lsp_server())
    assert result.returncode == 0, result.stdout + result.stderr
    passed = re.search(r"^# pass (\d+)$", result.stdout, re.MULTILINE)
    assert passed and int(passed.group(1)) >= 15, result.stdout
    assert re.search(r"^# fail 0$", result.stdout, re.MULTILINE), result.stdout


def test_vsix_holds_the_extension_and_its_dependencies(node_modules: Path, node: str, tmp_path: Path) -> None:
    vsix = tmp_path / "exsce.vsix"
    result = _run(
        str(node_modules / ".bin" / "vsce"), "package", "--allow-missing-repository", "--out", str(vsix)
    )
    assert result.returncode == 0, result.stdout + result.stderr
    with zipfile.ZipFile(vsix) as archive:
        names = set(archive.namelist())
        archive.extractall(tmp_path / "unpacked")
    for part in (
        "package.json",
        "extension.js",
        "server.js",
        "folding.js",
        "syntaxes/exsce.tmLanguage.json",
        "language-configuration.json",
        "snippets/exsce.json",
        "node_modules/vscode-languageclient/package.json",
        "node_modules/vscode-languageclient/node.js",
        "node_modules/vscode-jsonrpc/package.json",
    ):
        assert f"extension/{part}" in names, f"{part} is not in the .vsix"
    assert not any(name.startswith("extension/test/") for name in names), "the tests are packaged"
    assert not any("/@vscode/vsce" in name for name in names), "a development dependency is packaged"
    manifest = json.loads((tmp_path / "unpacked" / "extension" / "package.json").read_text())
    assert manifest["version"] == json.loads((VSCODE / "package.json").read_text())["version"]

    # The unpacked extension starts a server with only what the .vsix bundles.
    log = tmp_path / "methods.log"
    started = _run(
        node,
        "test/unit/activate.js",
        json.dumps({"server.command": str(VSCODE / "test" / "unit" / "fake-server.js")}),
        env={
            "EXSCE_EXTENSION": str(tmp_path / "unpacked" / "extension" / "extension.js"),
            "FAKE_SERVER_LOG": str(log),
        },
        timeout=60,
    )
    seen = json.loads(started.stdout.strip().splitlines()[-1])
    assert seen["running"] and seen["errors"] == [], seen
    assert log.read_text().split() == ["initialize", "initialized", "shutdown", "exit"]


# ---------------------------------------------------------------- the language and the grammar


def _tx_text() -> str:
    """grammar/*.tx without their comments."""
    text = "\n".join(path.read_text(encoding="utf-8") for path in sorted((ROOT / "grammar").glob("*.tx")))
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.DOTALL)
    return re.sub(r"^\s*//[^\n]*", "", text, flags=re.MULTILINE)


BUILT_IN_STEP_WORDS = frozenset(
    "remove add replace swap reverse substitute start move reallocate robot task tasks pose poses "
    "waypoints order obstacle of reassign to like at taking over by as from and".split()
)
"""The words of the built-in transformations' steps."""


def _language_keywords() -> set[str]:
    """The keywords of grammar/*.tx and those of the derive steps, which the loader adds from
    the transformations' records."""
    return set(re.findall(r"'([A-Za-z_][A-Za-z0-9_]*)'", _tx_text())) | step_words()


def _rule_alternatives(rule: str) -> list[str]:
    """The words of a regex rule of the .tx grammar written as `Rule: [attr=]/(a|b|c)...`."""
    found = re.search(rf"^{rule}:[^/\n]*/[^(]*\(([\w|]+)\)", _tx_text(), flags=re.MULTILINE)
    assert found, f"rule {rule} not found in grammar/*.tx"
    return found.group(1).split("|")


def _units() -> set[str]:
    """The units of the textX rules Quantity and MetricUnit."""
    units: set[str] = set()
    for rule in ("Quantity", "MetricUnit"):
        found = re.search(rf"^{rule}:.*?\((m\\/s\|[^)]*)\)", _tx_text(), flags=re.MULTILINE)
        assert found, f"rule {rule} not found in grammar/*.tx"
        units |= set(found.group(1).replace("\\/", "/").split("|"))
    return units


def _group(regex: str, number: int) -> str:
    """The text of capture group `number` of `regex` (0: the whole regex)."""
    if number == 0:
        return regex
    count, i, in_class = 0, 0, False
    while i < len(regex):
        c = regex[i]
        if c == "\\":
            i += 2
            continue
        if in_class:
            in_class = c != "]"
        elif c == "[":
            in_class = True
        elif c == "(" and regex[i + 1] != "?":
            count += 1
            if count == number:
                depth, j = 1, i + 1
                while depth:
                    if regex[j] == "\\":
                        j += 2
                        continue
                    depth += {"(": 1, ")": -1}.get(regex[j], 0)
                    j += 1
                return regex[i + 1 : j - 1]
        i += 1
    raise ValueError(f"no group {number} in {regex}")


@dataclass(frozen=True)
class ScopedPattern:
    scope: str
    pattern: str  # the regex, or the capture group, that gets the scope


def _scoped_patterns() -> list[ScopedPattern]:
    """Every regex of the TextMate grammar, or capture group of one, with the scope it gives."""
    found = []

    def walk(node: object) -> None:
        if isinstance(node, dict):
            for key, captures in (("match", "captures"), ("begin", "beginCaptures"), ("end", "endCaptures")):
                if key in node:
                    if key == "match" and "name" in node:
                        found.append(ScopedPattern(node["name"], node[key]))
                    for number, capture in node.get(captures, {}).items():
                        if "name" in capture:
                            found.append(ScopedPattern(capture["name"], _group(node[key], int(number))))
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    walk(json.loads(GRAMMAR_JSON.read_text(encoding="utf-8")))
    return found


def _unhighlighted(words: set[str], scope_prefixes: tuple[str, ...]) -> set[str]:
    patterns = [p.pattern for p in _scoped_patterns() if p.scope.startswith(scope_prefixes)]
    return {word for word in words if not any(re.fullmatch(pattern, word) for pattern in patterns)}


def test_every_keyword_of_the_language_is_highlighted() -> None:
    keywords = _language_keywords()
    assert {"scenario", "environment", "derive", "metric", "reallocate", "otherwise"} <= keywords
    assert _unhighlighted(keywords, KEYWORD_SCOPES) == set()


def test_every_function_window_value_and_unit_is_highlighted() -> None:
    # the Function rule takes any name before '(' (so that an unknown one is reported by name):
    # the functions are the model's list
    functions = set(FUNCTIONS) | set(_rule_alternatives("WhereFunction"))
    assert _unhighlighted(functions, ("support.function.",)) == set()
    assert _unhighlighted(set(_rule_alternatives("WindowValue")), ("variable.language.",)) == set()
    assert _unhighlighted(_units(), ("keyword.other.unit",)) == set()


def test_every_keyword_is_asserted_in_a_grammar_test() -> None:
    """A keyword highlighted somewhere is not enough: a grammar test shows it in its construct.

    The words of derive steps are highlighted from the transformations' records (the generator
    reads them): those of the built-in transformations are asserted in derive.test.exsce, and a
    new transformation's need not be."""
    asserted = {
        text
        for test_file in GRAMMAR_TESTS
        for text, scopes, _ in _assertions(test_file)
        if any(scope.startswith(KEYWORD_SCOPES) for scope in scopes)
    }
    assert _language_keywords() - (step_words() - BUILT_IN_STEP_WORDS) - asserted == set()


def test_grammar_is_what_its_generator_writes() -> None:
    spec = importlib.util.spec_from_file_location(
        "generate_grammar", VSCODE / "syntaxes" / "generate_grammar.py"
    )
    assert spec is not None and spec.loader is not None
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    assert GRAMMAR_JSON.read_text(encoding="utf-8") == generator.render(), (
        "run: python3 editors/vscode/syntaxes/generate_grammar.py"
    )


def test_grammar_tests_are_specifications() -> None:
    valid = [path for path in GRAMMAR_TESTS if path.name != "unfinished.test.exsce"]
    result = run_exscec("check", *map(str, valid))
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stderr.count(": ok (") == len(valid), result.stderr


# ---------------------------------------------------------------- snippets


def expand_snippet(body: str) -> str:
    """A snippet body as a user who tabs through it gets it: each placeholder at its default."""
    values: dict[str, str] = {}
    pos = 0
    token = re.compile(r"\$(\d+)|\$\{(\d+)\}|\$\{(\d+):|\$\{(\d+)\|([^|]*)\|\}")

    def parse(until: str | None) -> str:
        nonlocal pos
        out: list[str] = []
        while pos < len(body):
            c = body[pos]
            if c == until:
                return "".join(out)
            if c == "\\" and body[pos + 1 : pos + 2] in ("$", "}", "\\", ",", "|"):
                out.append(body[pos + 1])
                pos += 2
            elif c == "$":
                found = token.match(body, pos)
                if found is None:
                    raise ValueError(f"snippet syntax this test does not know: {body[pos : pos + 20]!r}")
                pos = found.end()
                if found.group(3):  # ${n:default}
                    value = parse("}")
                    pos += 1
                    values.setdefault(found.group(3), value)
                elif found.group(4):  # ${n|first,second|}
                    value = found.group(5).split(",")[0]
                    values.setdefault(found.group(4), value)
                else:  # $n, ${n}: a tab stop, or a mirror of a placeholder
                    value = values.get(found.group(1) or found.group(2), "")
                out.append(value)
            else:
                out.append(c)
                pos += 1
        assert until is None, f"unclosed placeholder in {body!r}"
        return "".join(out)

    return parse(None)


def test_expand_snippet() -> None:
    assert expand_snippet("task ${1:t} {\n\tvisit ${2:p}$0\n}") == "task t {\n\tvisit p\n}"
    assert expand_snippet("${1:r1} does x\n$1 ${2|parallel,sequential|}") == "r1 does x\nr1 parallel"
    assert expand_snippet('on "${1:/{ns\\}/x}" ${2:max($1)}') == 'on "/{ns}/x" max(/{ns}/x)'


def _snippets() -> dict[str, str]:
    snippets = json.loads((VSCODE / "snippets" / "exsce.json").read_text(encoding="utf-8"))
    return {
        name: expand_snippet(s["body"] if isinstance(s["body"], str) else "\n".join(s["body"]))
        for name, s in snippets.items()
    }


# Snippets of whole declarations, in an order where each one's defaults name what the
# ones before declare (scenario_name in environment_name, visit pose_name, ...).
DECLARATIONS = ["robot type", "environment", "task", "metric", "scenario", "acceptance", "derive"]
# Snippets of parts of a declaration, each in a declaration that holds it; CONTEXT is
# the declarations above, but the one named (a scenario has one acceptance block).
FRAGMENTS = {
    "area": ("environment fragment_environment {\nSNIPPET\n}\n", None),
    "pose": ("environment fragment_environment {\n\tarea fragment_area {\nSNIPPET\n\t}\n}\n", None),
    "obstacle": ("environment fragment_environment {\nSNIPPET\n}\n", None),
    "subtask": ("task fragment_task {\nSNIPPET\n}\n", None),
    "mission": (
        "scenario fragment_scenario in environment_name {\n"
        "\trobots {\n\t\trobot1: robot_type_name starts at pose_name\n\t}\nSNIPPET\n}\n",
        None,
    ),
    "criterion": ("acceptance for scenario_name {\nSNIPPET\n}\n", "acceptance"),
}


def test_every_snippet_expands_to_a_valid_specification(tmp_path: Path) -> None:
    snippets = _snippets()
    assert set(snippets) == set(DECLARATIONS) | set(FRAGMENTS), (
        "put a new snippet in DECLARATIONS or FRAGMENTS"
    )
    specs = [tmp_path / "declarations.exsce"]
    specs[0].write_text("\n\n".join(snippets[name] for name in DECLARATIONS) + "\n")
    for name, (host, left_out) in FRAGMENTS.items():
        context = "\n\n".join(snippets[n] for n in DECLARATIONS if n != left_out)
        spec = tmp_path / f"{name}.exsce"
        spec.write_text(context + "\n\n" + host.replace("SNIPPET", snippets[name]))
        specs.append(spec)
    result = run_exscec("check", *map(str, specs), cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stderr.count(": ok (") == len(specs), result.stderr


# ---------------------------------------------------------------- package.json, language configuration


def test_package_json_contributes_the_language() -> None:
    manifest = json.loads((VSCODE / "package.json").read_text(encoding="utf-8"))
    contributes = manifest["contributes"]
    (language,) = contributes["languages"]
    assert (language["id"], language["extensions"]) == ("exsce", [".exsce"])
    (grammar,) = contributes["grammars"]
    assert grammar["scopeName"] == json.loads(GRAMMAR_JSON.read_text())["scopeName"] == "source.exsce"
    for path in (
        manifest["main"],
        language["configuration"],
        grammar["path"],
        contributes["snippets"][0]["path"],
    ):
        assert (VSCODE / path).is_file(), path
    settings = contributes["configuration"]["properties"]
    assert settings["exsce.server.command"]["default"] == "exscec"
    assert settings["exsce.server.args"]["default"] == ["lsp"]
    assert "exsce.trace.server" in settings
    assert manifest["activationEvents"] == ["onLanguage:exsce"]
    assert manifest["dependencies"].keys() == {"vscode-languageclient"}
    assert (VSCODE / "LICENSE").read_text() == (ROOT / "LICENSE").read_text()


def test_a_pose_id_is_one_word() -> None:
    config = json.loads((VSCODE / "language-configuration.json").read_text(encoding="utf-8"))
    word = re.compile(config["wordPattern"])
    assert word.findall("visit classroom_c025-w001 facing 0.9") == [
        "visit",
        "classroom_c025-w001",
        "facing",
        "0.9",
    ]
    assert word.findall("right_long_corridor-point-0") == ["right_long_corridor-point-0"]
    assert word.findall("a.pose.x - b.pose.x") == ["a", "pose", "x", "b", "pose", "x"]
    assert word.findall("at (1.5, -2.25)") == ["at", "1.5", "-2.25"]
    assert word.findall("classroom_c025-") == ["classroom_c025-"]  # still one word while it is typed
