"""The fluid solver behind the ``lbm`` truth (:mod:`dcee.simulation.lbm`): lattice Boltzmann
(`lbmpy <https://pypi.org/project/lbmpy/>`_) behind a turbulence grid, in the canonical frame
(source at the origin, mean wind +x at 1 m/s).

**Flow.** The incompressible Navier-Stokes equations in 2-D (D2Q9 cumulant lattice Boltzmann,
Smagorinsky subgrid model) in a channel ``[-grid_distance - 4, downstream] × [-width/2,
width/2]`` m, periodic crosswind, a uniform inflow at the upstream end and an extrapolating
outflow. A row of bars (``bar_diameter``, ``bar_spacing`` apart) ``grid_distance`` upstream of
the source sheds wakes that merge into turbulence, as a grid does in a wind tunnel or flume;
a seeded perturbation of the initial velocity (``realisation``) makes each realisation its own.

**Scalar.** A second lattice (D2Q9 advection-diffusion with two relaxation times, the flow's
velocity as input) carries a passive scalar from a disc of radius ``source_radius`` at the
origin held at a fixed value (lbmpy's ``DiffusionDirichlet``), zero at the inflow and
zero-gradient at the outflow. The odd-moment rate sets the diffusivity, the even one follows
from the "magic" product Λ = 1/4 (:data:`MAGIC`). Measured on the default grid: with a single
relaxation time (SRT) the scalar lattice at this Péclet number leaked a grid-scale
checkerboard upwind of the source, a time mean of 1.4 % of the peak 3.5 m upwind (above the
sensor threshold there at typical release rates, so readings upwind of the source that no
plume makes); TRT with Λ = 1/4 cuts it 13× (30× at 5.5 m) with the same spread downwind.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.scenarios.schema.truth import LbmSpec

FIELD = "truth.model"
FLUX_DISTANCE = 10.0
"""m downwind of the source where the scalar flux that normalises the field is measured."""
REFERENCE_SPEED = 1.0
"""m/s: the canonical frame's mean wind."""

Progress = Callable[[float, float], None]
"""``progress(done, total)`` in canonical seconds."""


def _lbmpy() -> Any:
    try:
        import lbmpy
        import pystencils  # noqa: F401
    except ImportError:
        raise DceeInputError(
            FIELD, "the lbm truth needs lbmpy: pip install 'dcee[fluid]'"
        ) from None
    return lbmpy


