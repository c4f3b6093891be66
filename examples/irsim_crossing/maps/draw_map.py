"""Draw crossing.pgm and crossing.yaml: three rooms in a row, joined by corridors 1.2 m wide.

    python examples/irsim_crossing/maps/draw_map.py   # writes the two files beside this one

The map is 34 m x 10 m at 0.05 m a cell, its origin at (0, 0).  The west room spans x 0.5-9.5 m,
the hall x 12.5-21.5 m and the east room x 24.5-33.5 m (all y 0.5-9.5 m); between each two, a
wall 3 m thick with a corridor through it at y 4.4-5.6 m.  Free cells are white (254), walls black (0), as map_server reads them.
"""

from pathlib import Path

import numpy as np

RESOLUTION = 0.05
WIDTH, HEIGHT = 34.0, 10.0


def cells(metres: float) -> int:
    return int(round(metres / RESOLUTION))


def draw() -> np.ndarray:
    rows, cols = cells(HEIGHT), cells(WIDTH)
    free = np.zeros((rows, cols), dtype=bool)  # row 0 = y 0 here; flipped when written

    def open_box(x0: float, x1: float, y0: float, y1: float) -> None:
        free[cells(y0) : cells(y1), cells(x0) : cells(x1)] = True

    open_box(0.5, 9.5, 0.5, 9.5)  # west room
    open_box(12.5, 21.5, 0.5, 9.5)  # hall
    open_box(24.5, 33.5, 0.5, 9.5)  # east room
    open_box(9.5, 12.5, 4.4, 5.6)  # west corridor
    open_box(21.5, 24.5, 4.4, 5.6)  # east corridor
    return np.where(free[::-1], 254, 0).astype(np.uint8)  # image row 0 is the far (north) side


def main() -> None:
    here = Path(__file__).parent
    image = draw()
    header = f"P5\n{image.shape[1]} {image.shape[0]}\n255\n".encode()
    (here / "crossing.pgm").write_bytes(header + image.tobytes())
    (here / "crossing.yaml").write_text(
        "image: crossing.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        encoding="utf-8",
    )


if __name__ == "__main__":
    main()
