"""Generated files read back in their own language before they are written (and after, on demand).

A template or a filter that let a user's text through would show here first:
Python must compile, YAML and ``setup.cfg`` parse, XML parse, and a CMake file's
parentheses balance.  A file that does not is an error naming it (and its line),
never a file left for a build to trip over.
"""

from __future__ import annotations

import configparser
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path, PurePosixPath

import yaml

from exsce_dsl.errors import GenerationError, SourceLocation


def _failed(
    name: str, language: str, why: str, line: int | None = None, column: int | None = None
) -> GenerationError:
    location = SourceLocation(name, line, column or 1) if line else None
    return GenerationError(
        f"the generated {language} file {name} does not read back: {why}; please report this", location
    )


def _language(name: str, text: str) -> str | None:
    path = PurePosixPath(name)
    if path.suffix == ".py" or (
        not path.suffix and text.startswith("#!") and "python" in text.split("\n", 1)[0]
    ):
        return "Python"
    return {
        ".yaml": "YAML",
        ".yml": "YAML",
        ".xml": "XML",
        ".launch": "XML",
        ".cfg": "INI",
    }.get(path.suffix, "CMake" if path.name == "CMakeLists.txt" else None)


def check_generated(name: str, text: str) -> None:
    """Raise a :class:`GenerationError` (at the line, when known) unless ``text``, the content of
    the generated file ``name``, reads back in its language; other files pass."""
    language = _language(name, text)
    try:
        if language == "Python":
            compile(text, name, "exec", dont_inherit=True)
        elif language == "YAML":
            yaml.safe_load(text)
        elif language == "XML":
            ET.fromstring(text)
        elif language == "INI":
            configparser.ConfigParser(interpolation=None).read_string(text, source=name)
        elif language == "CMake":
            _check_cmake(name, text)
    except SyntaxError as exc:  # compile's, and ET.ParseError (a SyntaxError too)
        raise _failed(name, language or "", exc.msg, exc.lineno, exc.offset) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        raise _failed(name, "YAML", str(exc).splitlines()[0], line) from None
    except (ValueError, configparser.Error) as exc:  # a NUL in Python source; a bad INI line
        raise _failed(name, language or "", str(exc).splitlines()[0]) from None


def _check_cmake(name: str, text: str) -> None:
    """Parentheses balance on each command, quotes close, nothing follows a comment's line."""
    depth = 0
    for number, line in enumerate(text.split("\n"), start=1):
        quoted = False
        for column, char in enumerate(line, start=1):
            if char == '"':
                quoted = not quoted
            elif not quoted and char == "#":
                break
            elif not quoted and char in "()":
                depth += 1 if char == "(" else -1
                if depth < 0:
                    raise _failed(name, "CMake", "a ')' closes nothing", number, column)
        if quoted:
            raise _failed(name, "CMake", "a quote is not closed on its line", number)
    if depth:
        raise _failed(name, "CMake", "a '(' is never closed")


def check_written(paths: Iterable[Path]) -> None:
    """:func:`check_generated` for files already written (the error names each by its path)."""
    for path in paths:
        check_generated(str(path), path.read_text(encoding="utf-8"))
