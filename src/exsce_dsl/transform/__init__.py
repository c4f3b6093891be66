"""Input transformations of scenarios and their chaining: pure functions, model in, model out."""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.transform.applied import Applied
    from exsce_dsl.transform.derivation import Derived, Request, derive, derived_document
    from exsce_dsl.transform.records import (
        Arguments,
        Group,
        Part,
        Slot,
        Transformation,
        Word,
        phrase_parts,
        shown_phrase,
        variants,
    )
    from exsce_dsl.transform.transformations import TRANSFORMATIONS
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
