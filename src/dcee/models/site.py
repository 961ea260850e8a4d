"""The site the robot searches: obstacles and no-go zones, and path lengths around them.

A :class:`SiteMap` is a boolean occupancy grid over the horizontal plane (cells of side
``resolution`` m from ``origin``): a blocked cell is one the robot may not enter or cross, an
obstacle (a wall, a tank, a building) or a no-go zone (where it must not go even though it
could). It is built from shapes (:class:`Rectangle`, :class:`Circle`, :class:`Polygon`,
scenario section ``[world]``), from an occupancy-grid map in the ROS map-server format (a YAML
file and its PGM/PNG image, :func:`dcee.models.ros_map.load_ros_map`) or from a
``nav_msgs/OccupancyGrid``'s array (:meth:`SiteMap.from_occupancy`), each optionally inflated
by a ``clearance`` m.

Distances: the travel distance from a position to a point is the straight-line distance when
the segment between them is clear, else the length of the shortest 8-connected grid path
around the blocked cells (Dijkstra, :func:`scipy.sparse.csgraph.dijkstra`, one field per start
cell computed once and cached), so in open space every cost is exactly what it is without a
map. A point inside a blocked region (a source in a no-go zone) is reached through the nearest
reachable cell. The gas flows round the site's obstacles on the fluid solver's truth
(``truth.model = "lbm"``) and ignores them on the others: the isotropic truth is the paper's
plume in open terrain, and the filament truth's filaments pass through walls (documented in
docs/scenarios.md).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcee.errors import DceeInputError

CELL_RADIUS = math.sqrt(2.0) / 2.0
"""A cell's circumradius in cells: a shape that touches a cell comes this close to its centre."""

FIELD_CACHE = 2048
"""Distance fields kept per map (one per start cell; float32, e.g. 160 kB each at 200 × 200)."""


# --- shapes ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Rectangle:
    """Axis-aligned rectangle from corner ``low`` (x, y) m to corner ``high``."""

    low: tuple[float, float]
    high: tuple[float, float]

    def contains(self, xy: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """(K,) bool: the (K, 2) points lie inside (or within ``margin`` m of) the rectangle."""
        lo, hi = np.asarray(self.low) - margin, np.asarray(self.high) + margin
        inside = np.all((xy >= lo) & (xy <= hi), axis=1)
        if margin <= 0:
            return inside
        # rounded corners: outside the corner squares, within margin of the corner itself
        cx = np.clip(xy[:, 0], self.low[0], self.high[0])
        cy = np.clip(xy[:, 1], self.low[1], self.high[1])
        return inside & (np.hypot(xy[:, 0] - cx, xy[:, 1] - cy) <= margin)


@dataclass(frozen=True)
class Circle:
    """Disk of ``radius`` m about ``center`` (x, y) m."""

    center: tuple[float, float]
    radius: float

    def contains(self, xy: np.ndarray, margin: float = 0.0) -> np.ndarray:
        d = np.hypot(xy[:, 0] - self.center[0], xy[:, 1] - self.center[1])
        return d <= self.radius + margin


@dataclass(frozen=True)
class Polygon:
    """Simple polygon with vertices ``points`` ((x, y) m, in order; closed implicitly)."""

    points: tuple[tuple[float, float], ...]

    def contains(self, xy: np.ndarray, margin: float = 0.0) -> np.ndarray:
        from matplotlib.path import Path as MplPath

        inside = MplPath(np.asarray(self.points, dtype=float)).contains_points(xy)
        if margin <= 0:
            return inside
        return inside | (_distance_to_edges(np.asarray(self.points, float), xy) <= margin)

    def problem(self) -> str | None:
        """Why these points make no simple polygon (None when they do): fewer than three, no
        area, or two edges that are not neighbours meeting (a ring that crosses or touches
        itself, e.g. corners listed out of order: a bow tie)."""
        pts = np.asarray(self.points, dtype=float).reshape(-1, 2)
        # a point repeated next to itself (the first again at the end, as GeoJSON closes a
        # ring) adds no edge
        pts = pts[np.any(pts != np.roll(pts, 1, axis=0), axis=1)] if len(pts) > 1 else pts
        n = len(pts)
        if n < 3:
            return "a polygon needs at least 3 distinct points"
        for i in range(n):
            for j in range(i + 2, n):
                if i == 0 and j == n - 1:
                    continue  # the closing edge and the first are neighbours
                if _segments_meet(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]):
                    return (
                        f"its edges {i + 1} and {j + 1} cross or touch: a polygon's points go in "
                        "order round its boundary"
                    )
        x, y = pts[:, 0], pts[:, 1]
        if abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) <= 1e-12:
            return "the polygon has no area (its points lie on one line)"
        return None


