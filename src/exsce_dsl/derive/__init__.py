"""Deriving scenarios: input transformations on the semantic model, and their record."""
