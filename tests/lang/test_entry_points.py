"""``exsce_dsl.lang`` names the entry points other layers use, each from the module that defines it."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

import exsce_dsl.lang as lang
from exsce_dsl.faces import face_names

WHERE = face_names(Path(lang.__file__).read_text(encoding="utf-8"))
"""The face's one list: each entry point and its module (the imports under ``if TYPE_CHECKING:``)."""


@pytest.mark.parametrize("name", lang.__all__)
def test_each_entry_point_is_the_name_its_module_defines(name: str) -> None:
    module = importlib.import_module(WHERE[name])
    assert getattr(lang, name) is getattr(module, name)


def test_every_entry_point_is_listed_once() -> None:
    assert lang.__all__ == list(WHERE) and len(set(lang.__all__)) == len(lang.__all__)


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no attribute 'load'"):
        lang.load  # noqa: B018


def test_importing_the_language_imports_no_part_of_it() -> None:
    """One entry point (the cached specification) must not pull textX and every part in."""
    code = "import json, sys\nimport exsce_dsl.lang\nprint(json.dumps(sorted(sys.modules)))"
    found = set(
        json.loads(
            subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
        )
    )
    assert "textx" not in found and not any(m.startswith("exsce_dsl.lang.") for m in found)
