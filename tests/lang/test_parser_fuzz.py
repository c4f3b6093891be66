"""Random text and random mutations of the examples: parsing and checking raise ExsceError or nothing.

A crash (any other exception) would reach a user as "internal error" (or, in
the language server, a dead document); hypothesis shrinks any it finds to a
small text to add to the error matrix.
"""

from __future__ import annotations

from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import analyse, load_spec
from exsce_dsl.prov import compile_scenario

from tests.support.paths import EXAMPLES

FOLDER = EXAMPLES / "brsu_building_c"
FILES = sorted(FOLDER.rglob("*.exsce"))
TEXTS = {path: path.read_text(encoding="utf-8") for path in FILES}
WORDS = sorted({w for text in TEXTS.values() for w in text.replace("{", " ").replace("}", " ").split()})
ROOT_SPEC = FOLDER / "scenario_c.exsce"


def _mutate(text: str, edits: list[tuple[int, int, int, str]]) -> str:
    """Apply edits (kind, position, length, word): delete, duplicate, insert a word, move a slice."""
    for kind, where, length, word in edits:
        at = where % (len(text) + 1)
        end = min(len(text), at + length)
        if kind == 0:
            text = text[:at] + text[end:]
        elif kind == 1:
            text = text[:end] + text[at:end] + text[end:]
        elif kind == 2:
            text = text[:at] + f" {word} " + text[at:]
        else:
            piece = text[at:end]
            rest = text[:at] + text[end:]
            to = (where * 7 + length) % (len(rest) + 1)
            text = rest[:to] + piece + rest[to:]
    return text


def _check(path: Path, text: str) -> None:
    overlay = {str(path): text}
    try:
        spec = load_spec(ROOT_SPEC, overlay)
    except ExsceError:
        return
    for scenario in spec.scenarios:  # what still checks clean must compile
        try:
            compile_scenario(scenario)
        except ExsceError:
            pass


edit = st.tuples(st.integers(0, 3), st.integers(0, 10_000), st.integers(0, 60), st.sampled_from(WORDS))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(FILES), st.lists(edit, min_size=1, max_size=4))
def test_mutated_examples_give_exsce_errors_only(path: Path, edits: list[tuple[int, int, int, str]]) -> None:
    _check(path, _mutate(TEXTS[path], edits))


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet=st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=300))
def test_random_text_gives_exsce_errors_only(text: str) -> None:
    _check(ROOT_SPEC, text)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.sampled_from([*WORDS, "{", "}", "(", ")", ",", "\\n", '"x"', "1.5", "-3"]), max_size=40))
def test_sequences_of_the_languages_own_words_give_exsce_errors_only(words: list[str]) -> None:
    text = " ".join(w.replace("\\\\n", "\\n") for w in words)
    analysis = analyse(ROOT_SPEC, {str(ROOT_SPEC): text})  # the editor's path: diagnostics, never a raise
    assert all(d.message for d in analysis.diagnostics)


def test_the_fuzzed_text_is_what_gets_parsed() -> None:
    """The overlay reaches the parser for the root and for an imported file (else the above test nothing)."""
    for path in (ROOT_SPEC, FOLDER / "environment.exsce"):
        try:
            load_spec(ROOT_SPEC, {str(path): "scenario {"})
        except ExsceError as exc:
            assert path.name in str(exc)
        else:
            raise AssertionError(f"the overlay of {path.name} was not parsed")
