"""Write ``src/dcee/scenarios/maps/block.yaml`` + ``block.pgm``: a ROS map-server occupancy grid
of a small city block (an L-shaped building, a courtyard block, two smaller buildings and a
strip the map leaves unknown), the map file of the built-in ``site:block`` (issue 44's site from
a map file). ``python studies/make_block_map.py``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent.parent / "src" / "dcee" / "scenarios" / "maps"
RESOLUTION = 0.25
SIZE = 50.0
FREE, OCCUPIED, UNKNOWN = 254, 0, 205
BUILDINGS = [
    (8.0, 8.0, 22.0, 14.0),  # the L: its foot
    (8.0, 14.0, 14.0, 26.0),  # and its arm
    (28.0, 30.0, 44.0, 44.0),  # the courtyard block (courtyard below)
    (28.0, 8.0, 36.0, 20.0),
    (16.0, 34.0, 22.0, 42.0),
]
COURTYARD = (32.0, 34.0, 40.0, 40.0)
UNKNOWN_STRIP = (45.0, 0.0, 50.0, 6.0)


def main() -> None:
    n = round(SIZE / RESOLUTION)
    pixels = np.full((n, n), FREE, np.uint8)

    def paint(box: tuple[float, float, float, float], value: int) -> None:
        x0, y0, x1, y1 = (round(v / RESOLUTION) for v in box)
        pixels[n - y1 : n - y0, x0:x1] = value  # image row 0 is the top (largest y)

    for box in BUILDINGS:
        paint(box, OCCUPIED)
    paint(COURTYARD, FREE)
    paint(UNKNOWN_STRIP, UNKNOWN)
    Image.fromarray(pixels, mode="L").save(HERE / "block.pgm")
    (HERE / "block.yaml").write_text(
        "image: block.pgm\nresolution: 0.25\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n",
        encoding="utf-8",
    )


if __name__ == "__main__":
    main()
