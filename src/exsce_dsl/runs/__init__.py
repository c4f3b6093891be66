"""Runs: bag files in, metrics and run provenance out."""
