"""Step 4 of a run: the monitors, over signals and segments."""
