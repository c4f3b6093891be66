"""Oracles: from acceptance criteria and stored runs to verdicts on runs."""
