"""The fluid solver behind the ``lbm3d`` truth (:mod:`dcee.simulation.lbm3d`): a 3-D lattice
Boltzmann large-eddy simulation of a neutral surface layer over rough ground (`lbmpy
<https://pypi.org/project/lbmpy/>`_), in the canonical frame (source at x = y = 0 at height
``h`` above the ground, mean wind +x at 1 m/s at :data:`REFERENCE_HEIGHT`).

**Flow.** The incompressible Navier-Stokes equations in 3-D (D3Q19 cumulant lattice Boltzmann,
Smagorinsky subgrid model) in a box ``[-inflow_distance, downstream] × [-width/2, width/2] ×
[0, height]`` m, periodic crosswind. The inflow holds the neutral surface layer's log law
u(z) = (u*/κ) ln(z/z0), scaled to 1 m/s at :data:`REFERENCE_HEIGHT` (lbmpy's ``UBB`` with a
profile callback); the ground is lbmpy's wall-function bounce-back (``WallFunctionBounce``)
with the Monin-Obukhov similarity wall model (``MoninObukhovSimilarityTheory``, neutral, the
roughness length ``roughness``) on an exponentially filtered reference velocity; the lid is
free-slip and the outflow extrapolating. Eddies enter with the wind
(:class:`_InflowEddies`: the surface layer's velocity variances, correlated over
``eddy_length`` and ``eddy_time``) ``inflow_distance`` upstream of the source and are carried,
stretched and dissipated by the solver; the plume meanders in them. A seeded perturbation of
the initial velocity and the eddies' seed (``realisation``) make each realisation its own.

**Scalar.** A second lattice (D3Q7 advection-diffusion, two relaxation times with the "magic"
Λ = 1/4 of :mod:`dcee.simulation.lbm_solver`, the flow's velocity as input) carries a passive
scalar from the lattice cells within ``source_radius`` of the source, held at a fixed value;
zero at the inflow, zero-gradient at the outflow, no flux through the ground and the lid
(bounce-back).

**Units.** The ground lies on the face between the lattice's first two layers, so fluid cell
k (k ≥ 1) is centred (k − ½) · spacing above it; a source's height is the centre of the cell
it lies in. The stored field is divided by the mean scalar flux through the cross-section
:data:`FLUX_DISTANCE` m downwind: the plume of 1 g/s at 1 m/s, g/m³.
"""

from __future__ import annotations

import math
import time as _time
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.scenarios.schema.truth import Lbm3dSpec
from dcee.simulation.lbm_solver import (
    FIELD,
    FLUX_DISTANCE,
    REFERENCE_SPEED,
    Progress,
    _even_rate,
    _integral_time,
    _lbmpy,
    unstable,
    zero_streaming_targets,
)

REFERENCE_HEIGHT = 4.0
"""m above the ground where the canonical mean wind is 1 m/s (the scenario's ``u``): the
paper's flight height, where its UAV measures the wind."""
KAPPA = 0.41
"""von Kármán's constant (the wall model's, anchors.md)."""