class _Domain:
    """Lattice geometry of a parameter set: sizes, the source cell and the canonical axes."""

    def __init__(self, spec: LbmSpec) -> None:
        dx = spec.spacing
        self.dx = dx
        self.upstream = spec.grid_distance + 4.0 * max(spec.bar_diameter, dx)
        self.nx = round((self.upstream + spec.downstream) / dx) + 1
        self.ny = round(spec.width / dx)
        self.ny += self.ny % 2
        self.source = (round(self.upstream / dx), self.ny // 2)
        self.x = (np.arange(self.nx) - self.source[0]) * dx
        self.y = (np.arange(self.ny) - self.source[1]) * dx
        self.step_seconds = spec.lattice_speed * dx / REFERENCE_SPEED
        """canonical seconds per lattice step"""
        self.bars_x = -spec.grid_distance
        # the source straight downwind of the gap between two bars (in the mixing of two wakes,
        # not on one wake's regular vortex street), then every bar_spacing round the width
        count = max(1, round(spec.width / spec.bar_spacing))
        k = np.arange(count) - count // 2
        self.bars_y = spec.bar_spacing * (k + 0.5)


Solid = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``solid(x, y)``: (K,) bool, the canonical points (m, source at the origin, wind +x) inside a
building or wall."""


def solid_cells(spec: LbmSpec, solid: Solid) -> np.ndarray:
    """(nx, ny) bool: the lattice cells of ``spec``'s domain whose centre ``solid`` calls solid
    (the mask the solver walls off, and part of the cache key)."""
    dom = _Domain(spec)
    x, y = np.meshgrid(dom.x, dom.y, indexing="ij")
    return np.asarray(solid(x.ravel(), y.ravel()), dtype=bool).reshape(x.shape)


def solve(
    spec: LbmSpec, progress: Progress | None = None, solids: np.ndarray | None = None
) -> dict[str, Any]:
    """Run the solver: ``concentration`` (T, ny, nx) float32 g/m³ for 1 g/s per metre of height
    at 1 m/s, axes ``t`` (s from the first stored frame), ``x``, ``y`` (m, source at the
    origin), and ``attrs`` (flux, turbulence statistics at the source, timings).

    ``solids`` (nx, ny) bool (:func:`solid_cells`): buildings and walls, no-slip for the flow
    (bounce-back) and no-flux for the scalar (bounce-back of the scalar lattice), stored as 0;
    a stored value near a wall is the mean over the fluid cells of its block."""
    _lbmpy()
    from lbmpy import LBMConfig, LBStencil, Method, Stencil, SubgridScaleModel
    from lbmpy.boundaries import (
        UBB,
        DiffusionDirichlet,
        ExtrapolationOutflow,
        NeumannByCopy,
        NoSlip,
    )
    from lbmpy.lbstep import LatticeBoltzmannStep
    from pystencils import Target, create_data_handling, make_slice

    started = _time.perf_counter()
    dom = _Domain(spec)
    ulb = spec.lattice_speed
    dh = create_data_handling(
        (dom.nx, dom.ny), periodicity=(False, True), default_target=Target.CPU
    )
    sgs = (SubgridScaleModel.SMAGORINSKY, spec.smagorinsky) if spec.smagorinsky > 0 else None
    flow_config = LBMConfig(
        stencil=LBStencil(Stencil.D2Q9),
        method=Method.CUMULANT,
        relaxation_rate=spec.relaxation,
        compressible=True,
        subgrid_scale_model=sgs,
    )
    flow = LatticeBoltzmannStep(
        data_handling=dh, lbm_config=flow_config, name="flow", compute_velocity_in_every_step=True
    )
    boundaries = flow.boundary_handling
    boundaries.set_boundary(UBB((ulb, 0.0)), make_slice[0, :])
    east = flow.method.stencil.index((1, 0))
    boundaries.set_boundary(
        ExtrapolationOutflow(flow.method.stencil[east], flow.method), make_slice[-1, :]
    )
    radius = spec.bar_diameter / 2.0 / dom.dx
    bx = (dom.bars_x - dom.x[0]) / dom.dx
    bys = (dom.bars_y - dom.y[0]) / dom.dx

    def bars(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        # x, y: cell coordinates (cell centres at i + 0.5); periodic crosswind
        inside = np.zeros(np.shape(x), dtype=bool)
        for by in bys:
            dy = np.abs(y - 0.5 - by)
            dy = np.minimum(dy, dom.ny - dy)
            inside |= (x - 0.5 - bx) ** 2 + dy**2 <= radius**2
        return inside

    boundaries.set_boundary(NoSlip(), mask_callback=bars)
    if solids is not None:
        if solids.shape != (dom.nx, dom.ny):
            raise ValueError(f"solids must be {(dom.nx, dom.ny)}, got {solids.shape}")
        if solids[dom.source]:
            raise DceeInputError(FIELD, "the source lies inside a building or wall")

        def walls(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            i = np.clip(np.floor(x).astype(int), 0, dom.nx - 1)
            j = np.clip(np.floor(y).astype(int), 0, dom.ny - 1)
            return solids[i, j]

        boundaries.set_boundary(NoSlip(), mask_callback=walls)
    rng = np.random.Generator(np.random.PCG64([0x1B3, spec.realisation]))
    velocity = dh.cpu_arrays[flow.velocity_data_name]
    velocity[..., 0] = ulb
    velocity[..., 1] = 0.0
    inner = (slice(1, -1), slice(1, -1))
    velocity[(*inner, 1)] = 0.02 * ulb * rng.standard_normal((dom.nx, dom.ny))
    if solids is not None:
        velocity[(*inner, 0)][solids] = 0.0  # the flow starts round the walls, not through them
        velocity[(*inner, 1)][solids] = 0.0
    flow.set_pdf_fields_from_macroscopic_values()

    dh.add_array("scalar", values_per_cell=1)
    scalar_config = LBMConfig(
        stencil=LBStencil(Stencil.D2Q9),
        method=Method.TRT,
        relaxation_rates=[_even_rate(spec.scalar_relaxation), spec.scalar_relaxation],
        compressible=True,
        zero_centered=False,
    )
    scalar = LatticeBoltzmannStep(
        data_handling=dh,
        lbm_config=scalar_config,
        name="scalar",
        velocity_input_array_name=flow.velocity_data_name,
        density_data_name="scalar",
        compute_density_in_every_step=True,
    )
    sx, sy = dom.source
    disc = spec.source_radius / dom.dx
    scalar.boundary_handling.set_boundary(
        DiffusionDirichlet(1.0),
        mask_callback=lambda x, y: (x - 0.5 - sx) ** 2 + (y - 0.5 - sy) ** 2 <= disc**2 + 1e-9,
    )
    scalar.boundary_handling.set_boundary(DiffusionDirichlet(0.0), make_slice[0, :])
    if solids is None:
        scalar.boundary_handling.set_boundary(NeumannByCopy(), make_slice[-1, :])
    else:
        # a building's wake reaches the outflow and flows back in there; the copied gradient
        # then grew without bound (measured on site:wall after 100 s); clean air comes back
        scalar.boundary_handling.set_boundary(DiffusionDirichlet(0.0), make_slice[-1, :])
        scalar.boundary_handling.set_boundary(NoSlip(), mask_callback=walls)
    dh.fill("scalar", 0.0, ghost_layers=True)
    scalar.set_pdf_fields_from_macroscopic_values()
    zero_streaming_targets(dh, flow, scalar)

    every = max(1, round(spec.frame_interval / dom.step_seconds))
    spin = math.ceil(spec.spinup / dom.step_seconds / every)
    frames = math.ceil(spec.duration / (every * dom.step_seconds))
    # stored as means over blocks of store_stride² cells (a restriction, not a pick): the scalar
    # lattice's checkerboard mode at high Péclet number (±, a few per mille of the peak round the
    # source) averages out instead of being sampled
    stride = spec.store_stride
    bx_n, by_n = dom.nx // stride, dom.ny // stride
    keep_x = np.arange(bx_n) * stride + (stride - 1) / 2.0
    keep_y = np.arange(by_n) * stride + (stride - 1) / 2.0
    out = np.empty((frames, by_n, bx_n), dtype=np.float32)
    if solids is not None:
        fluid = (~solids).astype(np.float64)
        fluid_blocks = fluid[: bx_n * stride, : by_n * stride].reshape(bx_n, stride, by_n, stride)
        fluid_count = np.maximum(fluid_blocks.sum(axis=(1, 3)), 1.0)
    flux_column = sx + round(FLUX_DISTANCE / dom.dx)
    flux = np.zeros(frames)
    v_source = np.zeros(frames)
    u_source = np.zeros(frames)
    total = (spin + frames) * every * dom.step_seconds
    source_peak = 0.0
    for k in range(spin + frames):
        for _ in range(every):
            flow.time_step()
            scalar.time_step()
        if progress is not None:
            progress((k + 1) * every * dom.step_seconds, total)
        c = dh.gather_array("scalar")
        v = dh.gather_array(flow.velocity_data_name)
        if not (np.isfinite(c[sx, sy]) and np.isfinite(v[flux_column, sy, 0])):
            raise unstable()
        if solids is not None:
            # whatever the wall cells hold is not gas (their own populations are never read
            # by the fluid: bounce-back reflects at the wall; left alone they may grow to inf)
            c = np.where(solids, 0.0, c)
        source_peak = bounded(c, float(c[sx, sy]), source_peak, k * every * dom.step_seconds)
        if k < spin:
            continue
        f = k - spin
        block = c[: bx_n * stride, : by_n * stride].reshape(bx_n, stride, by_n, stride)
        if solids is None:
            out[f] = np.maximum(block.mean(axis=(1, 3)), 0.0).T
        else:
            out[f] = np.maximum(block.sum(axis=(1, 3)) / fluid_count, 0.0).T
        flux[f] = float(np.sum(c[flux_column, :] * v[flux_column, :, 0]))
        u_source[f] = v[sx - round(2.0 / dom.dx), sy, 0]
        v_source[f] = v[sx - round(2.0 / dom.dx), sy, 1]
    if not np.all(np.isfinite(out)):
        raise DceeInputError(FIELD, "the lattice Boltzmann run produced NaN concentrations")
    # the mean flux (lattice units: scalar · lattice velocity per cell) → per metre of height
    # at the reference speed: flux_lu · (U / ulb) · dx; concentrations per unit of that flux
    mean_flux = float(np.mean(flux)) * (REFERENCE_SPEED / ulb) * dom.dx
    if not mean_flux > 0:
        raise DceeInputError(FIELD, "no scalar reached 10 m downwind: lengthen spinup")
    out /= np.float32(mean_flux)
    t = np.arange(frames) * every * dom.step_seconds
    sigma_v = float(np.std(v_source) / ulb)
    attrs = {
        "flux_lattice": float(np.mean(flux)),
        "flux_cv": float(np.std(flux) / np.mean(flux)),
        "turbulence_intensity_u": float(np.std(u_source) / ulb),
        "turbulence_intensity_v": sigma_v,
        "lagrangian_time_estimate": _integral_time(v_source, every * dom.step_seconds),
        "lattice_steps": (spin + frames) * every,
        "cells": dom.nx * dom.ny,
        "wall_seconds": _time.perf_counter() - started,
    }
    return {
        "concentration": out,
        "t": t,
        "x": dom.x[0] + keep_x * dom.dx,
        "y": dom.y[0] + keep_y * dom.dx,
        "attrs": attrs,
    }


def zero_streaming_targets(dh: Any, *steps: Any) -> None:
    """Zero the streaming targets of lbmpy steps (pdf arrays, ghost layers included): lbmpy
    allocates them uninitialised, and memory that an earlier computation in the same process
    freed held NaN bit patterns there: the run went NaN (measured: a 3-D run after a site's
    planar set-up in one process, never in a fresh one, whose fresh pages are zeros: the
    results of a fresh process are unchanged)."""
    for step in steps:
        dh.cpu_arrays[step._tmp_arr_name][...] = 0.0


BLOW_UP = 100.0
"""The most a cell of the air may hold, in units of the most the release cell has held so far,
before a run counts as diverged (:func:`unstable`). A conserved scalar obeys a maximum
principle: away from its release it never exceeds what the release cell holds (the stored
recordings of the open plume, of ``site:wall``, ``canyon``, ``block`` and of the example site:
at most 1.37 in 1 m block means after the first frames); ``site:passage``'s, computed
2026-12-05, reached 6.6e34 of it from 1465 s into the run (spin-up included), finite, every
concentration then divided by the diverged flux."""


def bounded(field: np.ndarray, at_source: float, source_peak: float, time: float) -> float:
    """The most the release cell has held, ``at_source`` (its value now) included; raises
    :func:`unstable` where a cell of the air ``field`` (walls zeroed) holds more than
    :data:`BLOW_UP` times that: a passive scalar has no source but the release, so such a run
    diverged, though it may have stayed finite."""
    peak = max(source_peak, at_source)
    if not float(np.max(field)) <= BLOW_UP * peak:
        raise unstable(time)
    return peak


class LatticeDiverged(DceeInputError):
    """A lattice Boltzmann run that went NaN or diverged (:func:`unstable`)."""


def unstable(at: float | None = None) -> LatticeDiverged:
    """The one-line error of a run that went NaN or diverged (``at``: s into the run)."""
    when = "" if at is None else f" {at:.0f} s into the run"
    return LatticeDiverged(
        FIELD,
        f"the lattice Boltzmann run became unstable{when} (it diverged); lower lattice_speed or "
        "raise smagorinsky",
    )


MAGIC = 0.25
"""TRT "magic" product Λ = (1/ω₊ − 1/2)(1/ω₋ − 1/2) of the scalar lattice: 1/4, the choice that
is stable for advection-diffusion at every Péclet number (Ginzburg's TRT analysis)."""


def _even_rate(odd: float) -> float:
    """The even-moment rate ω₊ that makes Λ = :data:`MAGIC` with the odd (diffusive) rate."""
    return 1.0 / (MAGIC / (1.0 / odd - 0.5) + 0.5)


def _integral_time(series: np.ndarray, dt: float) -> float:
    """Integral time scale (s) of a series: its autocorrelation integrated to the first zero."""
    s = np.asarray(series, dtype=np.float64) - np.mean(series)
    var = float(np.dot(s, s))
    if var <= 0:
        return 0.0
    n = len(s)
    acf = np.correlate(s, s, mode="full")[n - 1 :] / var
    below = np.nonzero(acf <= 0)[0]
    end = int(below[0]) if len(below) else n
    return float(np.sum(acf[:end]) * dt)


__all__ = [
    "FLUX_DISTANCE",
    "MAGIC",
    "REFERENCE_SPEED",
    "LatticeDiverged",
    "Solid",
    "bounded",
    "solid_cells",
    "solve",
    "unstable",
    "zero_streaming_targets",
]
