"""scenario_execution's own OSC2 parser, from the venv scripts/install-scenario-execution makes
(scenario-execution 1.8.0 from PyPI, with tools/osc2-declarations for ``osc.ros``/``osc.nav2``).

Missing, it is a failure that says how to install it, not a skip: CI installs it (.ci/run)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

VERSION = "1.8.0"
INSTALL = "sh scripts/install-scenario-execution"


def venv() -> Path:
    """Where the install script puts it: ``$EXSCE_SCENARIO_EXECUTION``, else the user's cache."""
    configured = os.environ.get("EXSCE_SCENARIO_EXECUTION")
    if configured:
        return Path(configured)
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return cache / "exsce-scenario-execution" / VERSION


def executable(name: str) -> Path:
    """A program of the venv; the test fails, naming the install command, when it is missing."""
    path = venv() / "bin" / name
    if not path.exists():
        pytest.fail(f"scenario_execution's parser is not installed at {venv()}: run `{INSTALL}`")
    return path


def dry_run(osc_file: Path) -> subprocess.CompletedProcess[str]:
    """``scenario_execution -n FILE``: parse, resolve and build the tree, execute nothing."""
    return subprocess.run(
        [str(executable("scenario_execution")), "-n", osc_file.name],
        cwd=osc_file.parent,
        capture_output=True,
        text=True,
        timeout=120,
    )


_READER = """
import json, sys
from antlr4 import InputStream
from scenario_execution.osc2_parsing.OpenSCENARIO2Lexer import OpenSCENARIO2Lexer
from scenario_execution.model.types import StringLiteral
asked = json.load(sys.stdin)
def tokens(text):
    lexer = OpenSCENARIO2Lexer(InputStream(text))
    found = []
    while (token := lexer.nextToken()).type != -1:
        found.append([token.type, token.text])
    return found
def literal(text):
    found = tokens(text)
    assert [t[0] for t in found] == [OpenSCENARIO2Lexer.StringLiteral], found
    return StringLiteral(found[0][1]).value
print(json.dumps({"tokens": [tokens(t) for t in asked["texts"]], "literals": [literal(t) for t in asked["literals"]]}))
"""


def read_with_scenario_execution(
    texts: list[str], literals: list[str]
) -> tuple[list[list[tuple[int, str]]], list[str]]:
    """scenario_execution's own lexer on each of ``texts`` (its tokens: type and text, comments
    skipped), and each of ``literals`` read as its parser reads a string literal."""
    done = subprocess.run(
        [str(executable("python")), "-c", _READER],
        input=json.dumps({"texts": texts, "literals": literals}),
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    answer = json.loads(done.stdout)
    return answer["tokens"], answer["literals"]
