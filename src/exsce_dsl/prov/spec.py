"""The PROV of a scenario of a checked specification, as every way of compiling writes it.

``exscec compile``, ``textx generate --target provn`` (and the other PROV targets), the Python API
and the store all call :func:`compile_spec_scenario`, so a derived scenario comes with its
generation (how it was derived from its base) whichever way it was compiled.
"""

from __future__ import annotations

from prov.model import ProvDocument

from exsce_dsl.model import Scenario
from exsce_dsl.model.document import Specification
from exsce_dsl.prov.compile import compile_scenario
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE


def compile_spec_scenario(
    spec: Specification, scenario: Scenario | str | None = None, namespace: str = DEFAULT_NAMESPACE
) -> ProvDocument:
    """The bundles of one scenario of ``spec`` (its only one when ``scenario`` is None), and, for a
    derived scenario, the bundle of its generation."""
    chosen = scenario if isinstance(scenario, Scenario) else spec.scenario(scenario)
    document = compile_scenario(chosen, namespace)
    derived = next((d for d in spec.derived if d.id == chosen.id), None)
    if derived is not None and derived.derivation is not None:
        document.update(compile_derivation(derived.derivation, namespace))
    return document
