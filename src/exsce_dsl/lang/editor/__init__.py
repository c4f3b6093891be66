"""What only the language server uses: the analysis per keystroke, symbols, continuations."""
