"""Library text never names the command line's flags (issue 49, item 3).

Outside ``src/exsce_dsl/cli/``, the package says what to do about a problem in words: a remedy of
:mod:`exsce_dsl.remedies`, carried by an :class:`~exsce_dsl.errors.ExsceError` or a
:class:`~exsce_dsl.errors.Remedied` text; the command line says it with its options
(``cli.common.REMEDIES``).  So no string literal of those modules (f-strings' literal parts
included; docstrings and comments aside, which may name commands) holds a flag (``--replace``)
or an ``exscec`` invocation.  :data:`ALLOWED` names the few that must, and says why each may."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import Remedied
from exsce_dsl.remedies import REPLACE_THE_RUN

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl"

FLAG_TEXT = re.compile(r"(?<![\w-])--[a-z][a-z-]+|\bexscec ")
"""A long option (``--msg-path``) or an invocation of the command line (``exscec verify``)."""

WHY: dict[str, str] = {
    "the demo's script: the exscec commands it shows, runs and asks the user to type": "api/demo.py:*",
    "text generated into files for users, which names the command that made them: the docs table of "
    "transformations (docs/deriving.md), the comments of a drafted .exsce file, the generated ROS "
    "monitor package's header and README, the generated monitor code's header": (
        "transform/records.py:exscec runs/spec_draft.py:* codegen/ros_monitor.py:exscec "
        "monitor_code.py:exscec"
    ),
    "the command line of another program exsce starts, with its own options, not exscec's: "
    "exsce's ROS 1 dispatcher node": "execute/ros1/navigator.py:* execute/ros1/nodes/dispatcher_node.py:*",
    "generators registered with textX, whose own command line (`textx generate`) has these options": (
        "codegen/registration.py:--scenario rdf/registration.py:--overwrite"
    ),
    "help text, like docs/, telling the equivalent command: the language server's hover text, the "
    "MCP tools' descriptions": (
        "lsp/keywords.py:* mcp_server/check_tool.py:exscec mcp_server/library_tools.py:exscec "
        "mcp_server/store_tools.py:exscec"
    ),
    "the name of a running server (exscec serve, exscec mcp), not an invocation to type: the prefix "
    "of its log lines, the endpoint's HTTP authentication realm, the process holding a store": (
        "mcp_server/server.py:exscec endpoint/server.py:exscec endpoint/worker.py:exscec "
        "endpoint/app.py:exscec api/store.py:exscec store/open.py:exscec"
    ),
    "an executor's name is part of a campaign's identity (hashed into campaign_<digest>, recorded in "
    "its plan): new words would rename every campaign": "explore/executors.py:--fault explore/ros1_executor.py:*",
}
"""Why some literals may name the command line → the places: ``module:text`` (the module below
``src/exsce_dsl``; the text found, ``*`` for any)."""

ALLOWED: dict[tuple[str, str], str] = {
    (module, text): why
    for why, places in WHY.items()
    for module, _, text in (p.partition(":") for p in places.split())
}
"""(module, text or ``*``) → why it may name it."""


def _docstrings(tree: ast.Module) -> set[int]:
    """The ids of the string constants that are docstrings: a module's, class's or function's, and
    the attribute docstrings (any string alone as a statement)."""
    return {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr)
        and isinstance(node.value, ast.Constant)
        and isinstance(node.value.value, str)
    }


def _flag_texts(path: Path) -> list[tuple[int, str, str]]:
    """(line, what was found, the literal) for each flag or invocation in ``path``'s literals."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = _docstrings(tree)
    return [
        (node.lineno, found.group(0).strip(), node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs
        for found in FLAG_TEXT.finditer(node.value)
    ]


def _library_modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if p.relative_to(PACKAGE).parts[0] != "cli")


def test_no_library_literal_names_a_cli_flag() -> None:
    found = []
    for path in _library_modules():
        module = path.relative_to(PACKAGE).as_posix()
        for line, text, literal in _flag_texts(path):
            if (module, text) not in ALLOWED and (module, "*") not in ALLOWED:
                found.append(f"src/exsce_dsl/{module}:{line}: {text!r} in {literal[:80]!r}")
    assert not found, "library text naming the command line (say a remedy instead):\n" + "\n".join(found)


def test_each_allowance_is_still_needed() -> None:
    """An allowance whose text has gone is taken out, so the list says only what is true."""
    used = set()
    for path in _library_modules():
        module = path.relative_to(PACKAGE).as_posix()
        texts = {text for _, text, _ in _flag_texts(path)}
        used |= {(module, text) for text in texts} | ({(module, "*")} if texts else set())
    assert not set(ALLOWED) - used, f"allowances for text no longer there: {sorted(set(ALLOWED) - used)}"


def test_the_scan_sees_f_strings_and_skips_docstrings(tmp_path: Path) -> None:
    source = tmp_path / "sample.py"
    source.write_text(
        '"""Run ``exscec check --strict``."""\n'
        "def f(n):\n"
        '    """Like `exscec verify --junit`."""\n'
        '    return f"{n} found; pass --replace"\n'
        'SAID = "exscec serve"\n'
    )
    assert sorted((line, text) for line, text, _ in _flag_texts(source)) == [(4, "--replace"), (5, "exscec")]


def test_the_remedies_said_in_words_and_with_the_options() -> None:
    """A remedy reads in words from the library and with its option on the command line."""
    said = Remedied("a.bag: already a run of scenario 's' (run 1)", REPLACE_THE_RUN)
    assert not FLAG_TEXT.search(said.said())
    assert said.said(REMEDIES) == (
        "a.bag: already a run of scenario 's' (run 1); pass --replace to analyse it again under this spec"
    )


def test_every_remedy_has_the_command_line_s_wording() -> None:
    """Every remedy the library can give is said by the command line too (with its option, where
    one does it): a remedy without a wording would reach the user in words only."""
    import exsce_dsl.remedies as remedies

    defined = {value for name, value in vars(remedies).items() if name.isupper() and isinstance(value, str)}
    # said in words on purpose: inside a BagError's text that ingest composes, and to an MCP client
    words_only = {remedies.DEFINE_THE_BAGS_TYPE, remedies.LONGER_TIME_LIMIT}
    without = defined - set(REMEDIES) - words_only
    assert not without, f"remedies the command line does not word: {sorted(without)}"
