"""Step 3 of a run: path segments (the dispatcher's, the stack's goals, arrival, the whole run)."""
