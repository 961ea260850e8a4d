"""A 3-D plume computed by a fluid solver: lbmpy's large-eddy simulation of a neutral surface
layer (:mod:`dcee.simulation.lbm3d_solver`).

Every other plume here that nobody here wrote holds one horizontal plane. This one has height:
the mean wind grows with height by the log law over rough ground, the surface layer's eddies
meander the plume, and a release near the ground reaches a UAV flying above it only some way
downwind, where the plume has grown up to it. The search on it is 3-D and the source height is
estimated.

**Units.** The canonical frame has the source at x = y = 0, ``h`` above the ground (the centre
of the lattice cell holding the scenario's source height, :func:`lattice_height`) and the mean
wind along +x at 1 m/s at 4 m. Stored concentrations are per unit of the mean scalar flux 10 m
downwind: the plume of 1 g/s at 1 m/s, g/m³. A scenario with release ``q`` g/s at height
``z_s``, wind ``u`` m/s (at 4 m) from ``phi`` replays it at

    c(p, t) = c₁(R(p − s)_xy, p_z − (z_s − h), (t + t₀) u) · q / u

(R turns the wind direction onto +x, t₀ a seeded start in the recording, which loops): the
field is moved up or down by the at most half a cell between the source and its cell's centre.
Below the lowest stored cell centre (0.25 m with the default 0.5 m lattice) the field is that
cell's; above the stored height and outside the domain it is 0.

:func:`cached_recording` computes a parameter set and source cell once and keeps it as a 3-D
CF NetCDF file (time, z, y, x) in the cache folder of :func:`dcee.simulation.lbm.cache_folder`.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.io import check_writable_dir
from dcee.provenance import package_version
from dcee.scenarios.schema.truth import Lbm3dSpec
from dcee.simulation.lbm import cache_folder, save_dataset, xarray_module
from dcee.simulation.lbm3d_solver import (
    REFERENCE_HEIGHT,
    lattice_height,
    solve,
    source_layer,
)
from dcee.simulation.lbm_solver import FIELD, REFERENCE_SPEED, Progress
from dcee.simulation.playback import PlaybackTruth, load_cf_recording
from dcee.simulation.truth import TruthModel, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import Scenario

FORMAT = 1
"""Bumped when the stored file's layout or the solver setup changes (part of the cache key)."""


def cache_key(spec: Lbm3dSpec, height: float) -> str:
    """Hash of everything that decides the computed field: the parameters and the source's
    lattice layer."""
    doc: dict[str, Any] = {"format": FORMAT, "layer": source_layer(spec, height)}
    doc.update(spec.model_dump(mode="json", exclude={"plane"}))  # a slice reads the same run
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:16]


def cache_path(spec: Lbm3dSpec, height: float) -> Path:
    return cache_folder() / f"lbm3d-{cache_key(spec, height)}.nc"


def write_recording(path: Path, spec: Lbm3dSpec, run: dict[str, Any]) -> None:
    """Write a run as a 3-D CF-convention NetCDF recording (time, z, y, x), atomically."""
    xr = xarray_module("lbm3d")
    import lbmpy

    attrs = dict(run["attrs"])
    ds = xr.Dataset(
        {
            "concentration": (
                ("time", "z", "y", "x"),
                np.ascontiguousarray(run["concentration"].transpose(0, 3, 1, 2)),
                {
                    "units": "g m-3",
                    "long_name": "concentration for a release of 1 g/s in a mean wind of "
                    f"1 m/s at {REFERENCE_HEIGHT:g} m",
                },
            )
        },
        coords={
            "time": ("time", run["t"], {"units": "s", "axis": "T", "standard_name": "time"}),
            "z": (
                "z",
                run["z"],
                {"units": "m", "axis": "Z", "standard_name": "height", "positive": "up"},
            ),
            "y": ("y", run["y"], {"units": "m", "axis": "Y", "long_name": "crosswind, left"}),
            "x": ("x", run["x"], {"units": "m", "axis": "X", "long_name": "downwind"}),
        },
        attrs={
            "Conventions": "CF-1.8",
            "title": "dcee lbm3d plume (canonical frame: source at x = y = 0, wind +x at 1 m/s "
            f"at {REFERENCE_HEIGHT:g} m)",
            "source": f"lbmpy {lbmpy.__version__} lattice Boltzmann LES; dcee {package_version()}",
            "source_location": np.array([0.0, 0.0, attrs["release_height"]]),
            "parameters": json.dumps(spec.model_dump(mode="json"), sort_keys=True),
            **attrs,
        },
    )
    save_dataset(path, ds)


def check_release_height(spec: Lbm3dSpec, height: float, field: str) -> None:
    """:class:`DceeInputError` naming ``field`` unless a release ``height`` m above the ground
    lies in the stored layer with its source ball (0 to ``store_height`` − ``source_radius``):
    above it the solver has no cell to hold it (an IndexError before)."""
    top = spec.store_height - spec.source_radius
    if not 0.0 <= height <= top:
        raise DceeInputError(
            field,
            f"a release {height:g} m above the ground is outside the 3-D plume's stored layer "
            f"(0 to {top:g} m: truth.model.store_height {spec.store_height:g} m less the source "
            f"ball's {spec.source_radius:g} m)",
        )


