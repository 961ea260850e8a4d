"""Plumes that predict through source-receptor fields: one adjoint solve per sensor position.

With A C = b the discretised steady advection-diffusion equation of a release (A over the air
cells of a grid, b the release), the concentration at a receptor p is r_pᵀ A⁻¹ b = (A⁻ᵀ r_p)ᵀ b:
one back-substitution with the factorised Aᵀ gives the concentration at p for a source in any
cell (Keats, Yee & Lien 2007, who located a release among buildings so). A particle's prediction
at p is then an interpolation of that field at its source, scaled by its rate.

:class:`ReceptorFieldPlume` holds the factorisation, the fields (float32, least recently used
dropped beyond a byte budget) and the prediction every filter and planner calls
(``concentration_distance``). Its subclasses give the grid: :class:`~dcee.models.site_plume.
SitePlume` in the plane of the flight among buildings (bilinear, 4 corners) and
:class:`~dcee.models.room_plume.RoomPlume` in a room's volume (trilinear, 8 corners).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from dcee.models.plume import MIN_DISTANCE
from dcee.models.plume_kernels import gather_receptor_fields

FIELD_CACHE = 1024
"""Receptor fields kept at most (float32; 20,000 cells: 80 kB each)."""

FIELD_BYTES = 96 * 2**20
"""Bytes of receptor fields kept at most per plume (a room's fields are larger than a site's)."""


class ReceptorFieldPlume:
    """The adjoint-field machinery shared by the wall-aware plumes (module doc). A subclass
    calls :meth:`_factorise` with its transport matrix and implements :meth:`weights` (points →
    cell numbers and interpolation weights, in groups of four corners) and :meth:`_rate`."""

    dims: int = 2
    """Coordinates of a source the fields resolve (2: x, y in a plane; 3: x, y, z)."""

    def _factorise(
        self,
        matrix: object,
        n_cells: int,
        min_distance: float = MIN_DISTANCE,
        pivoting: bool = True,
    ) -> None:
        """Factorise Aᵀ once. ``pivoting=False`` keeps the diagonal pivots in the fill-reducing
        order (SuperLU's symmetric mode): safe for this operator, whose columns are diagonally
        dominant (the fluxes out of a cell are what its neighbours receive, plus what leaves or
        decays), and in three dimensions far cheaper: a 30 × 30 × 22 box of 15,680 cells in a
        turbulent wind factorised in 0.55 s with 4.9 million entries against 20 s and 33
        million with partial pivoting (measured)."""
        from scipy.sparse.linalg import splu

        self.min_distance = float(min_distance)
        # the stencil's pattern is symmetric: minimum degree on Aᵀ + A fills in about half what
        # the default column ordering does (site:wall: a solve 0.65 ms against 2.2 ms; a room's
        # 19,232 cells: 4.5 ms against 13 ms, measured)
        options = {} if pivoting else {"diag_pivot_thresh": 0.0, "options": {"SymmetricMode": True}}
        self._adjoint = splu(matrix.T.tocsc(), permc_spec="MMD_AT_PLUS_A", **options)  # type: ignore[attr-defined]
        self._rhs = np.zeros(n_cells)
        self._capacity = max(2, min(FIELD_CACHE, FIELD_BYTES // (4 * max(n_cells, 1))))
        # receptor fields, one row each (float32), and the row of each point (LRU order)
        self._bank = np.empty((min(16, self._capacity), n_cells), np.float32)
        self._slots: OrderedDict[tuple[float, ...], int] = OrderedDict()

    def weights(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((K, 4·m) air-cell numbers, (K, 4·m) weights) of (K, dims) points (subclass)."""
        raise NotImplementedError

    def _rate(self, theta: np.ndarray) -> np.ndarray:
        """(N,) the factor of each particle's field value: its release as the fields count it."""
        raise NotImplementedError

    def _slot(self, point: np.ndarray) -> int:
        """The row of :attr:`_bank` holding the receptor field of ``point`` (dims,) m, solving
        it (one adjoint back-substitution) if it is not kept; least recently used rows are
        reused beyond the capacity."""
        key = tuple(round(float(v), 6) for v in point[: self.dims])
        row = self._slots.get(key)
        if row is not None:
            self._slots.move_to_end(key)
            return row
        n_cells = len(self._rhs)
        if len(self._slots) < len(self._bank):
            row = len(self._slots)
        elif len(self._bank) < self._capacity:
            grown = np.empty((min(2 * len(self._bank), self._capacity), n_cells), np.float32)
            grown[: len(self._bank)] = self._bank
            row, self._bank = len(self._bank), grown
        else:
            _, row = self._slots.popitem(last=False)
        cells, w = self.weights(np.asarray(point, dtype=np.float64)[None, : self.dims])
        self._rhs[:] = 0.0
        np.add.at(self._rhs, cells[0], w[0])
        self._bank[row] = self._adjoint.solve(self._rhs) if self._rhs.any() else 0.0
        self._slots[key] = row
        return row

    def receptor_field(self, point: np.ndarray) -> np.ndarray:
        """(cells,) float32: the concentration at ``point`` (dims,) m per unit release (as
        :meth:`_rate` counts it) at each air cell (one adjoint solve, cached; a view, valid
        until the next field is solved)."""
        return self._bank[self._slot(np.asarray(point, dtype=np.float64))]

    def concentration_distance(
        self, theta: np.ndarray, positions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(N, K) concentrations (g/m³) and source distances (m, clamped at ``min_distance``)
        of particles ``theta`` (N, 8) at (K, 3) positions. Only each particle's location (its
        first ``dims`` values) and q are read (the wind and ζ are the model's). The K fields are
        read at the particles' cells by a compiled kernel, four corners at a time (at most half
        the field cache at a time)."""
        theta = np.asarray(theta, dtype=np.float64).reshape(-1, theta.shape[-1])
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        cells, w = self.weights(theta[:, : self.dims])
        groups = [
            (np.ascontiguousarray(cells[:, c : c + 4]), np.ascontiguousarray(w[:, c : c + 4]))
            for c in range(0, cells.shape[1], 4)
        ]
        conc = np.empty((len(theta), len(positions)))
        step = max(1, self._capacity // 2)
        for start in range(0, len(positions), step):
            chunk = positions[start : start + step]
            rows = np.array([self._slot(p) for p in chunk], dtype=np.int64)
            out = conc[:, start : start + len(chunk)]
            gather_receptor_fields(self._bank, rows, *groups[0], out)
            for group in groups[1:]:
                part = np.empty_like(out)
                gather_receptor_fields(self._bank, rows, *group, part)
                out += part
        conc *= self._rate(theta)[:, None]
        # the squared distance summed axis by axis, as einsum("nki,nki->nk") does (same bits)
        d2 = np.square(positions[None, :, 0] - theta[:, None, 0])
        d2 += np.square(positions[None, :, 1] - theta[:, None, 1])
        d2 += np.square(positions[None, :, 2] - theta[:, None, 2])
        dist = np.maximum(np.sqrt(d2, out=d2), self.min_distance)
        return conc, dist

    def concentration(self, theta: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """(N, K) concentrations, g/m³ (see :meth:`concentration_distance`)."""
        return self.concentration_distance(theta, positions)[0]

    def _forward(self, source: np.ndarray, release: float) -> np.ndarray:
        """(cells,) the forward solution of ``release`` (as :meth:`_rate` counts it) at
        ``source`` (dims,) m: for figures and tests (the estimator uses receptor fields)."""
        cells, w = self.weights(np.asarray(source, dtype=np.float64)[None, : self.dims])
        b = np.zeros(len(self._rhs))
        np.add.at(b, cells[0], w[0] * release)
        return self._adjoint.solve(b, trans="T")


def interpolation_weights(
    points: np.ndarray, origin: np.ndarray, h: float, index: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Multilinear weights of (K, d) points on the centres of a d-dimensional grid of cells of
    side ``h`` m from ``origin`` (d,) m, whose ``index`` array numbers the air cells (−1
    elsewhere; axis a of ``index`` is coordinate a): ((K, 2ᵈ) air-cell numbers, (K, 2ᵈ)
    weights), the weights renormalised over the air cells (0 where a point has none: inside a
    wall or off the grid). Corner c takes the upper neighbour along axis a where bit a of c is
    set."""
    points = np.asarray(points, dtype=np.float64)
    d = points.shape[1]
    shape = np.array(index.shape)
    f = (points - np.asarray(origin)[None, :d]) / h - 0.5
    lo = np.floor(f).astype(np.int64)
    t = f - lo
    cells = np.empty((len(points), 2**d), dtype=np.int64)
    w = np.empty((len(points), 2**d))
    for c in range(2**d):
        up = [(c >> a) & 1 for a in range(d)]
        wc = np.ones(len(points))
        inside = np.ones(len(points), bool)
        clipped = []
        for a in range(d):
            i = lo[:, a] + up[a]
            wc = wc * (t[:, a] if up[a] else 1.0 - t[:, a])
            inside &= (i >= 0) & (i < shape[a])
            clipped.append(np.clip(i, 0, shape[a] - 1))
        k = np.where(inside, index[tuple(clipped)], -1)
        cells[:, c] = np.maximum(k, 0)
        w[:, c] = np.where(k >= 0, wc, 0.0)
    total = w.sum(axis=1, keepdims=True)
    w = np.divide(w, total, out=np.zeros_like(w), where=total > 1e-12)
    return cells, w


def bernoulli(x: np.ndarray) -> np.ndarray:
    """B(x) = x / (eˣ − 1), B(0) = 1, for the fitted fluxes (accurate for small |x|)."""
    x = np.asarray(x, dtype=np.float64)
    out = np.ones_like(x)
    big = np.abs(x) > 1e-10
    out[big] = x[big] / np.expm1(x[big])
    return out


def transport_operator(
    fluid: np.ndarray,
    index: np.ndarray,
    h: float,
    faces: tuple[np.ndarray, ...],
    diffusivity: float,
    lifetime: float,
    outlets: np.ndarray | None = None,
) -> object:
    """The steady advection-diffusion-decay operator A (cells × cells, CSC) over the air cells
    of a d-dimensional grid of cubes of side ``h`` m (``fluid``, True where air is; ``index``
    numbers its air cells, −1 elsewhere), finite volumes with the exponentially fitted
    (Scharfetter-Gummel) flux through each face, exact for 1-D advection-diffusion between two
    cell centres at any cell Péclet number:

        (A C)_i = Σ_faces K h^(d−2) [B(−Pe) C_i − B(Pe) C_j] + h^d C_i / τ,  Pe = v h / K,

    g/s out of cell i (in two dimensions per metre of height). ``faces[a]``: the velocity
    (m/s, along array axis a) on the faces normal to axis a (the MAC grid: one more than the
    cells along a; face m between cells m − 1 and m). Gas crosses no face of a wall cell; beyond
    the grid's edge and in the ``outlets`` cells (not air, True where gas leaves: a door) the
    air is clean (C = 0)."""
    from scipy.sparse import coo_matrix

    shape = np.array(fluid.shape)
    d = len(shape)
    n = int(fluid.sum())
    at = np.nonzero(fluid)
    me = index[at]
    k = float(diffusivity)
    coefficient = k * h ** (d - 2)
    decay = 0.0 if math.isinf(lifetime) else h**d / float(lifetime)
    rows, cols, vals = [me], [me], [np.full(n, decay)]
    for axis in reversed(range(d)):  # the plane's x faces first, as it always summed them
        for side in (1, -1):
            # the outward velocity of this face of each air cell
            face = list(at)
            face[axis] = at[axis] + (1 if side > 0 else 0)
            v = side * faces[axis][tuple(face)]
            nbr = list(at)
            nbr[axis] = at[axis] + side
            inside = (nbr[axis] >= 0) & (nbr[axis] < shape[axis])
            nbr[axis] = np.clip(nbr[axis], 0, shape[axis] - 1)
            nb = np.where(inside, index[tuple(nbr)], -1)
            clean = ~inside
            if outlets is not None:
                clean |= inside & outlets[tuple(nbr)]
            open_face = clean | (nb >= 0)
            pe = v * h / k
            rows.append(me[open_face])
            cols.append(me[open_face])
            vals.append(coefficient * bernoulli(-pe[open_face]))
            inner = inside & (nb >= 0)
            rows.append(me[inner])
            cols.append(nb[inner])
            vals.append(-coefficient * bernoulli(pe[inner]))
    return coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), (n, n)
    ).tocsc()


__all__ = [
    "FIELD_BYTES",
    "FIELD_CACHE",
    "ReceptorFieldPlume",
    "bernoulli",
    "interpolation_weights",
    "transport_operator",
]
