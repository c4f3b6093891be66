"""Parse trees to the semantic model: every reference resolved, every error reported at its place.

``specification`` builds a whole specification (``load_spec``, ``analyse``) with a builder per
declaration kind; the other modules build one part each or check a whole scenario.
"""