def cached_recording(
    spec: Lbm3dSpec,
    height: float,
    progress: Progress | None = None,
) -> Path:
    """The CF NetCDF recording of ``spec`` for a release ``height`` m above the ground,
    computed and cached on first use (the cache folder checked before the solver runs)."""
    check_release_height(spec, height, "height")
    path = cache_path(spec, height)
    if path.is_file():
        return path
    check_writable_dir(path.parent, "cache")
    run = solve(spec, height, progress)
    write_recording(path, spec, run)
    return path


def recording_attrs(path: Path) -> dict[str, Any]:
    """The solver's statistics stored in a recording's global attributes."""
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return dict(ds.attrs)


class SolverPlume3dTruth(TruthModel):
    """The canonical 3-D recording moved to a scenario's source, wind direction and speed.

    Parameters
    ----------
    recording : the canonical :class:`PlaybackTruth` (looped, with a z axis).
    source : (3,) m, the release (its height above the ground is ``source[2]``).
    release_height : m, the height the recording releases at (its source cell's centre).
    q : release rate, g/s.
    u : mean wind speed at 4 m, m/s (> 0).
    phi : wind direction, rad (the wind comes from it, :mod:`dcee.models.plume`).
    start : canonical seconds into the recording at episode time 0.
    ground : m, the world's height of the ground (the search volume's floor).
    plane : m (world z): read every position in this horizontal slice (a planar truth), or
        None for the 3-D field.
    """

    name = "lbm3d"
    label = "lbm3d plume"

    def __init__(
        self,
        recording: PlaybackTruth,
        source: np.ndarray,
        release_height: float,
        q: float,
        u: float,
        phi: float,
        start: float,
        ground: float = 0.0,
        plane: float | None = None,
    ) -> None:
        if not u > 0:
            raise DceeInputError("truth.u", "the lbm3d truth needs a wind (u > 0)")
        if recording.z is None:
            raise DceeInputError(FIELD, "the lbm3d recording has no z axis")
        self.recording = recording
        self.source = np.asarray(source, dtype=np.float64)[:3]
        self.downwind = -np.array([math.cos(phi), math.sin(phi)])
        self.left = np.array([-self.downwind[1], self.downwind[0]])
        self.speed_ratio = u / REFERENCE_SPEED
        self.scale = q / self.speed_ratio
        self.start = start
        # world height → canonical height: the source's height above the ground lands on the
        # recording's release height
        self.lift = release_height - (self.source[2] - ground)
        self.ground = ground
        self.plane = plane

    @property
    def time_step(self) -> float | None:
        step = self.recording.time_step
        return None if step is None else step / self.speed_ratio

    def canonical(self, positions: np.ndarray) -> np.ndarray:
        """(K, 3) canonical (downwind, crosswind, height) coordinates of (K, 3) positions, m."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        d = p[:, :2] - self.source[:2]
        z = p[:, 2] if self.plane is None else np.full(len(p), self.plane)
        height = z - self.ground + self.lift
        return np.stack([d @ self.downwind, d @ self.left, height], axis=1)

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) g/m³ at (K, 3) positions at episode ``time`` s; 0 outside the computed domain
        and above the stored height."""
        c = self.canonical(positions)
        rec = self.recording
        assert rec.z is not None
        inside = (
            (c[:, 0] >= rec.x[0])
            & (c[:, 0] <= rec.x[-1])
            & (c[:, 1] >= rec.y[0])
            & (c[:, 1] <= rec.y[-1])
            & (c[:, 2] <= rec.z[-1])
        )
        out = np.zeros(len(c))
        if np.any(inside):
            p = c[inside]
            p[:, 2] = np.maximum(p[:, 2], rec.z[0])
            out[inside] = rec.field(p, self.start + time * self.speed_ratio) * self.scale
        return out

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.reshape(position, (1, 3)), time)[0])


def load_canonical(path: Path) -> tuple[PlaybackTruth, float]:
    """(looped canonical truth, its release height m) from a cached recording."""
    truth, source = load_cf_recording(path, "linear", True)
    if source is None:
        raise DceeInputError(FIELD, f"{path.name} does not say where it releases")
    return truth, float(source[2])


@register_truth("lbm3d")
def lbm3d_truth(scenario: Scenario, seed: int) -> SolverPlume3dTruth:
    """The 3-D solver plume for ``scenario`` (computed once per parameter set and source cell,
    then cached); the run ``seed`` picks where in the looped recording the search starts."""
    spec = scenario.truth.model
    if not isinstance(spec, Lbm3dSpec):
        raise DceeInputError("truth.model", "expected the lbm3d parameters")
    if scenario.world.walls:
        raise DceeInputError(
            "truth.model", "the lbm3d plume is open terrain; a site's walls need truth.model = lbm"
        )
    theta = scenario.truth_theta()
    ground = float(scenario.volume.low[2])
    height = float(theta[2]) - ground
    check_release_height(spec, height, "truth.z")
    recording, release = load_canonical(cached_recording(spec, height))
    rng = np.random.Generator(np.random.PCG64([0x3D1B, 1, seed]))
    start = float(rng.uniform(0.0, recording.period))
    return SolverPlume3dTruth(
        recording, theta[:3], release, theta[3], theta[4], theta[5], start, ground, spec.plane
    )


__all__ = [
    "SolverPlume3dTruth",
    "cache_path",
    "cached_recording",
    "lattice_height",
    "load_canonical",
    "recording_attrs",
    "write_recording",
]