class _Domain:
    """Lattice geometry of a parameter set and a source height."""

    def __init__(self, spec: Lbm3dSpec, height: float) -> None:
        dx = spec.spacing
        self.dx = dx
        self.upstream = spec.inflow_distance
        self.nx = round((self.upstream + spec.downstream) / dx) + 1
        self.ny = round(spec.width / dx)
        self.ny += self.ny % 2
        self.nz = round(spec.height / dx) + 1  # + the ground's layer
        k = source_layer(spec, height)
        self.source = (round(self.upstream / dx), self.ny // 2, k)
        self.x = (np.arange(self.nx) - self.source[0]) * dx
        self.y = (np.arange(self.ny) - self.source[1]) * dx
        self.z = (np.arange(self.nz) - 0.5) * dx  # cell centres above the ground (k = 0: ground)
        self.step_seconds = spec.lattice_speed * dx / REFERENCE_SPEED
        """canonical seconds per lattice step"""


def source_layer(spec: Lbm3dSpec, height: float) -> int:
    """The lattice layer (≥ 1) whose cell holds a release ``height`` m above the ground."""
    return max(1, math.floor(height / spec.spacing) + 1)


def lattice_height(spec: Lbm3dSpec, height: float) -> float:
    """m: the height the solver releases at for a requested ``height`` (its cell's centre)."""
    return (source_layer(spec, height) - 0.5) * spec.spacing


def log_law(spec: Lbm3dSpec, z: np.ndarray) -> np.ndarray:
    """Mean wind (m/s, canonical) of the inflow at heights ``z`` m: (u*/κ) ln(z/z0), 1 m/s at
    :data:`REFERENCE_HEIGHT`."""
    z = np.maximum(np.asarray(z, dtype=np.float64), 1.5 * spec.roughness)
    return np.log(z / spec.roughness) / math.log(REFERENCE_HEIGHT / spec.roughness)


def friction_velocity(spec: Lbm3dSpec) -> float:
    """u* (m/s, canonical) of the inflow's log law."""
    return KAPPA * REFERENCE_SPEED / math.log(REFERENCE_HEIGHT / spec.roughness)


SURFACE_LAYER_SIGMAS = (2.4, 1.9, 1.25)
"""σu/u*, σv/u*, σw/u* of the neutral surface layer (Panofsky & Dutton 1984, *Atmospheric
Turbulence*, ch. 7): the inflow's eddies have these standard deviations (times
``turbulence``)."""


class _InflowEddies:
    """Turbulent eddies entering with the log-law wind: each velocity component at the inflow is
    the mean plus σ_i · ψ_i(y, z, t), ψ a unit-variance field, Gaussian-correlated crosswind
    (σ ``eddy_length``) and vertically (half of it), exponentially correlated in time (time
    constant ``eddy_time`` canonical s: Taylor's frozen eddies of about that length times the
    wind passing the inflow). A synthetic-inflow method in the spirit of Klein, Sadiki & Janicka
    (J. Comput. Phys. 186, 2003), written here; what the plume meets downstream is the solver's
    own turbulence, carried and dissipated by it."""

    def __init__(self, spec: Lbm3dSpec, dom: _Domain, handling: Any, ubb: Any, rng: Any) -> None:
        from scipy.ndimage import gaussian_filter

        self._filter = gaussian_filter
        self.rng = rng
        self.every = max(1, round(0.1 / dom.step_seconds))  # update every 0.1 canonical s
        self.count = 0
        dt = self.every * dom.step_seconds
        self.a = math.exp(-dt / spec.eddy_time)
        self.b = math.sqrt(1.0 - self.a**2)
        self.width = (spec.eddy_length / dom.dx, spec.eddy_length / 2.0 / dom.dx)
        self.shape = (dom.ny, dom.nz)
        delta = np.zeros(self.shape)
        delta[dom.ny // 2, dom.nz // 2] = 1.0
        self.norm = 1.0 / math.sqrt(float(np.sum(self._smooth(delta) ** 2)))
        ulb = spec.lattice_speed
        sigma = np.array(SURFACE_LAYER_SIGMAS) * friction_velocity(spec) * spec.turbulence * ulb
        self.sigma = sigma / REFERENCE_SPEED
        self.setters = []
        for block in handling._data_handling.iterate(ghost_layers=True):
            setter = block[handling._index_array_name].boundary_object_to_data_setter.get(ubb)
            if setter is not None:
                j = np.floor(setter.non_boundary_cell_positions(1)).astype(int) % dom.ny
                k = np.clip(np.floor(setter.non_boundary_cell_positions(2)).astype(int), 1, None)
                k = np.minimum(k, dom.nz - 1)
                mean = np.asarray(setter["vel_0"], dtype=np.float64).copy()
                self.setters.append((setter, j, k, mean))
        height = (np.arange(dom.nz) - 0.5) * dom.dx
        self.w_taper = 1.0 - np.exp(-np.maximum(height, 0.0) / max(spec.eddy_length / 4, 0.25))
        self.psi = np.stack([self._noise() for _ in range(3)])

    def _smooth(self, field: np.ndarray) -> np.ndarray:
        return self._filter(field, self.width, mode=("wrap", "nearest"))

    def _noise(self) -> np.ndarray:
        return self._smooth(self.rng.standard_normal(self.shape)) * self.norm

    def step(self) -> None:
        """Advance one lattice step; every 0.1 canonical s the eddies move on."""
        self.count += 1
        if self.count % self.every:
            return
        for c in range(3):
            self.psi[c] = self.a * self.psi[c] + self.b * self._noise()
        for setter, j, k, mean in self.setters:
            setter["vel_0"] = mean + self.sigma[0] * self.psi[0][j, k]
            setter["vel_1"] = self.sigma[1] * self.psi[1][j, k]
            setter["vel_2"] = self.sigma[2] * self.psi[2][j, k] * self.w_taper[k]


def solve(spec: Lbm3dSpec, height: float, progress: Progress | None = None) -> dict[str, Any]:
    """Run the solver for a release ``height`` m above the ground: ``concentration`` (T, ny,
    nx, nz) float32 g/m³ for 1 g/s at 1 m/s, axes ``t`` (s from the first stored frame),
    ``x``, ``y`` (m, source at the origin), ``z`` (m above the ground), and ``attrs`` (flux,
    the release height, turbulence statistics upwind of the source, timings)."""
    _lbmpy()
    from lbmpy import LBMConfig, LBStencil, Method, Stencil, SubgridScaleModel
    from lbmpy.boundaries import (
        UBB,
        DiffusionDirichlet,
        ExtrapolationOutflow,
        FreeSlip,
        NeumannByCopy,
        NoSlip,
    )
    from lbmpy.boundaries.boundaryconditions import WallFunctionBounce
    from lbmpy.boundaries.wall_function_models import MoninObukhovSimilarityTheory
    from lbmpy.lbstep import LatticeBoltzmannStep
    from pystencils import Target, create_data_handling, make_slice

    started = _time.perf_counter()
    dom = _Domain(spec, height)
    ulb = spec.lattice_speed
    dh = create_data_handling(
        (dom.nx, dom.ny, dom.nz), periodicity=(False, True, False), default_target=Target.CPU
    )
    sgs = (SubgridScaleModel.SMAGORINSKY, spec.smagorinsky) if spec.smagorinsky > 0 else None
    flow = LatticeBoltzmannStep(
        data_handling=dh,
        lbm_config=LBMConfig(
            stencil=LBStencil(Stencil.D3Q19),
            method=Method.CUMULANT,
            relaxation_rate=spec.relaxation,
            compressible=True,
            subgrid_scale_model=sgs,
        ),
        name="flow3d",
        compute_velocity_in_every_step=True,
    )
    profile = ulb * log_law(spec, dom.z)  # lattice units, by layer (layer 0: the ground)

    def inflow(boundary_data: Any, **_: Any) -> None:
        k = np.clip(np.floor(boundary_data.link_positions(2)).astype(int), 1, dom.nz - 1)
        boundary_data["vel_0"] = profile[k]
        boundary_data["vel_1"] = 0.0
        boundary_data["vel_2"] = 0.0

    def ground_reference(boundary_data: Any, **_: Any) -> None:
        boundary_data["ref_vel_0"] = profile[1]
        boundary_data["ref_vel_1"] = 0.0

    b = flow.boundary_handling
    inflow_ubb = UBB(inflow, dim=3)
    b.set_boundary(inflow_ubb, make_slice[0, :, 1:])
    east = flow.method.stencil.index((1, 0, 0))
    b.set_boundary(
        ExtrapolationOutflow(flow.method.stencil[east], flow.method), make_slice[-1, :, 1:]
    )
    b.set_boundary(FreeSlip(flow.method.stencil, (0, 0, -1)), make_slice[1:-1, :, -1])
    ground = WallFunctionBounce(
        flow.method,
        dh.fields[flow.velocity_data_name],
        (0, 0, 1),
        MoninObukhovSimilarityTheory(spec.roughness / dom.dx, kappa=KAPPA),
        WallFunctionBounce.ReferenceVelocity.FILTERED_VELOCITY,
        filter_width=spec.wall_filter,
        reference_velocity_callback=ground_reference,
    )
    b.set_boundary(ground, make_slice[:, :, 0])
    rng = np.random.Generator(np.random.PCG64([0x3D1B, spec.realisation]))
    velocity = dh.cpu_arrays[flow.velocity_data_name]
    velocity[...] = 0.0
    inner = (slice(1, -1), slice(1, -1), slice(1, -1))  # the array has one ghost layer
    velocity[(*inner, 0)] = profile[None, None, :]
    for c in (1, 2):
        velocity[(*inner, c)] = 0.02 * ulb * rng.standard_normal((dom.nx, dom.ny, dom.nz))
    flow.set_pdf_fields_from_macroscopic_values()
    b.prepare()
    eddies = _InflowEddies(spec, dom, b, inflow_ubb, rng)

    dh.add_array("scalar3d", values_per_cell=1)
    scalar = LatticeBoltzmannStep(
        data_handling=dh,
        lbm_config=LBMConfig(
            stencil=LBStencil(Stencil.D3Q7),
            method=Method.TRT,
            relaxation_rates=[_even_rate(spec.scalar_relaxation), spec.scalar_relaxation],
            compressible=True,
            zero_centered=False,
        ),
        name="scalar3d",
        velocity_input_array_name=flow.velocity_data_name,
        density_data_name="scalar3d",
        compute_density_in_every_step=True,
    )
    sx, sy, sz = dom.source
    ball = spec.source_radius / dom.dx
    sb = scalar.boundary_handling
    sb.set_boundary(
        DiffusionDirichlet(1.0),
        mask_callback=lambda x, y, z: (
            ((x - 0.5 - sx) ** 2 + (y - 0.5 - sy) ** 2 + (z - 0.5 - sz) ** 2 <= ball**2 + 1e-9)
            & (z > 1.0)
        ),
    )
    sb.set_boundary(DiffusionDirichlet(0.0), make_slice[0, :, 1:])
    sb.set_boundary(NeumannByCopy(), make_slice[-1, :, 1:])
    sb.set_boundary(NoSlip(), make_slice[:, :, 0])
    sb.set_boundary(NoSlip(), make_slice[1:-1, :, -1])
    dh.fill("scalar3d", 0.0, ghost_layers=True)
    scalar.set_pdf_fields_from_macroscopic_values()
    zero_streaming_targets(dh, flow, scalar)

    every = max(1, round(spec.frame_interval / dom.step_seconds))
    spin = math.ceil(spec.spinup / dom.step_seconds / every)
    frames = math.ceil(spec.duration / (every * dom.step_seconds))
    stride = spec.store_stride
    bx_n, by_n = dom.nx // stride, dom.ny // stride
    top = min(dom.nz, 1 + round(spec.store_height / dom.dx))
    keep_x = np.arange(bx_n) * stride + (stride - 1) / 2.0
    keep_y = np.arange(by_n) * stride + (stride - 1) / 2.0
    out = np.empty((frames, by_n, bx_n, top - 1), dtype=np.float32)
    flux_column = sx + round(FLUX_DISTANCE / dom.dx)
    flux = np.zeros(frames)
    probe = (sx - round(2.0 / dom.dx), sy)  # 2 m upwind of the source
    u_probe = np.zeros((frames, dom.nz))
    v_probe = np.zeros(frames)
    w_probe = np.zeros(frames)
    total = (spin + frames) * every * dom.step_seconds
    for k in range(spin + frames):
        for _ in range(every):
            eddies.step()
            flow.time_step()
            scalar.time_step()
        if progress is not None:
            progress((k + 1) * every * dom.step_seconds, total)
        c = dh.gather_array("scalar3d")
        v = dh.gather_array(flow.velocity_data_name)
        if not (np.isfinite(c[sx, sy, sz]) and np.isfinite(v[flux_column, sy, sz, 0])):
            raise unstable()
        if k < spin:
            continue
        f = k - spin
        block = c[: bx_n * stride, : by_n * stride, 1:top]
        block = block.reshape(bx_n, stride, by_n, stride, top - 1).mean(axis=(1, 3))
        out[f] = np.maximum(block, 0.0).transpose(1, 0, 2)
        flux[f] = float(np.sum(c[flux_column, :, 1:] * v[flux_column, :, 1:, 0]))
        u_probe[f] = v[probe[0], probe[1], :, 0]
        v_probe[f] = v[probe[0], probe[1], sz, 1]
        w_probe[f] = v[probe[0], probe[1], sz, 2]
    if not np.all(np.isfinite(out)):
        raise DceeInputError(FIELD, "the lattice Boltzmann run produced NaN concentrations")
    # the mean flux (lattice units: scalar · lattice velocity per cell face) → g/s at the
    # reference speed: flux_lu · (U / ulb) · dx²; concentrations per unit of that flux
    mean_flux = float(np.mean(flux)) * (REFERENCE_SPEED / ulb) * dom.dx**2
    if not mean_flux > 0:
        raise DceeInputError(FIELD, "no scalar reached 10 m downwind: lengthen spinup")
    out /= np.float32(mean_flux)
    t = np.arange(frames) * every * dom.step_seconds
    mean_u = u_probe.mean(axis=0) / ulb
    ref = int(np.argmin(np.abs(dom.z - REFERENCE_HEIGHT)))
    attrs = {
        "release_height": float(dom.z[sz]),
        "flux_lattice": float(np.mean(flux)),
        "flux_cv": float(np.std(flux) / np.mean(flux)),
        "friction_velocity_inflow": friction_velocity(spec),
        "mean_wind_reference_height": float(mean_u[ref]),
        "mean_wind_profile": mean_u[1:].astype(np.float64),
        "mean_wind_heights": dom.z[1:].astype(np.float64),
        "turbulence_intensity_u": float(np.std(u_probe[:, sz]) / ulb),
        "turbulence_intensity_v": float(np.std(v_probe) / ulb),
        "turbulence_intensity_w": float(np.std(w_probe) / ulb),
        "lagrangian_time_estimate": _integral_time(v_probe, every * dom.step_seconds),
        "lattice_steps": (spin + frames) * every,
        "cells": dom.nx * dom.ny * dom.nz,
        "wall_seconds": _time.perf_counter() - started,
    }
    return {
        "concentration": out,
        "t": t,
        "x": dom.x[0] + keep_x * dom.dx,
        "y": dom.y[0] + keep_y * dom.dx,
        "z": dom.z[1:top].copy(),
        "attrs": attrs,
    }


__all__ = [
    "KAPPA",
    "REFERENCE_HEIGHT",
    "friction_velocity",
    "lattice_height",
    "log_law",
    "solve",
    "source_layer",
    "zero_streaming_targets",
]
