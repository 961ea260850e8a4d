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
from collections.abc import Callable

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.plume import MIN_DISTANCE
from dcee.models.receptor_fields import (
    ReceptorFieldPlume,
    bernoulli,
    interpolation_weights,
    transport_operator,
)
from dcee.models.site_flow import site_wind

LAYER_DEPTH = 2.0
"""m: the depth the release is spread over (the fluid solver's truth's default): the plane
carries q / LAYER_DEPTH per metre of height. Only the estimated q depends on it."""

MARGIN = 10.0
"""m of clean-air grid round the search area: the edge's zero concentration and zero
potential are that far from any reading."""


class SitePlume(ReceptorFieldPlume):
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
        self.index = np.full(self.fluid.shape, -1, dtype=np.int64)
        self.index[self.fluid] = np.arange(int(self.fluid.sum()))
        if isinstance(wind, tuple):
            self.face_u, self.face_v = wind
        else:
            self.face_u, self.face_v = site_wind(self.fluid, self.resolution, u, phi, wind)
        matrix = transport_matrix(
            self.fluid, self.index, self.resolution, self.face_u, self.face_v, zeta1, zeta2
        )
        self._factorise(matrix, int(self.fluid.sum()), min_distance)

    # --- interpolation ------------------------------------------------------------------------

    def weights(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bilinear weights of (K, 2) points on the cell centres: ((K, 4) fluid-cell numbers,
        (K, 4) weights), the weights renormalised over the air cells (0 where a point has
        none: inside a wall or off the grid)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        return interpolation_weights(xy, np.asarray(self.origin), self.resolution, self.index.T)

    def _rate(self, theta: np.ndarray) -> np.ndarray:
        return theta[:, 3] / self.layer_depth

    def field(self, source: np.ndarray, q: float) -> np.ndarray:
        """(ny, nx) the forward solution of a release of ``q`` g/s at ``source`` (2,) m (NaN in
        walls): for figures and tests (the estimator uses receptor fields)."""
        out = np.full(self.fluid.shape, np.nan)
        out[self.fluid] = self._forward(source, q / self.layer_depth)
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
    """The steady advection-diffusion-decay operator A (cells × cells, CSC) over the air cells
    of the plane: (A C)_i = Σ_faces K [B(−Pe) C_i − B(Pe) C_j] + h² C_i / τ (g/s per metre of
    height out of cell i), C_j = 0 beyond the grid, no flux through a wall's face (module doc;
    :func:`~dcee.models.receptor_fields.transport_operator` in two dimensions)."""
    return transport_operator(fluid, index, h, (face_v, face_u), diffusivity, lifetime)


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
