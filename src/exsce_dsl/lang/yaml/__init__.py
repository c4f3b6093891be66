"""The method's YAML files: scenario and task files in and out, oracle files both ways."""
