"""textX generators for the code generation targets, as entry points.

``textx generate scenario.exsce --target dispatcher-config -o DIR`` runs the
same generator as ``exscec generate dispatcher-config``; ``--scenario ID``
picks a scenario when the file declares several, ``--overwrite`` replaces
files that exist.  Without ``-o`` the files go to ``<spec>-<target>/``
beside the spec.  One generator per entry of :data:`TARGETS`; a test checks
that each is here and registered in ``pyproject.toml``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from textx import TextXSemanticError, generator

from exsce_dsl.codegen.targets import TARGETS
from exsce_dsl.errors import ExsceError


def _target_generator(name: str) -> Any:
    """A textX generator ``exsce -> name`` that runs ``TARGETS[name]`` (imported when it runs)."""
    target = TARGETS[name]

    def generate(
        metamodel: Any, model: Any, output_path: str | None, overwrite: bool, debug: bool, **custom_args: Any
    ) -> None:
        from exsce_dsl.lang import load_spec

        scenario_id = custom_args.pop("scenario", None)
        if custom_args:
            raise TextXSemanticError(
                f"unknown argument(s) {', '.join('--' + k for k in custom_args)}; "
                f"the {name} generator takes --scenario ID"
            )
        source = Path(model._tx_filename)
        out_dir = Path(output_path) if output_path else source.parent / f"{source.stem}-{name}"
        try:
            target.generate(load_spec(source), scenario_id, out_dir, overwrite)
        except ExsceError as exc:
            loc = exc.location
            raise TextXSemanticError(
                exc.message,
                line=loc.line if loc else None,
                col=loc.column if loc else None,
                filename=loc.file if loc else None,
            ) from None

    generate.__doc__ = f"exsce scenario to {target.description}"
    generate.__name__ = f"{name.replace('-', '_')}_generator"
    return generator("exsce", name)(generate)


monitors_generator = _target_generator("monitors")
dispatcher_config_generator = _target_generator("dispatcher-config")
ros1_monitor_generator = _target_generator("ros1-monitor")
ros2_monitor_generator = _target_generator("ros2-monitor")