def _segments_meet(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    """True when the closed segments ab and cd share a point (orientation tests, exact for
    the collinear cases)."""

    def orient(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    def within(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> bool:  # r on segment pq
        return min(p[0], q[0]) <= r[0] <= max(p[0], q[0]) and min(p[1], q[1]) <= r[1] <= max(
            p[1], q[1]
        )

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if ((o1 > 0 and o2 < 0) or (o1 < 0 and o2 > 0)) and (
        (o3 > 0 and o4 < 0) or (o3 < 0 and o4 > 0)
    ):
        return True
    return (
        (o1 == 0 and within(a, b, c))
        or (o2 == 0 and within(a, b, d))
        or (o3 == 0 and within(c, d, a))
        or (o4 == 0 and within(c, d, b))
    )


def _distance_to_edges(poly: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """(K,) distance of (K, 2) points to the closed polyline ``poly`` (V, 2)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a  # (V, 2)
    ap = xy[:, None, :] - a[None]  # (K, V, 2)
    t = np.clip(
        np.einsum("kvd,vd->kv", ap, ab) / np.maximum(np.einsum("vd,vd->v", ab, ab), 1e-12), 0, 1
    )
    nearest = a[None] + t[..., None] * ab[None]
    return np.min(np.linalg.norm(xy[:, None, :] - nearest, axis=2), axis=1)


Shape = Rectangle | Circle | Polygon


# --- the map ---------------------------------------------------------------------------------


@dataclass(eq=False)
class SiteMap:
    """Where the robot may not go: ``blocked`` (ny, nx) bool, cell (i, j) covering
    x ∈ [x0 + j·r, x0 + (j+1)·r), y ∈ [y0 + i·r, y0 + (i+1)·r) with (x0, y0) = ``origin`` m and
    r = ``resolution`` m. Points outside the grid are not blocked (the search volume bounds the
    robot). ``name`` says where the map came from (reports, errors)."""

    blocked: np.ndarray
    origin: tuple[float, float]
    resolution: float
    name: str = "site"
    unknown: np.ndarray | None = None
    """(ny, nx) bool: the cells a map leaves unknown (None: every cell known), as given"""
    _fields: OrderedDict[int, np.ndarray] = field(default_factory=OrderedDict, repr=False)
    _graph: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.blocked = np.ascontiguousarray(self.blocked, dtype=bool)
        if self.blocked.ndim != 2 or min(self.blocked.shape) < 1:
            raise DceeInputError("world.map", "the occupancy grid must be a non-empty 2-D array")
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise DceeInputError(
                "world.resolution", f"must be a finite length > 0 m, got {self.resolution!r}"
            )
        if not all(math.isfinite(v) for v in self.origin):
            # a NaN origin put every position in no cell: a map that blocks nothing
            raise DceeInputError(
                "world.map", f"{self.name}: its origin must be finite, got {self.origin!r}"
            )

    def __getstate__(self) -> dict[str, Any]:  # caches are rebuilt on demand
        return {**self.__dict__, "_fields": OrderedDict(), "_graph": None}

    # -- construction ---------------------------------------------------------------------

    @classmethod
    def from_shapes(
        cls,
        low: tuple[float, float],
        high: tuple[float, float],
        shapes: list[Shape] | tuple[Shape, ...],
        resolution: float = 0.25,
        clearance: float = 0.0,
        name: str = "site",
    ) -> SiteMap:
        """The grid over the rectangle ``low``–``high`` (m) with every cell that a shape grown
        by ``clearance`` touches blocked: a cell whose centre lies within ``clearance`` plus
        the cell's circumradius (√2/2 of a side) of a shape. So every point of a shape lies in
        a blocked cell, and no wall thinner than a cell slips between cell centres."""
        nx = max(1, math.ceil((high[0] - low[0]) / resolution - 1e-9))
        ny = max(1, math.ceil((high[1] - low[1]) / resolution - 1e-9))
        site = cls(np.zeros((ny, nx), bool), (float(low[0]), float(low[1])), resolution, name)
        centres = site.cell_centres().reshape(-1, 2)
        blocked = np.zeros(len(centres), bool)
        for shape in shapes:
            blocked |= shape.contains(centres, clearance + CELL_RADIUS * resolution)
        site.blocked = blocked.reshape(ny, nx)
        return site

    @classmethod
    def from_occupancy(
        cls,
        occupancy: np.ndarray,
        origin: tuple[float, float],
        resolution: float,
        occupied: float = 0.65,
        unknown_blocked: bool = True,
        clearance: float = 0.0,
        name: str = "map",
    ) -> SiteMap:
        """From occupancy probabilities (ny, nx) in [0, 1] (row 0 at the ``origin``'s y, NaN
        for unknown), as a ``nav_msgs/OccupancyGrid`` carries them (÷ 100, −1 → NaN): blocked
        where above ``occupied``, and where unknown when ``unknown_blocked`` (what Nav2's
        planners assume), then inflated by ``clearance`` m."""
        occ = np.asarray(occupancy, dtype=float)
        blocked = np.where(np.isnan(occ), unknown_blocked, occ > occupied)
        site = cls(
            blocked, (float(origin[0]), float(origin[1])), float(resolution), name, np.isnan(occ)
        )
        return site.inflated(clearance)

    def inflated(self, clearance: float) -> SiteMap:
        """This map with every cell within ``clearance`` m of a blocked cell blocked."""
        if clearance <= 0 or not self.blocked.any():
            return self
        from scipy import ndimage

        dist = ndimage.distance_transform_edt(~self.blocked) * self.resolution
        return SiteMap(dist <= clearance, self.origin, self.resolution, self.name, self.unknown)

    # -- queries --------------------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, int]:
        return self.blocked.shape  # type: ignore[return-value]

    def cell_centres(self) -> np.ndarray:
        """(ny, nx, 2) cell centres in m."""
        ny, nx = self.shape
        r = self.resolution
        xs = self.origin[0] + (np.arange(nx) + 0.5) * r
        ys = self.origin[1] + (np.arange(ny) + 0.5) * r
        gx, gy = np.meshgrid(xs, ys)
        return np.stack([gx, gy], axis=-1)

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(row, column, inside-the-grid) of (K, 2) points."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        j = np.floor((xy[:, 0] - self.origin[0]) / self.resolution).astype(np.int64)
        i = np.floor((xy[:, 1] - self.origin[1]) / self.resolution).astype(np.int64)
        ny, nx = self.shape
        inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
        return np.clip(i, 0, ny - 1), np.clip(j, 0, nx - 1), inside

    def is_unknown(self, xy: np.ndarray) -> np.ndarray:
        """(K,) bool: the (K, 2) points lie in a cell the map leaves unknown."""
        if self.unknown is None:
            return np.zeros(len(np.atleast_2d(xy)), dtype=bool)
        i, j, inside = self.cells(np.atleast_2d(np.asarray(xy, dtype=float))[:, :2])
        return inside & self.unknown[np.where(inside, i, 0), np.where(inside, j, 0)]

    def is_blocked(self, xy: np.ndarray) -> np.ndarray:
        """(K,) bool: the (K, 2) (or (K, 3)) points lie in a blocked cell."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))[:, :2]
        i, j, inside = self.cells(xy)
        return inside & self.blocked[i, j]

    def segment_clear(self, start: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """(K,) bool: the straight segments from ``start`` (2,) to each of ``ends`` (K, 2)
        touch no blocked cell (sampled every quarter cell, both ends included). A robot that
        stands in a blocked cell (a unicycle settles a few centimetres off its waypoint, which
        may be a cell edge) may leave it: blocked samples within a cell's diagonal of the start,
        before the first free one, are not counted."""
        start = np.asarray(start, dtype=float)[:2]
        ends = np.atleast_2d(np.asarray(ends, dtype=float))[:, :2]
        if not self.blocked.any():
            return np.ones(len(ends), bool)
        length = np.hypot(*(ends - start).T)
        n = int(np.ceil(length.max() / (0.25 * self.resolution))) + 1 if len(ends) else 1
        t = np.linspace(0.0, 1.0, max(n, 2))
        pts = start[None, None, :] + t[None, :, None] * (ends - start)[:, None, :]  # (K, n, 2)
        blocked = self.is_blocked(pts.reshape(-1, 2)).reshape(len(ends), -1)
        if blocked[:, 0].any():  # standing in a blocked cell: the way out of it is allowed
            near = (t[None, :] * length[:, None]) <= math.sqrt(2.0) * self.resolution
            leaving = np.logical_and.accumulate(blocked & near, axis=1)
            blocked &= ~leaving
        return ~blocked.any(axis=1)

    def _graph_matrix(self) -> Any:
        """The 16-connected grid graph (the 8 neighbours and the 8 knight moves: grid paths at
        most 2.7 % longer than the true shortest path, against 8.2 % with 8 neighbours). A move
        from a free cell needs every cell it passes free (no corner cutting); a blocked cell
        is entered from a free one and left only to another blocked one, so a blocked region
        is never a shortcut, and a point inside it is reached from its nearest face."""
        if self._graph is None:
            from scipy.sparse import coo_matrix

            ny, nx = self.shape
            free = ~self.blocked
            rows_i, cols_j = np.mgrid[0:ny, 0:nx]
            rows, cols, w = [], [], []
            # (di, dj) and the cells a move from (0, 0) passes on its way
            moves = {
                (0, 1): [],
                (1, 0): [],
                (1, 1): [(1, 0), (0, 1)],
                (1, -1): [(1, 0), (0, -1)],
                (1, 2): [(0, 1), (1, 1)],
                (2, 1): [(1, 0), (1, 1)],
                (1, -2): [(0, -1), (1, -1)],
                (2, -1): [(1, 0), (1, -1)],
            }
            for (di, dj), passes in moves.items():
                ok = (rows_i + di < ny) & (cols_j + dj >= 0) & (cols_j + dj < nx)
                ai, aj = rows_i[ok], cols_j[ok]
                bi, bj = ai + di, aj + dj
                clear = np.ones(ai.size, bool)
                for pi, pj in passes:  # the cells between, seen from either end
                    clear &= free[ai + pi, aj + pj]
                a, b = ai * nx + aj, bi * nx + bj
                inner = self.blocked[ai, aj] & self.blocked[bi, bj]
                fwd = (free[ai, aj] & clear) | inner  # a -> b
                bwd = (free[bi, bj] & clear) | inner  # b -> a
                step = self.resolution * math.hypot(di, dj)
                rows += [a[fwd], b[bwd]]
                cols += [b[fwd], a[bwd]]
                w += [np.full(int(fwd.sum()), step), np.full(int(bwd.sum()), step)]
            self._graph = coo_matrix(
                (np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))),
                shape=(ny * nx, ny * nx),
            ).tocsr()
        return self._graph

    def distance_field(self, start: np.ndarray) -> np.ndarray:
        """(ny, nx) float32 path length (m) from ``start`` (2,) to every cell centre around the
        blocked cells (inf where unreachable). Cached per start cell."""
        i, j, _ = self.cells(np.asarray(start, float)[None, :2])
        key = int(i[0]) * self.shape[1] + int(j[0])
        hit = self._fields.get(key)
        if hit is not None:
            self._fields.move_to_end(key)
            return hit
        from scipy.sparse.csgraph import dijkstra

        out = dijkstra(self._graph_matrix(), indices=key).reshape(self.shape).astype(np.float32)
        self._fields[key] = out
        if len(self._fields) > FIELD_CACHE:
            self._fields.popitem(last=False)
        return out

    def travel_distance(self, start: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Horizontal travel distance (m) from ``start`` (2,) or (3,) to ``points`` (..., 2)
        or (..., 3): the straight line where the segment is clear, else the grid path around
        the blocked cells (inf where unreachable)."""
        start = np.asarray(start, dtype=float)[:2]
        pts = np.asarray(points, dtype=float)
        shape = pts.shape[:-1]
        flat = pts.reshape(-1, pts.shape[-1])[:, :2]
        straight = np.hypot(flat[:, 0] - start[0], flat[:, 1] - start[1])
        if not self.blocked.any():
            return straight.reshape(shape)
        clear = self.segment_clear(start, flat)
        out = straight.copy()
        if not clear.all():
            fieldmap = self.distance_field(start)
            i, j, inside = self.cells(flat[~clear])
            around = fieldmap[i, j].astype(float)
            # within the cell: at least the straight line
            out[~clear] = np.where(inside, np.maximum(around, straight[~clear]), straight[~clear])
        return out.reshape(shape)

    def reachable(self, start: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(K,) bool: each point can be reached from ``start`` (a finite travel distance)."""
        return np.isfinite(self.travel_distance(start, points))


def compose_site(
    low: tuple[float, float],
    high: tuple[float, float],
    shapes: list[Shape] | tuple[Shape, ...] = (),
    maps: list[SiteMap] | tuple[SiteMap, ...] = (),
    resolution: float = 0.5,
    clearance: float = 0.0,
    name: str = "site",
) -> SiteMap:
    """One map over the search area ``low``–``high`` (m) at ``resolution``: the ``shapes``
    drawn on it and every cell of it that any of ``maps`` blocks anywhere (each cell sampled
    at the finer map's resolution, so a one-pixel wall is kept), all grown by ``clearance`` m.
    A map that does not cover the whole search area is refused (one line naming its extent)."""
    site = SiteMap.from_shapes(low, high, shapes, resolution, clearance, name)
    if not maps:
        return site
    blocked_by_maps = np.zeros(site.shape, bool)
    centres = site.cell_centres()
    for m in maps:
        ny, nx = m.shape
        x0, y0 = m.origin
        x1, y1 = x0 + nx * m.resolution, y0 + ny * m.resolution
        if x0 > low[0] + 1e-9 or y0 > low[1] + 1e-9 or x1 < high[0] - 1e-9 or y1 < high[1] - 1e-9:
            raise DceeInputError(
                "world.map",
                f"{m.name} covers x {x0:g}..{x1:g} m, y {y0:g}..{y1:g} m, not the whole search "
                f"area x {low[0]:g}..{high[0]:g} m, y {low[1]:g}..{high[1]:g} m",
            )
        k = int(min(8, math.ceil(resolution / m.resolution) + 1))
        offsets = (np.arange(k) + 0.5) / k - 0.5  # sub-points across the cell
        for ox in offsets * resolution:
            for oy in offsets * resolution:
                pts = centres.reshape(-1, 2) + np.array([ox, oy])
                blocked_by_maps |= m.is_blocked(pts).reshape(site.shape)
    grown = SiteMap(blocked_by_maps, site.origin, resolution, name).inflated(clearance)
    site.blocked = site.blocked | grown.blocked
    return site


__all__ = [
    "Circle",
    "Polygon",
    "Rectangle",
    "Shape",
    "SiteMap",
    "compose_site",
]
