"""The examples of README.md and every page of docs/ hold (issue 33, item 9).

- An ```` ```exsce ```` block checks clean as a file of its own, written beside the shipped
  example (so that its imports resolve); one marked ``from=PATH`` is an excerpt of that shipped
  file: its lines appear there, in order (``...`` stands for what is left out).
- Every ``exscec`` line of a ```` ```sh ```` block names a command that exists, with options
  it takes: click parses it, as the shell would pass it.
- The README's "Start from your bag" block runs as written on a bag the test writes.

docs/tutorial.md (tests/cli/test_tutorial.py), docs/python.md and the README's Python block
(tests/api/test_python_api.py) and every ``--help`` example (tests/cli/test_help_examples_*.py)
run as written in their own tests.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import click
import pytest

from exsce_dsl.api import check
from exsce_dsl.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
EXAMPLES = ROOT / "examples"


@dataclass(frozen=True)
class Block:
    page: Path
    line: int
    language: str
    info: dict[str, str]
    text: str

    def __str__(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def _blocks(page: Path) -> list[Block]:
    found = []
    whole = page.read_text(encoding="utf-8")
    for match in re.finditer(r"^([ \t]*)```(\w*)([^\n]*)\n(.*?)^\1```", whole, flags=re.S | re.M):
        indent = len(match.group(1))
        text = "\n".join(line[indent:] for line in match.group(4).splitlines())
        info = dict(word.split("=", 1) for word in match.group(3).split() if "=" in word)
        line = whole[: match.start()].count("\n") + 1
        found.append(Block(page, line, match.group(2), info, text))
    return found


BLOCKS = [b for page in PAGES for b in _blocks(page)]


def _of(language: str, excerpt: bool | None = None) -> list[Block]:
    return [
        b for b in BLOCKS
        if b.language == language and (excerpt is None or ("from" in b.info) == excerpt)
    ]


def _significant(text: str) -> list[str]:
    """The lines that say something: no comments, blank lines or ``...``."""
    lines = (re.sub(r"\s*//.*$", "", line).strip() for line in text.splitlines())
    return [line for line in lines if line and line != "..."]


def test_the_pages_have_examples_of_each_kind() -> None:
    """The rules below see the blocks (a fence the parser missed would pass unseen)."""
    assert len(_of("exsce", excerpt=True)) >= 6 and len(_of("exsce", excerpt=False)) >= 2
    assert len(_exscec_lines()) >= 30


@pytest.mark.parametrize("block", _of("exsce", excerpt=True), ids=str)
def test_an_excerpt_is_in_its_shipped_file_in_order(block: Block) -> None:
    source = _significant((ROOT / block.info["from"]).read_text(encoding="utf-8"))
    at = 0
    for line in _significant(block.text):
        assert line in source[at:], f"{block}: '{line}' is not in {block.info['from']} (after line {at})"
        at = source.index(line, at) + 1


@pytest.mark.parametrize("block", _of("exsce", excerpt=False), ids=str)
def test_a_whole_example_checks_clean(block: Block, tmp_path: Path) -> None:
    shutil.copytree(EXAMPLES / "brsu_building_c", tmp_path / "example")
    path = tmp_path / "example" / "docs_example.exsce"
    path.write_text(block.text, encoding="utf-8")
    found = check(path)
    assert found.ok, f"{block}:\n" + "\n".join(str(d) for d in found.diagnostics)


def _exscec_lines() -> list[tuple[Block, list[str]]]:
    lines = []
    for block in _of("sh"):
        for line in block.text.splitlines():
            words = shlex.split(line, comments=True)
            if words and words[0] == "exscec":
                lines.append((block, words[1:]))
    return lines


def _resolve(words: list[str]) -> tuple[click.Command, list[str], str]:
    """The (sub)command the words name, the words left for it, and its name."""
    command: click.Command = main
    name = "exscec"
    while isinstance(command, click.Group) and words and not words[0].startswith("-"):
        context = click.Context(command, info_name=name)
        found = command.get_command(context, words[0])
        assert found is not None, f"no command '{name} {words[0]}'"
        command, name, words = found, f"{name} {words[0]}", words[1:]
    return command, words, name


@pytest.mark.parametrize(
    "block, words", _exscec_lines(), ids=[f"{b}:{' '.join(w[:2])}" for b, w in _exscec_lines()]
)
def test_every_exscec_line_parses(block: Block, words: list[str]) -> None:
    leading = [w for w in words[:1] if w.startswith("--")]  # options of the group (--debug)
    command, rest, name = _resolve(words[len(leading):])
    context = click.Context(command, info_name=name, **command.context_settings)
    try:  # the options exist and take what is given (files need not exist here)
        values, _, _ = command.make_parser(context).parse_args(list(rest))
    except click.UsageError as exc:
        raise AssertionError(f"{block}: exscec {' '.join(words)}: {exc.format_message()}") from exc
    for param in command.params:
        given = values.get(param.name)
        if isinstance(param.type, click.Choice) and given is not None:
            for value in given if isinstance(given, (list, tuple)) else [given]:
                assert value in param.type.choices, f"{block}: {param.name}={value!r} is not one of {param.type.choices}"


def test_the_readmes_start_from_your_bag_runs_as_written(tmp_path: Path) -> None:
    """The four commands on a Nav2 run's bag the executor writes, named as the README names it."""
    from exsce_dsl.lang import load_spec
    from exsce_dsl.sim.run import simulate

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Start from your bag"):]
    section = section[: section.index("\n## ", 3)]  # up to the next section
    [block] = [b for b in _blocks(ROOT / "README.md") if b.language == "sh" and b.text in section]
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_a.exsce")
    [run] = simulate(spec.scenario(None), tmp_path / "sim", fmt="ros1", seed=3, convention="nav2")
    shutil.copy(run.bag, tmp_path / "run1.bag")
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("EXSCE_STORE", None)
    for line in block.text.splitlines():
        done = subprocess.run(shlex.split(line, comments=True), cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
        assert "Traceback" not in done.stderr
    assert (tmp_path / "report" / "index.html").is_file()


def _anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_link_between_pages_finds_its_page_and_heading(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    for target, anchor in re.findall(r"\]\(([^)#\s:]*\.md|)(?:#([^)\s]+))?\)", text):
        linked = (page.parent / target) if target else page
        assert linked.is_file(), f"{page.name}: no page {target}"
        if anchor:
            headings = re.findall(r"^#+ (.+)$", linked.read_text(encoding="utf-8"), flags=re.M)
            assert anchor in {_anchor(h) for h in headings}, f"{page.name}: no heading #{anchor} in {linked.name}"


def test_the_readme_is_short_and_starts_where_users_start() -> None:
    """Stumble: the README was 830 lines and "Your robot's bags" began at line 479."""
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 300
    first_screen = "\n".join(lines[:50])
    assert ".venv/bin/exscec demo" in first_screen and ".venv/bin/python -m pytest" in first_screen
    assert "## Start from your bag" in first_screen
    linked = set(re.findall(r"\]\(docs/(\w+)\.md", "\n".join(lines)))
    assert linked == {p.stem for p in (ROOT / "docs").glob("*.md")}, "every docs page is in the index"


def test_the_language_page_lists_every_function_with_its_arguments() -> None:
    """Stumble: the README never said how many arguments path_length takes, which plane the
    built-in distance uses, or that a metric of each robot names its topics with {ns}."""
    from exsce_dsl.model.expressions import CONDITION_AGGREGATES, FUNCTIONS, WINDOW_VALUES

    page = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    section = page[page.index("## Every function"):]
    rows = re.findall(r"^\| (.+?) \| (.+?) \| (.+?) \|$", section, flags=re.M)
    named = {name for cell, _, _ in rows for name in re.findall(r"`(\w+)[( ]", cell + " ")}
    missing = (set(FUNCTIONS) | set(CONDITION_AGGREGATES)) - named
    assert not missing, f"functions without a row: {sorted(missing)}"
    assert set(WINDOW_VALUES) <= set(re.findall(r"`(\w+)`", section))
    [path_length] = [args for cell, args, _ in rows if "path_length" in cell]
    assert "two or three" in path_length
    assert "x-y plane" in section and "{ns}" in section
