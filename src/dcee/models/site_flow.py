"""The wind round a site's buildings for the wall-aware plume (issue 44).

Two models of the time-mean wind in the plane of the flight, on the staggered (MAC) grid of
:class:`~dcee.models.site_plume.SitePlume` (x-velocities on the cells' west/east faces, y on
their south/north faces, 0 on every face that touches a wall):

* :func:`mass_consistent_wind` — the free wind U made divergence-free with no flow into a wall,
  the least change to U that does so (u = U + ∇φ). The diagnostic wind model of urban dispersion
  codes (Sherman's MATHEW; the initial field of Röckle's and QUIC-URB's): it turns the wind along
  a wall and through a gap, but has no wake: behind a building the air moves as in front of it.
* :func:`wake_wind` — the steady Navier–Stokes equations with a constant eddy viscosity ν_t (a
  zero-equation RANS model), marched in pseudo-time from the mass-consistent wind by Chorin's
  projection and averaged over its last flow-through: the wind slows and turns back in a
  building's lee (a recirculating wake), speeds up round its ends, and a street across the wind
  holds a vortex. It is not the truth's solver (lbmpy's turbulent lattice Boltzmann with a
  turbulence grid and a Smagorinsky model, :mod:`dcee.simulation.lbm`): a coarser model of the
  mean flow, as an urban-dispersion code would compute for a site before a search.

Both share :class:`Projection` (the pressure Poisson equation over the air cells, factorised
once): φ = 0 beyond the grid's edge (the edge is open air), no flux through a wall's face.
Tested: no divergence in the air, nothing through a wall, the free wind unchanged in open
terrain, a reversed flow behind a wall across the wind and none in front of it
(tests/test_site_flow.py).
"""

from __future__ import annotations

import math

import numpy as np

from dcee.errors import DceeInputError

WAKE_VISCOSITY = 1.0
"""m²/s: the eddy viscosity ν_t of :func:`wake_wind` by default, the order of κ u* z at a UAV's
flight height among buildings (0.4 · 0.5 m/s · 4 m ≈ 0.8 m²/s; the first-order upwind advection
adds about |u| h / 2 of numerical viscosity on top). Kept by measurement on the tuning sites
``random-site:1-20`` (``dcee-cl``, rule written before the run: most searches acquired, ties
within one search to the lower median final error): 0.25, 0.5 and 1 m²/s acquired 14, 14 and
13/20, within one search, and 1 has the lowest median final error (0.52 m against 0.58 and
0.70 m; docs/results/sites-walls-tune/viscosity). The time-mean field of the true release
matched the truth's slightly better at 0.5 (log-RMS 0.51 against 0.58, sites 1-8); the
searches did not follow it."""

FLOW_TIMES = 4.0
"""flow-through times (the grid's longest side over the free wind speed) :func:`wake_wind`
marches; the last one is averaged (a shedding wake's mean)."""


WALL_WIND_DEFAULT = "wake"
"""The wall-aware plume's wind when ``estimator.wall_wind`` is unset: chosen on
the tuning sites ``random-site:1-20`` (lbm truth, ``dcee-cl``, rule written before the run:
most acquired): the wake wind 12/20 against the potential wind's 9/20 (3 / 0, McNemar p = 0.25;
median final error 0.51 m against 3.95 m, docs/results/sites-walls-tune)."""


