"""Occupancy maps in map_server format, written for a test."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def write_map(
    folder: Path,
    name: str = "map",
    size: int = 100,
    occupied: tuple[int, int, int, int] | None = None,
) -> Path:
    """A map_server map of ``size``² cells of 5 cm, origin (0, 0); ``occupied`` = (x0, y0, x1, y1) cells."""
    grid = np.full((size, size), 254, dtype=np.uint8)
    if occupied is not None:
        x0, y0, x1, y1 = occupied
        grid[size - y1 : size - y0, x0:x1] = 0  # rows count from the top
    (folder / f"{name}.pgm").write_bytes(f"P5\n{size} {size}\n255\n".encode() + grid.tobytes())
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return folder / f"{name}.yaml"
