"""The semantic model back to ``.exsce`` text (round-trip stable), and acceptance criteria as Gherkin."""
