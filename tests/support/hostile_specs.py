"""A small specification whose every string slot that reaches a generator is filled in by a test,
and what a generated file may hold: the calls its template writes, text only inside literals.

The slots: a metric's meaning, the text of a selection in its value, the topic it reads, a
robot's namespace, the title of an acceptance criterion, and the spec file's own name (which
the generated files' headers quote)."""

from __future__ import annotations

import ast
import io
import tokenize
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import yaml
from hypothesis import strategies as st

from exsce_dsl.lang.lexical import string_literal

PIECES = (
    "\n", "\r", "\r\n", "\t", "\v", "\f", "\0", "\x85", "\u2028", "\u2029", "\u202e", "\ufeff", "\uffff",
    "'", '"', "\\", "#", '"""', "'''", "{{", "}}", "{%", "%}", "{#", "</", "<!--", "-->", "]]>", "&", "<", ">",
    "--", "`", "$x^^$", "(", ")", ":", "\U0001f916", "__import__('os').system('true')", "x = 1",
)  # fmt: skip
HOSTILE = st.lists(st.one_of(st.sampled_from(PIECES), st.text(max_size=3)), min_size=1, max_size=8).map(
    "".join
)
"""Texts made of what breaks out of literals, comments and markup, in any order, and anything else."""

TEMPLATE = """\
robot type rover {
  base diff_drive
}

environment yard {
  area field {
    pose yard-a at (0.0, 0.0)
    pose yard-b at (5.0, 0.0)
    pose yard-d at (0.0, 8.0)
  }
}

metric frame_height for each robot {
  MEANING
  unit m
  reads tf: tf2_msgs/msg/TFMessage on TOPIC
  value max(tf.transforms[child_frame_id == SELECTION].transform.translation.z)
}

task round_1 {
  visit yard-b
}

task round_2 {
  visit yard-a
}

scenario yard_run in yard {
  robots {
    r1: rover namespace NAMESPACE starts at yard-a
    r2: rover starts at yard-d
  }
  mission yard_mission parallel {
    r1 does round_1
    r2 does round_2
  }
}

acceptance for yard_run {
  scenario TITLE {
    when yard_mission runs
    then each robot max_velocity stays below 1.0 m/s
     and each robot frame_height stays below 2.0 m
  }
}
"""

PLAIN = {
    "MEANING": "height of the robot's base frame",
    "TOPIC": "/{ns}/tf",
    "SELECTION": "base_link",
    "NAMESPACE": "r1",
    "TITLE": "stays low",
}
"""The slots filled in harmlessly: the specification checks and every target generates."""
SLOTS = (*PLAIN, "FILE")


def spec_text(**slots: str) -> str:
    """The template spec with its slots (all of :data:`PLAIN` unless given) as quoted strings."""
    text = TEMPLATE
    for slot, value in {**PLAIN, **slots}.items():
        text = text.replace(slot, string_literal(value))
    return text


def file_name(text: str) -> str:
    """``text`` made a file name that holds as much of it as a file system allows (no ``/``, no
    NUL, at most 200 bytes), ending in ``.exsce``."""
    kept = text.replace("/", "").replace("\0", "")
    while len(kept.encode("utf-8", "surrogatepass")) > 200:
        kept = kept[:-1]
    return f"{kept}.exsce"


def write_spec(folder: Path, slot: str, value: str) -> Path:
    """The template spec with ``value`` in ``slot`` (``FILE``: as the file's name), in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    if slot == "FILE":
        path = folder / file_name(value)
        path.write_text(spec_text(), encoding="utf-8")
    else:
        path = folder / "hostile.exsce"
        path.write_text(spec_text(**{slot: value}), encoding="utf-8")
    return path


def called_names(source: str) -> set[str]:
    """The dotted name of everything ``source`` calls (``core.prepare``, ``np.abs``...; a call of
    something that is not a name, such as ``f()()``, as ``<expression>``)."""
    called = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            called.add(_dotted(node.func))
    return called


def _dotted(node: ast.expr) -> str:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return f"{_dotted(node.value)}.{node.attr}"
    return "<expression>"


def names_outside_literals(source: str) -> set[str]:
    """Every name token of ``source`` (not inside a string literal or a comment)."""
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    return {t.string for t in tokens if t.type == tokenize.NAME}


def python_files(files: Mapping[str, str]) -> dict[str, str]:
    """The Python files of a generated file set: ``*.py`` and scripts with a Python shebang."""
    return {
        name: text
        for name, text in files.items()
        if name.endswith(".py") or (text.startswith("#!") and "python" in text.split("\n", 1)[0])
    }


def check_files_read_back(files: Mapping[str, str]) -> None:
    """Assert that every generated file reads back in its language: Python compiles, YAML and XML
    parse, and CMake's parentheses balance with each command on its lines."""
    for name, text in python_files(files).items():
        compile(text, name, "exec", dont_inherit=True)
    for name, text in files.items():
        if name.endswith((".yaml", ".yml")):
            yaml.safe_load(text)
        elif name.endswith((".xml", ".launch")):
            ET.fromstring(text)
        elif name.endswith("CMakeLists.txt"):
            assert cmake_commands(text) == CMAKE_COMMANDS, name


CMAKE_COMMANDS = [
    "cmake_minimum_required",
    "project",
    "find_package",
    "catkin_python_setup",
    "catkin_package",
    "catkin_install_python",
    "install",
]
"""The commands of the ROS 1 package's CMakeLists.txt, in order, as its template writes them."""


def cmake_commands(text: str) -> list[str]:
    """The commands of a CMake file, in order; an assertion error if its parentheses do not
    balance (comments left out: ``#`` to the end of a line, outside quotes)."""
    commands, depth, word = [], 0, ""
    for line in text.split("\n"):
        quoted = False
        for char in line:
            if char == '"':
                quoted = not quoted
            elif quoted:
                continue
            elif char == "#":
                break
            elif char == "(":
                if depth == 0:
                    commands.append(word.strip())
                depth += 1
            elif char == ")":
                depth -= 1
                assert depth >= 0, line
            if depth == 0 and char not in "()":
                word = word + char if (char.isalnum() or char == "_") else ""
            elif char == ")" and depth == 0:
                word = ""
        assert not quoted, line
        word = ""
    assert depth == 0
    return commands
