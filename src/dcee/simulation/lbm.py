"""A plume computed by a fluid solver: lattice Boltzmann (lbmpy) behind a turbulence grid.

The truths written here (filament, puffs) were written together with the reading model, so
their agreement with it proves little. This truth is computed by a solver nobody here wrote:
`lbmpy <https://pypi.org/project/lbmpy/>`_ (FAU Erlangen, code generation of compiled
lattice Boltzmann kernels), chosen by measurement (docs/scenarios.md: phiflow's NumPy backend
took 0.9 s per step of a 256 × 128 grid on this 2-core machine, lbmpy 0.7 ms per step of a
200 × 144 grid with the scalar, about 1,000 times less per cell; one unstored scratch run of
each, a lab note rather than a benchmark).

The solver (its flow, its scalar and the choices made in it) is :mod:`dcee.simulation.lbm_solver`.

**Units.** The canonical frame has the source at the origin and the mean wind along +x at
``U = 1`` m/s, so one lattice step is ``lattice_speed · spacing`` s. Recorded concentrations are
divided by the mean scalar flux through the cross-section 10 m downwind (the release per metre
of plane), so the stored field is the plume of 1 g/s per metre of height at 1 m/s, in g/m³. A
scenario with release ``q`` g/s, wind ``u`` m/s from ``phi`` replays it at
``c = c₁(R(p − s), (t + t₀) u) · (q / layer_depth) / u`` (R turns the wind direction onto +x,
t₀ a seeded start in the recording, which loops).

:func:`cached_recording` computes a parameter set once and keeps it as a CF NetCDF file in the
cache folder (``$DCEE_CACHE`` or ``~/.cache/dcee``, file named by a hash of the parameters);
:class:`SolverPlumeTruth` replays it through :class:`~dcee.simulation.playback.PlaybackTruth`.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.io import check_writable_dir, write_atomic
from dcee.provenance import package_version
from dcee.scenarios.schema.truth import LbmSpec
from dcee.simulation.lbm_solver import (
    FIELD,
    REFERENCE_SPEED,
    LatticeDiverged,
    Progress,
    solid_cells,
    solve,
)
from dcee.simulation.playback import PlaybackTruth, load_cf_recording
from dcee.simulation.truth import TruthModel, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import Scenario

FORMAT = 3
"""Bumped when the stored file's layout or the solver setup changes (part of the cache key).
3 (2026-12-05): a run that diverged is refused (:data:`dcee.simulation.lbm_solver.BLOW_UP`), so
a recording cached before that holds a diverged run (``site:passage``'s did) is not read."""


def cache_folder() -> Path:
    """Where computed plumes are kept: ``$DCEE_CACHE`` or ``~/.cache/dcee``, then ``plumes``."""
    root = os.environ.get("DCEE_CACHE") or str(Path.home() / ".cache" / "dcee")
    return Path(root) / "plumes"


def cache_key(spec: LbmSpec, solids: np.ndarray | None = None) -> str:
    """Hash of everything that decides the computed field (the walls' lattice mask included)."""
    doc: dict[str, Any] = {"format": FORMAT}
    doc.update(spec.model_dump(mode="json", exclude={"layer_depth"}))
    if solids is not None:
        mask = np.packbits(np.asarray(solids, dtype=bool), axis=None).tobytes()
        doc["solids"] = [list(np.shape(solids)), hashlib.sha256(mask).hexdigest()]
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:16]


def cache_path(spec: LbmSpec, solids: np.ndarray | None = None) -> Path:
    return cache_folder() / f"lbm-{cache_key(spec, solids)}.nc"


SITE_MARGIN = 10.0
"""m: on a site, the domain reaches this far beyond the search area crosswind and downwind, and
the turbulence grid stands at least this far (plus its near wake, 15 m) upwind of it."""


