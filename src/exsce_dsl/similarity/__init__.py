"""Scenario similarity: the method's distances d1–d6 and hierarchical clustering."""
