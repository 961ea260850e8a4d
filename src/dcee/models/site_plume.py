"""A plume that flows round buildings: the estimator's wall-aware dispersion model (issue 44).

The paper's plume (:mod:`dcee.models.plume`) is the solution of the steady advection-diffusion
equation in open terrain. Near buildings the same equation holds in the air between them, with
walls that neither wind nor gas crosses. :class:`SitePlume` solves it numerically on a grid over
the search area, in the plane of the flight (planar, as the fluid solver's truth is):

    u(x) · ∇C − K ∇²C + C / τ = (q / h) δ(x − s),  no flux through a wall,

* **Wind round the walls** (:mod:`dcee.models.site_flow`): ``wind = "wake"``, the time-mean
  flow of a constant-eddy-viscosity Navier–Stokes model (a recirculating wake in a building's
  lee, a vortex in a street across the wind); ``wind = "potential"``, the free wind U made
  mass-consistent (u = U + ∇φ: turned along a wall and through a gap, no wake).
* **Transport.** Finite volumes on the grid's cells, each face's flux by the exponentially
  fitted (Scharfetter-Gummel) scheme, exact for 1-D advection-diffusion between two cell
  centres at any cell Péclet number (no numerical diffusion from upwinding, no oscillation):
  flux = K [B(−Pe) C_i − B(Pe) C_j], B(x) = x / (eᵡ − 1), Pe = v h / K. Outside the grid the
  air is clean. K = ζ1 (m²/s), τ = ζ2 (s) and U (u, φ) are the paper's parameters; h is the
  layer the release is spread over (:data:`LAYER_DEPTH`, as the fluid solver's truth takes it).
* **Source-receptor fields.** With A C = b the discrete equation, the concentration at a
  receptor p is r_pᵀ A⁻¹ b = (A⁻ᵀ r_p)ᵀ b: one adjoint solve per sensor position gives the
  concentration there for a source anywhere (Keats, Yee & Lien 2007, who located a release
  among buildings so). ``A`` is factorised once (SuperLU, minimum-degree ordering); a field
  costs one back-substitution (under a millisecond at 20,000 cells) and is cached per position,
  so every particle's prediction at a position is an interpolation.

The wind, K and τ are fixed per model (one flow, one factorisation): the wind is the scenario's,
known to the estimator (``unknown = "source"``); K and τ are the estimator's settings (K learned
by a bank of models, ``estimator.wall_diffusivity``; no decay by default). Tested against the
closed-form planar plume in open terrain and against a wall that shelters what lies behind it
(tests/test_site_plume.py).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.plume import MIN_DISTANCE
from dcee.models.plume_kernels import gather_receptor_fields
from dcee.models.site_flow import site_wind

LAYER_DEPTH = 2.0
"""m: the depth the release is spread over (the fluid solver's truth's default): the plane
carries q / LAYER_DEPTH per metre of height. Only the estimated q depends on it."""

MARGIN = 10.0
"""m of clean-air grid round the search area: the edge's zero concentration and zero
potential are that far from any reading."""

FIELD_CACHE = 1024
"""Receptor fields kept (float32; 20,000 cells: 80 kB each)."""


def bernoulli(x: np.ndarray) -> np.ndarray:
    """B(x) = x / (eˣ − 1), B(0) = 1, for the fitted fluxes (accurate for small |x|)."""
    x = np.asarray(x, dtype=np.float64)
    out = np.ones_like(x)
    big = np.abs(x) > 1e-10
    out[big] = x[big] / np.expm1(x[big])
    return out


class SitePlume:
    """The wall-aware planar plume over one site and one wind (module doc).

    Parameters
    ----------
    fluid : (ny, nx) bool, True where air is (cell (i, j) centred at origin + ((j + ½) h,
        (i + ½) h)), False in walls and buildings.
    origin : (x0, y0) m of the grid's corner; resolution : h, m.
    u, phi : the free wind, m/s, and the direction it comes from, rad (the paper's convention).
    zeta1 : diffusivity K, m²/s; zeta2 : the gas's lifetime τ, s (inf: none).
    layer_depth : m, see :data:`LAYER_DEPTH`.
    wind : ``"wake"`` or ``"potential"`` (module doc); or a precomputed pair of face velocity
        arrays (shared by the models of one site and wind that differ only in K).
    """

    def __init__(
        self,
        fluid: np.ndarray,
        origin: tuple[float, float],
        resolution: float,
        u: float,
        phi: float,
        zeta1: float,
        zeta2: float,
        layer_depth: float = LAYER_DEPTH,
        min_distance: float = MIN_DISTANCE,
        wind: str | tuple[np.ndarray, np.ndarray] = "potential",
    ) -> None:
        self.fluid = np.asarray(fluid, dtype=bool)
        if self.fluid.ndim != 2 or min(self.fluid.shape) < 3:
            raise DceeInputError("world", "the site's grid must be at least 3 × 3 cells")
        if not (zeta1 > 0 and zeta2 > 0 and u >= 0 and resolution > 0 and layer_depth > 0):
            raise DceeInputError(
                "truth", "the wall-aware plume needs zeta1 > 0, zeta2 > 0 and u >= 0"
            )
        self.origin = (float(origin[0]), float(origin[1]))
        self.resolution = float(resolution)
        self.wind = (float(u), float(phi))
        self.zeta1, self.zeta2 = float(zeta1), float(zeta2)
        self.layer_depth = float(layer_depth)
        self.min_distance = float(min_distance)
        self.index = np.full(self.fluid.shape, -1, dtype=np.int64)
        self.index[self.fluid] = np.arange(int(self.fluid.sum()))
        if isinstance(wind, tuple):
            self.face_u, self.face_v = wind
        else:
            self.face_u, self.face_v = site_wind(self.fluid, self.resolution, u, phi, wind)
        matrix = transport_matrix(
            self.fluid, self.index, self.resolution, self.face_u, self.face_v, zeta1, zeta2
        )
        from scipy.sparse.linalg import splu

        # the stencil's pattern is symmetric: minimum degree on Aᵀ + A fills in about half what
        # the default column ordering does (site:wall: a solve 0.65 ms against 2.2 ms, measured)
        self._adjoint = splu(matrix.T.tocsc(), permc_spec="MMD_AT_PLUS_A")
        self._rhs = np.zeros(int(self.fluid.sum()))
        # receptor fields, one row each (float32), and the row of each point (LRU order)
        self._bank = np.empty((16, len(self._rhs)), np.float32)
        self._slots: OrderedDict[tuple[float, float], int] = OrderedDict()

    # --- interpolation ------------------------------------------------------------------------

    def weights(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bilinear weights of (K, 2) points on the cell centres: ((K, 4) fluid-cell numbers,
        (K, 4) weights), the weights renormalised over the air cells (0 where a point has
        none: inside a wall or off the grid)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        ny, nx = self.fluid.shape
        fx = (xy[:, 0] - self.origin[0]) / self.resolution - 0.5
        fy = (xy[:, 1] - self.origin[1]) / self.resolution - 0.5
        j0, i0 = np.floor(fx).astype(np.int64), np.floor(fy).astype(np.int64)
        tx, ty = fx - j0, fy - i0
        cells = np.empty((len(xy), 4), dtype=np.int64)
        w = np.empty((len(xy), 4))
        for c, (di, dj, wc) in enumerate(
            (
                (0, 0, (1 - tx) * (1 - ty)),
                (0, 1, tx * (1 - ty)),
                (1, 0, (1 - tx) * ty),
                (1, 1, tx * ty),
            )
        ):
            i, j = i0 + di, j0 + dj
            inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
            k = np.where(inside, self.index[np.clip(i, 0, ny - 1), np.clip(j, 0, nx - 1)], -1)
            cells[:, c] = np.maximum(k, 0)
            w[:, c] = np.where(k >= 0, wc, 0.0)
        total = w.sum(axis=1, keepdims=True)
        w = np.divide(w, total, out=np.zeros_like(w), where=total > 1e-12)
        return cells, w

    def _slot(self, xy: np.ndarray) -> int:
        """The row of :attr:`_bank` holding the receptor field of the point ``xy`` (2,) m,
        solving it (one adjoint back-substitution) if it is not kept; least recently used rows
        are reused beyond :data:`FIELD_CACHE`."""
        key = (round(float(xy[0]), 6), round(float(xy[1]), 6))
        row = self._slots.get(key)
        if row is not None:
            self._slots.move_to_end(key)
            return row
        n_cells = len(self._rhs)
        if len(self._slots) < min(len(self._bank), FIELD_CACHE):
            row = len(self._slots)
        elif len(self._bank) < FIELD_CACHE:
            grown = np.empty((min(2 * len(self._bank), FIELD_CACHE), n_cells), np.float32)
            grown[: len(self._bank)] = self._bank
            row, self._bank = len(self._bank), grown
        else:
            _, row = self._slots.popitem(last=False)
        cells, w = self.weights(np.asarray(xy)[None, :2])
        self._rhs[:] = 0.0
        np.add.at(self._rhs, cells[0], w[0])
        self._bank[row] = self._adjoint.solve(self._rhs) if self._rhs.any() else 0.0
        self._slots[key] = row
        return row

    def receptor_field(self, xy: np.ndarray) -> np.ndarray:
        """(cells,) float32: the concentration at the point ``xy`` (2,) m per unit of q/h
        released at each air cell (one adjoint solve, cached; a view, valid until the next
        field is solved)."""
        return self._bank[self._slot(xy)]

    # --- the plume ------------------------------------------------------------------------------

    def concentration_distance(
        self, theta: np.ndarray, positions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(N, K) concentrations (g/m³) and source distances (m, clamped at ``min_distance``)
        of particles ``theta`` (N, 8) at (K, 3) positions. Only each particle's x, y and q are
        read (the wind and ζ are the model's). The K fields are read at the particles' four
        cells by a compiled kernel (at most half the field cache at a time)."""
        theta = np.asarray(theta, dtype=np.float64).reshape(-1, theta.shape[-1])
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        cells, w = self.weights(theta[:, :2])
        conc = np.empty((len(theta), len(positions)))
        step = FIELD_CACHE // 2
        for start in range(0, len(positions), step):
            chunk = positions[start : start + step]
            rows = np.array([self._slot(p[:2]) for p in chunk], dtype=np.int64)
            gather_receptor_fields(self._bank, rows, cells, w, conc[:, start : start + len(chunk)])
        conc *= (theta[:, 3] / self.layer_depth)[:, None]
        # the squared distance summed axis by axis, as einsum("nki,nki->nk") does (same bits)
        d2 = np.square(positions[None, :, 0] - theta[:, None, 0])
        d2 += np.square(positions[None, :, 1] - theta[:, None, 1])
        d2 += np.square(positions[None, :, 2] - theta[:, None, 2])
        dist = np.maximum(np.sqrt(d2, out=d2), self.min_distance)
        return conc, dist

    def concentration(self, theta: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """(N, K) concentrations, g/m³ (see :meth:`concentration_distance`)."""
        return self.concentration_distance(theta, positions)[0]

    def field(self, source: np.ndarray, q: float) -> np.ndarray:
        """(ny, nx) the forward solution of a release of ``q`` g/s at ``source`` (2,) m (NaN in
        walls): for figures and tests (the estimator uses receptor fields)."""
        cells, w = self.weights(np.asarray(source, dtype=np.float64)[None, :2])
        b = np.zeros(len(self._rhs))
        np.add.at(b, cells[0], w[0] * q / self.layer_depth)
        c = self._adjoint.solve(b, trans="T")
        out = np.full(self.fluid.shape, np.nan)
        out[self.fluid] = c
        return out


def gather_receptor_fields_reference(
    bank: np.ndarray, rows: np.ndarray, cells: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """NumPy reference of :func:`dcee.models.plume_kernels.gather_receptor_fields`: (N, K)
    Σ_c weights[n, c] · bank[rows[k], cells[n, c]]."""
    vals = bank[rows[:, None], cells.reshape(1, -1)].reshape(len(rows), *cells.shape)
    return np.einsum("nc,knc->nk", weights, vals)


def transport_matrix(
    fluid: np.ndarray,
    index: np.ndarray,
    h: float,
    face_u: np.ndarray,
    face_v: np.ndarray,
    diffusivity: float,
    lifetime: float,
) -> object:
    """The steady advection-diffusion-decay operator A (cells × cells, CSC) over the air cells:
    (A C)_i = Σ_faces K [B(−Pe) C_i − B(Pe) C_j] + h² C_i / τ (g/s per metre of height out of
    cell i), C_j = 0 beyond the grid, no flux through a wall's face (module doc)."""
    from scipy.sparse import coo_matrix

    ny, nx = fluid.shape
    n = int(fluid.sum())
    ii, jj = np.nonzero(fluid)
    me = index[ii, jj]
    k = float(diffusivity)
    decay = 0.0 if math.isinf(lifetime) else h * h / float(lifetime)
    rows = [me]
    cols = [me]
    vals = [np.full(n, decay)]
    # outward velocity of each face of each air cell
    faces = (
        (0, 1, face_u[ii, jj + 1]),
        (0, -1, -face_u[ii, jj]),
        (1, 0, face_v[ii + 1, jj]),
        (-1, 0, -face_v[ii, jj]),
    )
    for di, dj, v in faces:
        i, j = ii + di, jj + dj
        inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
        nb = np.where(inside, index[np.clip(i, 0, ny - 1), np.clip(j, 0, nx - 1)], -1)
        open_face = ~inside | (nb >= 0)
        pe = v * h / k
        rows.append(me[open_face])
        cols.append(me[open_face])
        vals.append(k * bernoulli(-pe[open_face]))
        inner = inside & (nb >= 0)
        rows.append(me[inner])
        cols.append(nb[inner])
        vals.append(-k * bernoulli(pe[inner]))
    return coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), (n, n)
    ).tocsc()


def site_grid(
    low: tuple[float, float],
    high: tuple[float, float],
    resolution: float,
    solid: Callable[[np.ndarray], np.ndarray],
    margin: float = MARGIN,
) -> tuple[np.ndarray, tuple[float, float]]:
    """The (ny, nx) air mask over the search area ``low``–``high`` m grown by ``margin``, cells
    of side ``resolution``, a cell a wall where ``solid`` ((K, 2) → (K,) bool) says its centre
    is; and the grid's origin."""
    x0, y0 = low[0] - margin, low[1] - margin
    nx = math.ceil((high[0] - low[0] + 2 * margin) / resolution)
    ny = math.ceil((high[1] - low[1] + 2 * margin) / resolution)
    xs = x0 + (np.arange(nx) + 0.5) * resolution
    ys = y0 + (np.arange(ny) + 0.5) * resolution
    gx, gy = np.meshgrid(xs, ys)
    walls = np.asarray(solid(np.column_stack([gx.ravel(), gy.ravel()])), dtype=bool)
    return ~walls.reshape(ny, nx), (x0, y0)


def open_to_edge(fluid: np.ndarray, origin: tuple[float, float], resolution: float, xy) -> bool:
    """True when the air cell holding the point ``xy`` (2,) m connects (through air cells,
    4-connected) to the grid's edge: gas released there has a free path out of the site."""
    from scipy import ndimage

    labels, _ = ndimage.label(fluid)
    j = int((xy[0] - origin[0]) // resolution)
    i = int((xy[1] - origin[1]) // resolution)
    ny, nx = fluid.shape
    if not (0 <= i < ny and 0 <= j < nx) or not fluid[i, j]:
        return False
    edge = np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])
    return bool(np.any(edge == labels[i, j]))


__all__ = [
    "LAYER_DEPTH",
    "MARGIN",
    "SitePlume",
    "bernoulli",
    "gather_receptor_fields_reference",
    "open_to_edge",
    "site_grid",
    "transport_matrix",
]
