"""Deriving scenarios: input transformations on the semantic model, and their record."""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.derive.derive_scenario import DerivedSpec, StoredDerivation, add_derivation, derive_spec
    from exsce_dsl.derive.expect import (
        RELATIVE_TOLERANCE,
        SUMMED,
        ExpectedValue,
        expected_metric,
        learning_runs,
    )
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