SITE_EDGE = 4.0
"""m: a band along the domain's edges kept air, so that no wall cell lies against the open
boundaries (a real map's block reaches past the search area and the domain's edge cuts it).
Measured on the Fontvieille site (wind from 315°, 2026-12-05): with walls on the edges the run
diverged 248 s in at lattice speed 0.02, with the band 456 s in; it took
:data:`SITE_FALLBACK_RELAXATION` as well to run through (whether that alone would have done
was not tried). The band lies at least :data:`SITE_MARGIN` − 4 m beyond the search area; no
earlier site had a wall there, so their recordings are unchanged (the mask is part of the
cache key)."""


SITE_FALLBACK_RELAXATION = 1.9
"""The flow's relaxation rate of a site whose run diverged at :data:`SITE_FALLBACK_SPEED` too:
a viscosity five times the default's (ω 1.99), the Smagorinsky eddy viscosity on top. Needed by
the block of Monaco's real map (``area:fontvieille``: diverged 456 s into the run at 0.02 with
ω 1.99, its streets 10-20 m wide between blocks up to 30 m, 2026-12-05); no earlier site
reaches it (each is stable at 0.03 or 0.02), so their recordings are unchanged."""


SITE_FALLBACK_SPEED = 0.02
"""The inflow's lattice speed of a site whose run at :data:`SITE_LATTICE_SPEED` diverged
(:class:`~dcee.simulation.lbm_solver.LatticeDiverged`): ``site:passage``'s jet through its 4 m
gap diverged at 0.03 (1465 s into the run) and is stable at 0.02 (flux coefficient of variation
0.29; measured 2026-12-05, as was a Smagorinsky constant of 0.2 at 0.03: 0.44). The slower
lattice takes 1.5 times the steps; a site stable at 0.03 keeps its plume."""

SITE_LATTICE_SPEED = 0.03
"""The inflow's lattice speed on a site at most. The flow speeds up round a building's ends and
in its wake (to 4.6 times the inflow on ``site:wall``, a 35 m wall across the plume), and the
scalar lattice grew without bound where the local speed neared 0.2 (measured at 0.1 and 0.05;
stable at 0.03 for 800 s). The relaxation rates are kept, so the physical viscosity and the
scalar's diffusivity are 0.1/0.03 = 3.3 times the open terrain's (0.15 m²/s for the scalar;
rates that keep them were unstable, measured): a site's plume is smoother than the open one."""


