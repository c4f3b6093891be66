"""Input transformations of scenarios and their chaining: pure functions, model in, model out."""
