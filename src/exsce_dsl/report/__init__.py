"""The HTML report of a store: scenarios and their lineage, runs, verdicts, metrics, paths, similarity.

:mod:`.contents` reads what to show from the store, :mod:`.plots` draws the
figures with matplotlib, and :mod:`.html` writes the pages.
"""
