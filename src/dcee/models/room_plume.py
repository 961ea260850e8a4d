"""A plume carried by a room's own air flow: the estimator's wall-aware model indoors (issue 84).

In a room the air does not blow one way: a draught through a door makes a jet, and the air
beside it turns back in a slow recirculation. The open plume (:mod:`dcee.models.plume`) assumes
one uniform wind; :class:`RoomPlume` solves the steady advection-diffusion equation in the
room's volume, in its given 3-D wind field (a building's CFD model; in a GADEN simulation, its
wind file), with walls and furniture that neither air nor gas crosses and doors (GADEN's outlet
cells) where gas leaves:

    u(x) · ∇C − K ∇²C + C / τ = q δ(x − s),  no flux through a wall, C = 0 at a door,

on cubes of side :data:`ROOM_CELL` (the room's occupancy grid coarsened, each cube air where at
least half of its cells are), by the exponentially fitted finite volumes and the adjoint
source-receptor fields of :mod:`dcee.models.receptor_fields`: one back-substitution per sensor
position gives the concentration there for a source in any cube, and a particle's prediction is
the trilinear interpolation of that field at its (x, y, z), times its q. The source height is
therefore estimated as its plan position is.

K (m²/s) and τ (s) are the model's, one factorisation per pair (K learned by a bank of models,
``estimator.wall_diffusivity``); the wind is the room's, known to the estimator as a building's
CFD model would give it (``estimator.wall_wind = "room"``). Tested against the closed-form
3-D plume in a box of uniform wind, mass balance through a door, and a wall that shelters what
lies behind it (tests/test_room_plume.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.plume import MIN_DISTANCE
from dcee.models.receptor_fields import (
    ReceptorFieldPlume,
    interpolation_weights,
    transport_operator,
)

ROOM_CELL = 0.2
"""m: the side of the model's cubes (the occupancy grid's cells merged up to it; GADEN's are
usually 0.1 m). Measured in GADEN's sample room (10.4 × 6.4 × 2.5 m, 19,232 air cubes at 0.2 m):
factorising takes 0.36 s and a receptor field 4.5 ms (SuperLU, minimum degree on Aᵀ + A); at
0.1 m the room has eight times the cells and a 3-D factorisation's fill grows faster than
that. The robot steps 0.5 m and the jet of the solver-wind room is about 1 m wide: 0.2 m
resolves both."""

ROOM_DIFFUSIVITY = 0.002
"""m²/s: the diffusivity K of a room's plume by default (the fluctuation likelihood weighs it and 3
and 10 times it, :data:`~dcee.scenarios.schema.learned_settings.WALL_DIFFUSIVITY_FACTORS`).
Chosen on GADEN's two sample rooms, the only GADEN simulations here: the time-mean concentration
GADEN's player gives at the sensor's height over 60-300 s against the model's for the true
release, on the 0.2 m cubes where GADEN's mean exceeds 0.05 ppm, log-RMS after the best scale, K
= 0.001, 0.002, 0.005, 0.01, 0.02, 0.05 m²/s: solver-wind room 0.54, **0.45**, 0.77, 1.01, 1.19,
1.42; uniform-draught room 1.82, 1.17, **1.02**, 1.25, 1.45, 1.65 (studies/gaden_room_fit.py).
The bank 0.002-0.02 holds both rooms' best. GADEN's own spreading is smaller still (its
filaments' noise, 0.02 m a 0.1 s step, is 0.002 m²/s; their growth 0.0005 m²/s): the rest of a
plume's width is the cubes' numerical diffusion, about |u| h / 2 = 0.04 m²/s in the jet."""

ROOM_MAX_CELLS = 40_000
"""Air cubes at most: a larger room is modelled on coarser cubes (its cell side grown by whole
occupancy-grid cells until it fits), so that a factorisation stays a few seconds (measured, a
box in a turbulent wind: 33,212 cubes 2.3 s and 13.9 million entries, a receptor field 22 ms;
30,856 cubes in a flatter box 1.3 s, 19 ms; two searches running beside it)."""


@dataclass(frozen=True)
class RoomFlow:
    """A room's air on the model's cubes: ``fluid`` (X, Y, Z) bool, True where air is (cube
    (i, j, k) centred at ``origin`` + ((i, j, k) + ½) ``h``); ``outlets`` (X, Y, Z) bool, the
    doors (gas leaves there); ``faces`` the wind (m/s) on the cubes' faces, one array per axis
    (the MAC grid: (X + 1, Y, Z), (X, Y + 1, Z), (X, Y, Z + 1))."""

    fluid: np.ndarray
    outlets: np.ndarray
    faces: tuple[np.ndarray, np.ndarray, np.ndarray]
    origin: np.ndarray
    h: float

    @property
    def cells(self) -> int:
        return int(self.fluid.sum())


def room_flow(
    air: np.ndarray,
    outlet: np.ndarray,
    wind: np.ndarray,
    low: np.ndarray,
    cell: float,
    target: float = ROOM_CELL,
    max_cells: int = ROOM_MAX_CELLS,
) -> RoomFlow:
    """The :class:`RoomFlow` of an occupancy grid of cubes of side ``cell`` m from ``low`` (3,)
    m: ``air`` and ``outlet`` (nx, ny, nz) bool, ``wind`` (nx, ny, nz, 3) m/s at the cells'
    centres. Cells are merged f × f × f, f the whole number nearest ``target`` / ``cell`` (at
    least 1), grown until at most ``max_cells`` cubes are air; the grid is padded with wall
    cells to a multiple of f. A cube is air where at least half its cells are, a door where it
    is not and holds an outlet cell; its wind is the mean over its cells that are air or
    outlet; a face's wind is the mean of its two cubes' (0 where either is a wall)."""
    air = np.asarray(air, dtype=bool)
    outlet = np.asarray(outlet, dtype=bool) & ~air
    if air.ndim != 3 or wind.shape != (*air.shape, 3) or outlet.shape != air.shape:
        raise DceeInputError("room", "the occupancy, outlets and wind must share one 3-D grid")
    f = max(1, round(target / cell))
    while True:
        flow = _merged(air, outlet, wind, np.asarray(low, dtype=np.float64), cell, f)
        if flow.cells <= max_cells or f >= max(air.shape):
            return flow
        f += 1


def _merged(
    air: np.ndarray, outlet: np.ndarray, wind: np.ndarray, low: np.ndarray, cell: float, f: int
) -> RoomFlow:
    pad = [(0, (-n) % f) for n in air.shape]
    air_p = np.pad(air, pad, constant_values=False)
    out_p = np.pad(outlet, pad, constant_values=False)
    wind_p = np.pad(np.asarray(wind, dtype=np.float64), [*pad, (0, 0)])
    shape = tuple(n // f for n in air_p.shape)

    def blocks(a: np.ndarray) -> np.ndarray:
        """(X, Y, Z, f³, …) the cells of each cube."""
        x, y, z = shape
        rest = a.shape[3:]
        b = a.reshape(x, f, y, f, z, f, *rest)
        b = np.moveaxis(b, (1, 3, 5), (3, 4, 5))
        return b.reshape(x, y, z, f**3, *rest)

    air_b, out_b = blocks(air_p), blocks(out_p)
    fluid = air_b.mean(axis=3) >= 0.5
    outlets = ~fluid & out_b.any(axis=3)
    moving = (air_b | out_b)[..., None]
    count = moving.sum(axis=3)
    centre = (blocks(wind_p) * moving).sum(axis=3) / np.maximum(count, 1)
    passable = fluid | outlets
    faces = []
    for axis in range(3):
        c = np.moveaxis(centre[..., axis] * passable, axis, 0)
        p = np.moveaxis(passable, axis, 0)
        face = np.zeros((c.shape[0] + 1, *c.shape[1:]))
        both = p[:-1] & p[1:]
        face[1:-1] = np.where(both, 0.5 * (c[:-1] + c[1:]), 0.0)
        face[0], face[-1] = c[0], c[-1]  # the grid's edge: the edge cube's own wind
        faces.append(np.moveaxis(face, 0, axis))
    return RoomFlow(fluid, outlets, (faces[0], faces[1], faces[2]), low.copy(), cell * f)


def _every_air_space_drains(flow: RoomFlow) -> bool:
    """Whether every connected space of air cubes (faces shared) touches a door or the grid's
    edge, where the gas can leave."""
    from scipy import ndimage

    labels, count = ndimage.label(flow.fluid)
    drains = ndimage.binary_dilation(flow.outlets) & flow.fluid
    edge = np.zeros_like(flow.fluid)
    for axis in range(3):
        index = [slice(None)] * 3
        for end in (0, -1):
            index[axis] = end
            edge[tuple(index)] = True
    drains |= edge & flow.fluid
    return set(range(1, count + 1)) <= set(np.unique(labels[drains]).tolist())


class RoomPlume(ReceptorFieldPlume):
    """The plume of one release in a room's air flow (module doc).

    Parameters
    ----------
    flow : the room's air and wind on the model's cubes (:func:`room_flow`).
    zeta1 : diffusivity K, m²/s; zeta2 : the gas's lifetime τ, s (inf: none).
    """

    dims = 3

    def __init__(
        self,
        flow: RoomFlow,
        zeta1: float,
        zeta2: float = math.inf,
        min_distance: float = MIN_DISTANCE,
    ) -> None:
        if not (zeta1 > 0 and zeta2 > 0):
            raise DceeInputError("estimator", "the room's plume needs K > 0 and a lifetime > 0")
        if min(flow.fluid.shape) < 2 or flow.cells == 0:
            raise DceeInputError("room", "the room's grid needs air cells, two or more a side")
        if math.isinf(zeta2) and not _every_air_space_drains(flow):
            # a conserved gas in a closed space has no steady state (the matrix is singular)
            raise DceeInputError(
                "estimator.wall_lifetime",
                "the room has air with no door or outlet to leave by; a conserved gas has no "
                "steady state there: give the gas a lifetime (s)",
            )
        self.flow = flow
        self.zeta1, self.zeta2 = float(zeta1), float(zeta2)
        self.index = np.full(flow.fluid.shape, -1, dtype=np.int64)
        self.index[flow.fluid] = np.arange(flow.cells)
        matrix = transport_operator(
            flow.fluid, self.index, flow.h, flow.faces, zeta1, zeta2, flow.outlets
        )
        self._factorise(matrix, flow.cells, min_distance, pivoting=False)

    def weights(self, xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Trilinear weights of (K, 3) points on the cubes' centres: ((K, 8) air-cube numbers,
        (K, 8) weights), renormalised over the air cubes (0 where a point has none)."""
        xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        return interpolation_weights(xyz, self.flow.origin, self.flow.h, self.index)

    def _rate(self, theta: np.ndarray) -> np.ndarray:
        return theta[:, 3]

    def field(self, source: np.ndarray, q: float) -> np.ndarray:
        """(X, Y, Z) g/m³, the forward solution of a release of ``q`` g/s at ``source`` (3,) m
        (NaN outside the air): for figures and tests."""
        out = np.full(self.flow.fluid.shape, np.nan)
        out[self.flow.fluid] = self._forward(source, q)
        return out


__all__ = ["ROOM_CELL", "ROOM_DIFFUSIVITY", "ROOM_MAX_CELLS", "RoomFlow", "RoomPlume", "room_flow"]