def site_frame(
    spec: LbmSpec,
    low: tuple[float, float],
    high: tuple[float, float],
    source: np.ndarray,
    phi: float,
    solid: Callable[[np.ndarray], np.ndarray],
) -> tuple[LbmSpec, np.ndarray | None]:
    """The solver set-up of a site: ``spec`` with the domain grown to hold the search area
    ``low``–``high`` (m) seen from the source (x, y) with the wind from ``phi`` (rad), and the
    lattice mask of the cells whose centre ``solid`` ((K, 2) world points → (K,) bool) calls a
    building or wall (None when no cell is: open terrain, the open-terrain recording)."""
    downwind = -np.array([math.cos(phi), math.sin(phi)])
    left = np.array([-downwind[1], downwind[0]])
    corners = np.array([[x, y] for x in (low[0], high[0]) for y in (low[1], high[1])])
    rel = corners - np.asarray(source, dtype=np.float64)[:2]
    along, across = rel @ downwind, rel @ left
    grown = spec.model_copy(
        update={
            "downstream": max(spec.downstream, float(along.max()) + SITE_MARGIN),
            "width": max(spec.width, 2.0 * float(np.abs(across).max()) + 2.0 * SITE_MARGIN),
            "grid_distance": max(spec.grid_distance, -float(along.min()) + SITE_MARGIN + 15.0),
            "lattice_speed": min(spec.lattice_speed, SITE_LATTICE_SPEED),
        }
    )

    def canonical_solid(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        world = source[None, :2] + x[:, None] * downwind[None] + y[:, None] * left[None]
        return solid(world)

    solids = solid_cells(grown, canonical_solid)
    edge = max(1, round(SITE_EDGE / grown.spacing))
    solids[:edge, :] = solids[-edge:, :] = False
    solids[:, :edge] = solids[:, -edge:] = False
    if not solids.any():
        return spec, None
    return grown, solids


def xarray_module(truth: str) -> Any:
    """xarray, or the one-line error naming the extra that brings it."""
    try:
        import xarray
    except ImportError:
        raise DceeInputError(
            FIELD, f"the {truth} truth needs xarray: pip install 'dcee[fluid]'"
        ) from None
    return xarray


def save_dataset(path: Path, ds: Any) -> None:
    """Write a solver's CF dataset to ``path`` (NetCDF-4, the concentration compressed),
    atomically: an interrupted write leaves no file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    encoding = {"concentration": {"zlib": True, "complevel": 4, "shuffle": True}}
    write_atomic(path, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf", encoding=encoding))


def write_recording(path: Path, spec: LbmSpec, run: dict[str, Any]) -> None:
    """Write a run as a CF-convention NetCDF recording (xarray + h5netcdf), atomically."""
    xr = xarray_module("lbm")
    import lbmpy

    ds = xr.Dataset(
        {
            "concentration": (
                ("time", "y", "x"),
                run["concentration"],
                {
                    "units": "g m-3",
                    "long_name": "concentration for a release of 1 g/s per metre of height "
                    "in a 1 m/s mean wind",
                },
            )
        },
        coords={
            "time": ("time", run["t"], {"units": "s", "axis": "T", "standard_name": "time"}),
            "x": ("x", run["x"], {"units": "m", "axis": "X", "long_name": "downwind"}),
            "y": ("y", run["y"], {"units": "m", "axis": "Y", "long_name": "crosswind, left"}),
        },
        attrs={
            "Conventions": "CF-1.8",
            "title": "dcee lbm plume (canonical frame: source at the origin, wind +x at 1 m/s)",
            "source": f"lbmpy {lbmpy.__version__} lattice Boltzmann; dcee {package_version()}",
            "source_location": np.array([0.0, 0.0, 0.0]),
            "parameters": json.dumps(spec.model_dump(mode="json"), sort_keys=True),
            **{k: v for k, v in run["attrs"].items()},
        },
    )
    save_dataset(path, ds)


def cached_recording(
    spec: LbmSpec,
    progress: Progress | None = None,
    announce: Callable[[str], None] | None = None,
    solids: np.ndarray | None = None,
) -> Path:
    """The CF NetCDF recording of ``spec`` (with the walls ``solids``, :func:`site_frame`),
    computed and cached on first use."""
    path = cache_path(spec, solids)
    if path.is_file():
        return path
    marker = path.with_suffix(".diverged")
    slower = solids is not None and _fallback(spec) != spec
    if slower and marker.is_file():
        return cached_recording(_fallback(spec), progress, announce, solids)
    check_writable_dir(path.parent, "cache")  # before minutes of solving, not after
    if announce is not None:
        announce(f"dcee: computing the lbm plume once (cached as {path})")
    try:
        run = solve(spec, progress, solids)
    except LatticeDiverged:
        if not slower:
            raise
        # a site's jet diverged with this set-up: once more, steadier (:func:`_fallback`;
        # remembered, so the diverging run is not repeated)
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text(
            f"diverged at lattice_speed {spec.lattice_speed:g}, relaxation {spec.relaxation:g}\n",
            encoding="utf-8",
        )
        return cached_recording(_fallback(spec), progress, announce, solids)
    write_recording(path, spec, run)
    return path


def _fallback(spec: LbmSpec) -> LbmSpec:
    """The next, steadier set-up of a site whose run diverged: first :data:`SITE_FALLBACK_SPEED`,
    then also :data:`SITE_FALLBACK_RELAXATION`; ``spec`` itself after both (no further try)."""
    if spec.lattice_speed > SITE_FALLBACK_SPEED:
        return spec.model_copy(update={"lattice_speed": SITE_FALLBACK_SPEED})
    if spec.relaxation > SITE_FALLBACK_RELAXATION:
        return spec.model_copy(update={"relaxation": SITE_FALLBACK_RELAXATION})
    return spec


class SolverPlumeTruth(TruthModel):
    """The canonical recording moved to a scenario's source, wind direction and speed.

    Parameters
    ----------
    recording : the canonical :class:`PlaybackTruth` (looped).
    source : (3,) m; only x, y matter (the plume is planar).
    q : release rate, g/s.
    u : mean wind speed, m/s (> 0).
    phi : wind direction, rad (the wind comes from it, :mod:`dcee.models.plume`).
    layer_depth : m, the depth the release is spread over.
    start : canonical seconds into the recording at episode time 0.
    """

    name = "lbm"
    label = "lbm plume"

    def __init__(
        self,
        recording: PlaybackTruth,
        source: np.ndarray,
        q: float,
        u: float,
        phi: float,
        layer_depth: float,
        start: float,
    ) -> None:
        if not u > 0:
            raise DceeInputError("truth.u", "the lbm truth needs a wind (u > 0)")
        self.recording = recording
        self.source = np.asarray(source, dtype=np.float64)[:2]
        self.downwind = -np.array([math.cos(phi), math.sin(phi)])
        self.left = np.array([-self.downwind[1], self.downwind[0]])
        self.speed_ratio = u / REFERENCE_SPEED
        self.scale = q / layer_depth / self.speed_ratio
        self.start = start

    @property
    def time_step(self) -> float | None:
        step = self.recording.time_step
        return None if step is None else step / self.speed_ratio

    def canonical(self, positions: np.ndarray) -> np.ndarray:
        """(K, 2) canonical (downwind, crosswind) coordinates of (K, 3) positions, m."""
        d = np.asarray(positions, dtype=np.float64).reshape(-1, 3)[:, :2] - self.source
        return np.stack([d @ self.downwind, d @ self.left], axis=1)

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) g/m³ at (K, 3) positions at episode ``time`` s; 0 outside the computed domain."""
        xy = self.canonical(positions)
        rec = self.recording
        inside = (
            (xy[:, 0] >= rec.x[0])
            & (xy[:, 0] <= rec.x[-1])
            & (xy[:, 1] >= rec.y[0])
            & (xy[:, 1] <= rec.y[-1])
        )
        out = np.zeros(len(xy))
        if np.any(inside):
            p = np.zeros((int(np.count_nonzero(inside)), 3))
            p[:, :2] = xy[inside]
            out[inside] = rec.field(p, self.start + time * self.speed_ratio) * self.scale
        return out

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.reshape(position, (1, 3)), time)[0])


