"""Specification files in and out: formatting (``exscec fmt``), the method's YAML files
(``exscec import``, ``exscec export``) and generated code (``exscec generate``)."""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import ExportError
from exsce_dsl.model import Document


@dataclass(frozen=True)
class FormattedFile:
    """A specification file as it is and in canonical form."""

    path: str
    original: str
    formatted: str

    @property
    def changed(self) -> bool:
        return self.formatted != self.original

    def diff(self) -> str:
        """What formatting changes, as a unified diff."""
        return "".join(
            difflib.unified_diff(
                self.original.splitlines(keepends=True),
                self.formatted.splitlines(keepends=True),
                fromfile=self.path,
                tofile=f"{self.path} (formatted)",
            )
        )

    def write(self) -> None:
        """Replace the file with its canonical form."""
        Path(self.path).write_text(self.formatted, encoding="utf-8")


def format_file(path: str | Path) -> FormattedFile:
    """``exscec fmt``: a checked specification file in canonical form, its comments kept before
    the element that follows them (a file with errors is a SpecError: only a checked model is
    formatted).  Nothing is written: see :meth:`FormattedFile.write`."""
    from exsce_dsl.lang import comments, display_path, format_spec_document, load_spec
    from exsce_dsl.textfiles import read_text

    spec = load_spec(path)
    original = read_text(path, "specification")
    shown = display_path(path)
    return FormattedFile(str(path), original, format_spec_document(spec, shown, comments(original, shown)))


def is_oracle_file(path: str | Path) -> bool:
    """Whether a YAML file of the method holds oracles (a baseline or metamorphic section)."""
    from exsce_dsl.lang import is_oracle_yaml

    return is_oracle_yaml(Path(path))


def import_scenario_file(
    yaml_file: str | Path, out_dir: str | Path, task_dirs: Sequence[str | Path] = (), *, force: bool = False
) -> list[Path]:
    """``exscec import SCENARIO.yaml``: the method's scenario and the task files it names (found
    below ``task_dirs`` and its own folder) as ``.exsce`` files in ``out_dir``; an existing file
    is replaced only with ``force``."""
    from exsce_dsl.lang import import_scenario_yaml, write_documents

    documents = import_scenario_yaml(Path(yaml_file), [Path(d) for d in task_dirs])
    return write_documents(documents, Path(out_dir), overwrite=force)


def import_oracle_file(
    yaml_file: str | Path, spec: str | Path, out_dir: str | Path | None = None, *, force: bool = False
) -> str | list[Path]:
    """``exscec import ORACLES.yaml --spec SPEC``: the method's oracle file as the acceptance
    criteria of its scenario (declared in ``spec``): their text, or with ``out_dir`` the file
    ``<scenario>_acceptance.exsce`` written there (importing ``spec``)."""
    from exsce_dsl.lang import (
        acceptance_document,
        format_document,
        import_oracles,
        load_spec,
        write_documents,
    )

    acceptance = import_oracles(Path(yaml_file), load_spec(spec))
    if out_dir is None:
        return format_document(Document("", (), (acceptance,)), {})
    document = acceptance_document(acceptance, Path(spec), Path(out_dir))
    return write_documents([document], Path(out_dir), overwrite=force)


EXPORTS = ("yaml", "oracle-yaml", "gherkin", "osc2")
"""What :func:`export_spec` writes: the method's scenario and task files, its oracle file,
Gherkin features, or an OSC2 scenario for scenario_execution."""


def export_spec(
    spec: str | Path, target: str, out_dir: str | Path, scenario: str | None = None
) -> list[Path]:
    """``exscec export --to TARGET``: a scenario of ``spec`` as one of :data:`EXPORTS`, in
    ``out_dir`` (for ``osc2``, a ``.osc`` file may be named instead); the files written."""
    from exsce_dsl.lang import export_gherkin, export_oracle_file, export_yaml, load_spec

    loaded = load_spec(spec)
    if target == "osc2":
        from exsce_dsl.codegen.osc2 import export_osc2

        return export_osc2(loaded, Path(out_dir), scenario)
    if target == "gherkin":
        return export_gherkin(loaded, Path(out_dir), scenario)
    if target == "oracle-yaml":
        chosen = loaded.scenario(scenario)
        acceptance = loaded.acceptance_of(chosen.id)
        if acceptance is None:
            raise ExportError(f"scenario '{chosen.id}' has no acceptance criteria to write as oracles")
        return [export_oracle_file(acceptance, chosen, Path(out_dir))]
    return export_yaml(loaded.scenario(scenario), Path(out_dir))


def generate(
    target: str, spec: str | Path, out_dir: str | Path, scenario: str | None = None, *, force: bool = False
) -> list[Path]:
    """``exscec generate TARGET``: the files of a code generator of
    :data:`~exsce_dsl.codegen.targets.TARGETS` for a scenario of ``spec``, below ``out_dir``; a
    file that exists is replaced only with ``force``."""
    from exsce_dsl.codegen.targets import TARGETS
    from exsce_dsl.lang import load_spec

    return TARGETS[target].generate(load_spec(spec), scenario, Path(out_dir), force)
