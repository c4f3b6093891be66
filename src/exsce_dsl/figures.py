"""Writing matplotlib figures to files, the same way everywhere.

Figures are made with :class:`matplotlib.figure.Figure` directly, not pyplot:
no global backend or figure registry, so nothing leaks between calls and no
display is looked for.  Files are reproducible: SVG without a date and with a
fixed hash salt for its ids, PNG without a software stamp.  Text from data (ids,
topics, names) is drawn as written (:func:`plain`), never parsed as mathtext.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
from matplotlib.figure import Figure

from exsce_dsl.errors import ExsceError
from exsce_dsl.templating import comment_text

FORMATS = ("png", "svg")


def plain(text: str) -> str:
    """``text`` as matplotlib draws it literally: each ``$`` escaped, so that no part of it is
    read as mathtext (a topic named ``$x^^$`` would stop the drawing with a parse error), and on
    one line, without the control characters an SVG file may not hold."""
    return comment_text(text).replace("$", "\\$")


def save_figure(figure: Figure, path: Path, dpi: int = 110) -> None:
    """Write ``figure`` as PNG or SVG, by the suffix of ``path``."""
    kind = path.suffix.lower().lstrip(".")
    if kind not in FORMATS:
        raise ExsceError(f"{path}: an image is written as .png or .svg, not '{path.suffix or 'no suffix'}'")
    try:
        if kind == "svg":
            with matplotlib.rc_context({"svg.hashsalt": "exsce"}):
                figure.savefig(path, format="svg", metadata={"Date": None})
        else:
            figure.savefig(path, format="png", dpi=dpi, metadata={"Software": None})
    except OSError as exc:
        raise ExsceError(f"cannot write {path}: {exc.strerror}") from None
