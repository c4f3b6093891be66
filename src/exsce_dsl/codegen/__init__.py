"""Code generators: Jinja2 templates (top-level ``templates/``) rendered from the semantic model."""
