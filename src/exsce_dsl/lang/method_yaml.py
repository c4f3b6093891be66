"""The method's YAML format (scenario and task files): import and export.

Import lives in :mod:`exsce_dsl.lang.yaml_import`, export in
:mod:`exsce_dsl.lang.yaml_export`; this module is the one to import from.
"""

from exsce_dsl.lang.yaml_export import export_yaml, scenario_to_yaml, task_to_yaml
from exsce_dsl.lang.yaml_import import import_scenario_yaml, import_task_yaml

__all__ = [
    "export_yaml",
    "import_scenario_yaml",
    "import_task_yaml",
    "scenario_to_yaml",
    "task_to_yaml",
]