class Projection:
    """The projection onto wind fields with no divergence in the air cells of ``fluid`` (ny, nx)
    and nothing through a wall: the Laplacian of φ over the air cells with φ = 0 beyond the
    grid's edge and no flux through a wall's face, factorised once (SuperLU)."""

    def __init__(self, fluid: np.ndarray, h: float) -> None:
        from scipy.sparse import coo_matrix
        from scipy.sparse.linalg import splu

        self.fluid = np.asarray(fluid, dtype=bool)
        self.h = float(h)
        ny, nx = self.fluid.shape
        index = np.full(self.fluid.shape, -1, dtype=np.int64)
        index[self.fluid] = np.arange(int(self.fluid.sum()))
        n = int(self.fluid.sum())
        ii, jj = np.nonzero(self.fluid)
        me = index[ii, jj]
        rows, cols, vals = [], [], []
        for di, dj in ((0, 1), (0, -1), (1, 0), (-1, 0)):
            i, j = ii + di, jj + dj
            inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
            nb = np.where(inside, index[np.clip(i, 0, ny - 1), np.clip(j, 0, nx - 1)], -1)
            open_face = ~inside | (nb >= 0)
            rows += [me[open_face], me[inside & (nb >= 0)]]
            cols += [me[open_face], nb[inside & (nb >= 0)]]
            vals += [np.full(int(open_face.sum()), -1.0), np.ones(int((inside & (nb >= 0)).sum()))]
        lap = coo_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), (n, n)
        )
        self._lu = splu(lap.tocsc(), permc_spec="MMD_AT_PLUS_A")
        air = np.ones((ny + 2, nx + 2), dtype=bool)
        air[1:-1, 1:-1] = self.fluid
        # faces that carry wind: both sides air (a side beyond the grid is air)
        self.open_u = air[1:-1, 1:] & air[1:-1, :-1]
        self.open_v = air[1:, 1:-1] & air[:-1, 1:-1]

    def __call__(self, fu: np.ndarray, fv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The face velocities ``fu`` (ny, nx + 1), ``fv`` (ny + 1, nx) m/s made divergence-free
        in the air: u = u* + ∇φ, Σ_faces u · n = 0 per air cell, wall faces 0."""
        ny, nx = self.fluid.shape
        fu = np.where(self.open_u, fu, 0.0)
        fv = np.where(self.open_v, fv, 0.0)
        outflow = fu[:, 1:] - fu[:, :-1] + fv[1:, :] - fv[:-1, :]
        padded = np.zeros((ny + 2, nx + 2))
        padded[1:-1, 1:-1][self.fluid] = self._lu.solve(-self.h * outflow[self.fluid])
        fu = fu + (padded[1:-1, 1:] - padded[1:-1, :-1]) / self.h
        fv = fv + (padded[1:, 1:-1] - padded[:-1, 1:-1]) / self.h
        return np.where(self.open_u, fu, 0.0), np.where(self.open_v, fv, 0.0)


def mass_consistent_wind(
    fluid: np.ndarray, h: float, free: np.ndarray, projection: Projection | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Face velocities (m/s) of the free wind ``free`` (2,) made divergence-free in the air
    with no flow through walls (module doc). Returns (ny, nx + 1) x-velocities on the cells'
    west/east faces and (ny + 1, nx) y-velocities on their south/north faces."""
    ny, nx = np.shape(fluid)
    project = projection or Projection(fluid, h)
    return project(np.full((ny, nx + 1), float(free[0])), np.full((ny + 1, nx), float(free[1])))


def wake_wind(
    fluid: np.ndarray,
    h: float,
    free: np.ndarray,
    viscosity: float = WAKE_VISCOSITY,
    flow_times: float = FLOW_TIMES,
) -> tuple[np.ndarray, np.ndarray]:
    """The time-mean wind round the walls of ``fluid`` (ny, nx) from a constant-eddy-viscosity
    Navier–Stokes model (module doc): free wind ``free`` (2,) m/s at the grid's edge, no slip on
    walls, ``viscosity`` ν_t m²/s. Marched from the mass-consistent wind for ``flow_times``
    flow-through times (explicit, first-order upwind advection, central diffusion, Chorin's
    projection), the last one averaged. Returns the faces as :func:`mass_consistent_wind`."""
    fluid = np.asarray(fluid, dtype=bool)
    free = np.asarray(free, dtype=float)
    speed = float(np.hypot(*free))
    project = Projection(fluid, h)
    fu, fv = mass_consistent_wind(fluid, h, free, project)
    if speed == 0.0:
        return fu, fv
    nu = float(viscosity)
    ny, nx = fluid.shape
    # interior faces march; the edge faces the wind enters by hold it, those it leaves by copy
    # their neighbour (zero gradient); then the projection (φ = 0 beyond the edge) opens them
    march_u = project.open_u.copy()
    march_u[:, [0, -1]] = False
    march_v = project.open_v.copy()
    march_v[[0, -1], :] = False
    # a tangential neighbour in a wall: the no-slip wall halfway, ghost = −u (beyond the edge:
    # the free wind)
    wall_u = ~project.open_u
    wall_v = ~project.open_v
    horizon = max(ny, nx) * h / speed
    total = flow_times * horizon
    mean_u = np.zeros_like(fu)
    mean_v = np.zeros_like(fv)
    averaged = 0.0
    t = 0.0
    while t < total:
        umax = max(float(np.abs(fu).max()), float(np.abs(fv).max()), speed)
        dt = min(0.4 * h / umax, 0.2 * h * h / nu)
        fu_new = fu + dt * _tendency(fu, fv, wall_u, free[0], h, nu)
        fv_new = fv + dt * _tendency(fv.T, fu.T, wall_v.T, free[1], h, nu).T
        fu = _held_edges(np.where(march_u, fu_new, 0.0), project.open_u, free[0])
        fv = _held_edges(np.where(march_v, fv_new, 0.0).T, project.open_v.T, free[1]).T
        fu, fv = project(fu, fv)
        t += dt
        if t > total - horizon:
            mean_u += dt * fu
            mean_v += dt * fv
            averaged += dt
    return project(mean_u / averaged, mean_v / averaged)


def site_wind(
    fluid: np.ndarray,
    h: float,
    u: float,
    phi: float,
    model: str,
    viscosity: float = WAKE_VISCOSITY,
) -> tuple[np.ndarray, np.ndarray]:
    """The face velocities round the walls of ``fluid`` (ny, nx) (cells of ``h`` m) of the free
    wind of ``u`` m/s from ``phi`` rad (the paper's convention: it blows towards
    −(cos φ, sin φ)) by the wind model ``model``: ``"wake"`` (:func:`wake_wind`, eddy viscosity
    ``viscosity`` m²/s) or ``"potential"`` (:func:`mass_consistent_wind`)."""
    free = -u * np.array([math.cos(phi), math.sin(phi)])
    if model == "wake":
        return wake_wind(fluid, h, free, viscosity=viscosity)
    if model == "potential":
        return mass_consistent_wind(fluid, h, free)
    raise DceeInputError("estimator.wall_wind", f"must be 'wake' or 'potential', got {model!r}")


def _held_edges(u: np.ndarray, open_faces: np.ndarray, component: float) -> np.ndarray:
    """``u`` (ny, nx + 1) with its end faces set: the inflow end holds ``component`` (the free
    wind's), the outflow end copies the face next to it (where ``open_faces``)."""
    inflow, outflow = (0, -1) if component >= 0 else (-1, 0)
    u[:, inflow] = component
    u[:, outflow] = u[:, outflow + (1 if outflow == 0 else -1)]
    return np.where(open_faces, u, 0.0)


def _tendency(
    u: np.ndarray, v: np.ndarray, wall: np.ndarray, edge: float, h: float, nu: float
) -> np.ndarray:
    """du/dt of the x-velocity ``u`` (ny, nx + 1) on its faces: −(u ∂x u + v̄ ∂y u) (first-order
    upwind) + ν ∇²u, with ``v`` (ny + 1, nx) the other component; ``wall`` marks faces in a
    wall (their u is 0; as a tangential neighbour the ghost is −u), ``edge`` the free wind's
    component beyond the grid. (The y-velocity's tendency is this one transposed.)"""
    ny, n1 = u.shape
    # neighbours along x (faces beyond the ends: the free wind)
    west = np.concatenate([np.full((ny, 1), edge), u[:, :-1]], axis=1)
    east = np.concatenate([u[:, 1:], np.full((ny, 1), edge)], axis=1)
    # neighbours along y: beyond the grid the free wind, a wall face the no-slip ghost
    south = np.concatenate([np.full((1, n1), edge), u[:-1]], axis=0)
    north = np.concatenate([u[1:], np.full((1, n1), edge)], axis=0)
    south_wall = np.concatenate([np.zeros((1, n1), bool), wall[:-1]], axis=0)
    north_wall = np.concatenate([wall[1:], np.zeros((1, n1), bool)], axis=0)
    south = np.where(south_wall, -u, south)
    north = np.where(north_wall, -u, north)
    # v at the u-faces: the mean of the four y-faces round it (0 beyond the ends)
    vp = np.pad(v, ((0, 0), (1, 1)))
    vbar = 0.25 * (vp[:-1, :-1] + vp[:-1, 1:] + vp[1:, :-1] + vp[1:, 1:])
    dudx = np.where(u > 0, u - west, east - u) / h
    dudy = np.where(vbar > 0, u - south, north - u) / h
    lap = (west + east + south + north - 4.0 * u) / (h * h)
    return -(u * dudx + vbar * dudy) + nu * lap


__all__ = [
    "FLOW_TIMES",
    "WAKE_VISCOSITY",
    "WALL_WIND_DEFAULT",
    "Projection",
    "mass_consistent_wind",
    "site_wind",
    "wake_wind",
]
