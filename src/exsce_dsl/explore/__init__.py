"""Exploring derivations of a base scenario: the applicable single steps, seeded draws of
compositions without duplicates, and shrinking a failing derivation."""