def load_canonical(path: Path) -> PlaybackTruth:
    truth, _ = load_cf_recording(path, "linear", True)
    return truth


@register_truth("lbm")
def lbm_truth(scenario: Scenario, seed: int) -> SolverPlumeTruth:
    """The solver plume for ``scenario`` (computed once per parameter set, then cached); the
    run ``seed`` picks where in the looped recording the search starts."""
    spec = scenario.truth.model
    theta = scenario.truth_theta()
    solids = None
    if scenario.world.walls:
        # the gas flows around the site's buildings and walls (not its no-go zones)
        spec, solids = site_frame(
            spec,
            tuple(scenario.volume.low[:2]),
            tuple(scenario.volume.high[:2]),
            theta[:2],
            float(theta[5]),
            lambda xy: scenario.in_obstacle(xy, no_go=False),
        )
    recording = load_canonical(cached_recording(spec, solids=solids))
    rng = np.random.Generator(np.random.PCG64([0x1B3, 1, seed]))
    start = float(rng.uniform(0.0, recording.period))
    return SolverPlumeTruth(
        recording, theta[:3], theta[3], theta[4], theta[5], spec.layer_depth, start
    )


__all__ = [
    "SolverPlumeTruth",
    "cache_folder",
    "cache_path",
    "cached_recording",
    "site_frame",
    "solve",
    "write_recording",
]
