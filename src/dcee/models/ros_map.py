"""Occupancy-grid maps in the ROS map-server format (a YAML file and its PGM/PNG image), read
into and written from a :class:`~dcee.models.site.SiteMap`."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import MAX_IMAGE_PIXELS, read_text
from dcee.models.site import SiteMap


def load_ros_map(path: str | Path, clearance: float = 0.0) -> SiteMap:
    """A map in the ROS map-server format: a YAML file (``image``, ``resolution`` m/cell,
    ``origin`` [x, y, yaw] of the lower-left pixel, ``negate``, ``occupied_thresh``,
    ``free_thresh``, optional ``mode``) and its PGM/PNG image. Occupancy of a pixel p (0-255):
    (255 − p)/255, or p/255 with ``negate``; above ``occupied_thresh`` blocked, below
    ``free_thresh`` free, in between unknown (blocked, as Nav2's planners treat it; with
    ``mode: scale`` or ``raw`` the same thresholds apply). Any problem is a one-line
    :class:`DceeInputError` naming the file and what is wrong."""
    import yaml
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    field_name = "world.map"
    try:
        meta = yaml.safe_load(read_text(path, field_name))
    except FileNotFoundError:
        raise DceeInputError(field_name, f"no map file {path}") from None
    except (OSError, UnicodeDecodeError, yaml.YAMLError, RecursionError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise DceeInputError(field_name, f"{path} is not a readable map YAML ({first})") from None
    if not isinstance(meta, dict):
        raise DceeInputError(
            field_name, f"{path} must be a YAML mapping (image, resolution, origin)"
        )
    missing = [k for k in ("image", "resolution", "origin") if k not in meta]
    if missing:
        raise DceeInputError(field_name, f"{path} lacks {', '.join(missing)}")
    res = meta["resolution"]
    if (
        isinstance(res, bool)
        or not isinstance(res, int | float)
        or not (math.isfinite(res) and res > 0)
    ):
        raise DceeInputError(field_name, f"{path}: resolution must be a number > 0 m, got {res!r}")
    origin = meta["origin"]
    if (
        not isinstance(origin, list)
        or len(origin) not in (2, 3)
        or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in origin
        )
    ):
        raise DceeInputError(field_name, f"{path}: origin must be [x, y, yaw], got {origin!r}")
    if len(origin) == 3 and abs(float(origin[2])) > 1e-9:
        raise DceeInputError(
            field_name,
            f"{path}: a rotated map (origin yaw {origin[2]}) is not supported; yaw must be 0",
        )
    thresholds = {}
    for key, default in (("occupied_thresh", 0.65), ("free_thresh", 0.196)):
        v = meta.get(key, default)
        if isinstance(v, bool) or not isinstance(v, int | float) or not 0 <= v <= 1:
            raise DceeInputError(field_name, f"{path}: {key} must be in [0, 1], got {v!r}")
        thresholds[key] = float(v)
    if thresholds["free_thresh"] > thresholds["occupied_thresh"]:
        raise DceeInputError(field_name, f"{path}: free_thresh must not exceed occupied_thresh")
    image = path.parent / str(meta["image"])
    try:
        with Image.open(image) as img:
            if img.width * img.height > MAX_IMAGE_PIXELS:  # the header's size, nothing decoded
                raise DceeInputError(
                    field_name,
                    f"{path}: its image declares {img.width} x {img.height} pixels, over the "
                    f"{MAX_IMAGE_PIXELS:,} a map may have",
                )
            pixels = np.asarray(img.convert("L"), dtype=float)
    except FileNotFoundError:
        raise DceeInputError(field_name, f"{path}: its image {image} does not exist") from None
    except (
        OSError,
        UnidentifiedImageError,
        ValueError,
        SyntaxError,
        Image.DecompressionBombError,
    ) as exc:
        raise DceeInputError(
            field_name, f"{path}: its image {image} cannot be read ({exc})"
        ) from None
    occ = pixels / 255.0 if meta.get("negate", 0) else (255.0 - pixels) / 255.0
    occ = occ[::-1]  # image row 0 is the top (largest y); the grid's row 0 is the origin's
    unknown = (occ > thresholds["free_thresh"]) & (occ <= thresholds["occupied_thresh"])
    occ = np.where(unknown, np.nan, occ)
    return SiteMap.from_occupancy(
        occ,
        (float(origin[0]), float(origin[1])),
        float(res),
        occupied=thresholds["occupied_thresh"],
        clearance=clearance,
        name=path.name,
    )


def write_ros_map(site: SiteMap, path: str | Path) -> Path:
    """Write ``site`` as a ROS map-server YAML and PGM (blocked cells occupied, the rest free)."""
    from PIL import Image

    path = Path(path)
    image = path.with_suffix(".pgm")
    pixels = np.where(site.blocked[::-1], 0, 254).astype(np.uint8)
    Image.fromarray(pixels, mode="L").save(image)
    path.write_text(
        f"image: {image.name}\nresolution: {site.resolution}\n"
        f"origin: [{site.origin[0]}, {site.origin[1]}, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n",
        encoding="utf-8",
    )
    return path


__all__ = ["load_ros_map", "write_ros_map"]
