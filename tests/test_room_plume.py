"""The plume in a room's own wind field (:mod:`dcee.models.room_plume`): against the closed-form
3-D plume, mass conservation, the adjoint's transpose, walls and doors, the occupancy grid's
coarsening, and GADEN's solver-wind sample room."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.models.room_plume import RoomFlow, RoomPlume, room_flow

ROOM = Path(__file__).parent / "data" / "gaden" / "empty-room-cfd"


def _uniform_flow(shape, h, wind=(0.0, 0.0, 0.0), air=None, outlets=None) -> RoomFlow:
    air = np.ones(shape, bool) if air is None else air
    outlets = np.zeros(shape, bool) if outlets is None else outlets
    centre = np.broadcast_to(np.asarray(wind, float), (*shape, 3)).copy()
    return room_flow(air, outlets, centre, np.zeros(3), h, target=h)


def _theta(x, y, z, q=1.0) -> np.ndarray:
    return np.array([[x, y, z, q, 0.0, 0.0, 0.0, 0.0]])


def test_open_air_matches_the_closed_form_plume() -> None:
    """A point release in a uniform wind with no wall near it (the grid's edge is clean air):
    C = q / (4π K d) · exp(u (Δx − d) / (2K)), the steady solution in unbounded air."""
    h, k, u = 0.25, 0.1, 0.4
    flow = _uniform_flow((48, 32, 32), h, (u, 0.0, 0.0))
    plume = RoomPlume(flow, k)
    src = np.array([2.125, 4.125, 4.125])  # a cube's centre
    offsets = np.array([[1.5, 0, 0], [3.0, 0, 0], [5.0, 0, 0], [3.0, 1.0, 0], [2.0, 0, 1.0]])
    points = src + offsets
    got = plume.concentration(_theta(*src, q=2.0), points)[0]
    d = np.linalg.norm(offsets, axis=1)
    want = 2.0 / (4 * math.pi * k * d) * np.exp(u * (offsets[:, 0] - d) / (2 * k))
    np.testing.assert_allclose(got, want, rtol=0.12)
    # and upwind the gas is far thinner than downwind
    assert plume.concentration(_theta(*src), (src - [2.0, 0, 0])[None])[0, 0] < 0.05 * got[1]


def test_a_closed_room_holds_q_tau_of_a_decaying_gas() -> None:
    """Walls all round and no door: at steady state the room holds q τ grams (no gas leaks
    through a wall), whatever the wind inside does."""
    shape = (14, 10, 8)
    air = np.zeros(shape, bool)
    air[1:-1, 1:-1, 1:-1] = True
    rng = np.random.default_rng(3)
    wind = rng.normal(0, 0.3, (*shape, 3))
    flow = room_flow(air, np.zeros(shape, bool), wind, np.zeros(3), 0.3, target=0.3)
    q, tau = 0.7, 40.0
    plume = RoomPlume(flow, 0.05, tau)
    field = plume.field(np.array([1.5, 1.2, 0.9]), q)
    assert np.nansum(field) * flow.h**3 == pytest.approx(q * tau, rel=1e-9)
    with pytest.raises(DceeInputError, match="wall_lifetime"):
        RoomPlume(flow, 0.05)  # a conserved gas in a closed room: no steady state
    # a door in the end wall: gas leaves by it, the room holds less, and a conserved gas has a
    # steady state
    outlets = np.zeros(shape, bool)
    outlets[-1, 4:6, 2:5] = True
    door = room_flow(air, outlets, wind, np.zeros(3), 0.3, target=0.3)
    leaky = RoomPlume(door, 0.05, tau).field(np.array([1.5, 1.2, 0.9]), q)
    assert np.nansum(leaky) * door.h**3 < 0.99 * q * tau
    assert np.all(RoomPlume(door, 0.05).field(np.array([1.5, 1.2, 0.9]), q)[door.fluid] > 0)


def test_the_receptor_field_is_the_forward_solution_at_the_receptor() -> None:
    """The adjoint field read at a source equals the forward solution read at the receptor
    (Aᵀ, not A, is factorised), in a wind that turns and rises, with a door."""
    shape = (16, 12, 8)
    air = np.zeros(shape, bool)
    air[1:-1, 1:-1, 1:-1] = True
    outlets = np.zeros(shape, bool)
    outlets[-1, 4:7, 1:4] = True
    x, y, z = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    wind = np.stack([0.3 + 0.05 * np.sin(y), 0.2 * np.cos(x / 3.0), 0.02 * (z - 4)], axis=-1)
    flow = room_flow(air, outlets, wind, np.array([-1.0, 0.5, 0.0]), 0.25, target=0.25)
    plume = RoomPlume(flow, 0.03)
    src, receptor = np.array([0.1, 1.4, 0.8]), np.array([2.1, 1.9, 0.6])
    forward = plume.field(src, 1.0)
    cells, w = plume.weights(receptor[None])
    at_receptor = np.nansum(forward[flow.fluid][cells[0]] * w[0])
    adjoint = plume.concentration(_theta(*src), receptor[None])[0, 0]
    assert adjoint == pytest.approx(at_receptor, rel=1e-6)  # the fields are float32
    assert adjoint > 0


def test_a_wall_shelters_what_lies_behind_it() -> None:
    h = 0.25
    shape = (40, 16, 8)
    air = np.ones(shape, bool)
    open_ = RoomPlume(_uniform_flow(shape, h, (0.3, 0, 0), air), 0.02)
    walled = air.copy()
    walled[19:22, 2:14, :6] = False  # a wall across the wind, air over and round it
    wall = RoomPlume(_uniform_flow(shape, h, (0.3, 0, 0), walled), 0.02)
    src, behind = _theta(3.0, 2.0, 0.6), np.array([[6.0, 2.0, 0.6]])
    assert wall.concentration(src, behind)[0, 0] < 0.2 * open_.concentration(src, behind)[0, 0]
    # a source inside the wall releases nothing
    assert wall.concentration(_theta(5.125, 2.125, 0.625), behind)[0, 0] == 0.0


def test_the_occupancy_grid_is_merged_into_cubes() -> None:
    """2 × 2 × 2 cells a cube: air where at least half are, a door where not and one is an
    outlet, the cube's wind the mean over its air and outlet cells, a face's the mean of its
    two cubes' (0 beside a wall); an odd side padded with wall."""
    air = np.ones((4, 2, 3), bool)
    air[2:, :, :] = False  # the second cube along x: wall …
    outlet = np.zeros_like(air)
    outlet[3, 1, 1] = True  # … holding one outlet cell: a door
    wind = np.zeros((4, 2, 3, 3))
    wind[:2, :, :2, 0] = 1.0
    wind[0, 0, 0, 0] = 3.0
    wind[3, 1, 1, 0] = 2.0
    flow = room_flow(air, outlet, wind, np.zeros(3), 0.1, target=0.2)
    assert flow.h == pytest.approx(0.2)
    assert flow.fluid.shape == (2, 1, 2)
    # the upper cubes hold one layer of air cells of two (padding is wall): exactly half
    np.testing.assert_array_equal(flow.fluid[:, 0, :], [[True, True], [False, False]])
    np.testing.assert_array_equal(flow.outlets[:, 0, :], [[False, False], [True, False]])
    lower = (3.0 + 7 * 1.0) / 8  # the first cube's mean wind along x
    door = 2.0  # the door cube's only air-or-outlet cell
    assert flow.faces[0][1, 0, 0] == pytest.approx(0.5 * (lower + door))
    assert flow.faces[0][1, 0, 1] == 0.0  # beside a wall cube


def test_the_solver_wind_room_carries_the_gas_along_its_jet() -> None:
    """GADEN's solver-wind sample: a release on the doors' axis reaches the far end of the jet
    (6 m downwind) far more than the same distance beside it, where the air turns back."""
    from dcee.recordings.gaden import FREE, GadenSimulation
    from dcee.recordings.gaden_files import OUTLET

    sim = GadenSimulation.open(ROOM)
    wind = sim.wind(0)
    flow = room_flow(sim.occupancy == FREE, sim.occupancy == OUTLET, wind, sim.grid.low, 0.1)
    assert flow.h == pytest.approx(0.2)
    plume = RoomPlume(flow, 0.002)
    c = plume.concentration(_theta(2.0, 3.0, 0.5), np.array([[8.0, 3.0, 0.5], [8.0, 1.0, 0.5]]))
    assert c[0, 0] > 10 * c[0, 1] > 0
