"""The scenario of a room simulated by GADEN, built from its folder alone (``dcee run --truth
DIR``, ``load_scenario(DIR)``): what a user who hands dcee a GADEN simulation expects, at room
scale. Every value is listed with its reason in docs/guide/plume-data.md; none was tuned on the
two sample rooms beyond what is said there.

* **Area**: the box of the room's free cells (GADEN's occupancy grid), every height.
* **Truth**: the release the result files name; its rate from ``sim.yaml``'s
  ``numFilaments_sec`` × the files' moles per filament × the gas's molar mass (for the record:
  the estimator does not read it); u and φ the wind of the source's cell. The source height is
  estimated (``dimensions = 3``).
* **Obstacles**: where an obstacle cell lies inside the area at the sensor's height (furniture,
  an inner wall; the area's outermost ring of cells, the walls beside the doors, left out), the
  occupancy grid's obstacle cells at that height become the scenario's ``world.map``
  (a ROS map file in ``$DCEE_CACHE`` or ``~/.cache/dcee``, ``maps/``): the robot never enters
  or crosses a blocked cell. An empty room (the samples) gets none.
* **Robot**: a ground robot with its sensor at :data:`SENSOR_HEIGHT` (0.5 m), 0.5 m steps at
  0.5 m/s (the lab's 0.3 m in a 4.5 m room scaled to a 10 m one), a 4 s hold per reading (the
  default on a time-varying truth); it starts at the free cell at sensor height farthest from
  the release (``--set agent.start=[x, y, 0.5]`` for another).
* **What the estimator knows**: the room's map and its whole wind field, as a building's CFD
  model would give it (GADEN's wind file): the estimator's plume is the room's own
  (``estimator.plume = "walls"`` with ``wall_wind = "room"``, :mod:`dcee.models.room_plume`),
  the gas carried by that wind round walls and out through the doors, its diffusivity weighed
  at :data:`~dcee.models.room_plume.ROOM_DIFFUSIVITY` and 3 and 10 times it. The source, its
  height included, and its rate are unknown (``unknown = "source"``; q gamma with mean 10 mg/s).
  Chosen on the samples: with only the wind the robot measures (``--set unknown=full --set
  estimator.plume=open``, the priors below) the solver-wind room's searches ended a median
  1.16 m off (docs/plumes.md reports both).
* **What a robot alone could know** (``unknown = "full"``, ``estimator.plume = "open"``): the
  room's size and the wind it measures at its start. Where that wind is at least :data:`CALM`
  (0.1 m/s), the prior of φ is centred on its direction (sd 30°) and of u on its speed (sd 0.3
  m/s); a slower wind tells no direction, and the prior of φ is uniform, of u N(0.3, 0.3) m/s (a
  ventilated room's draught, truncated at 0). Chosen on the samples: centred on the start's wind
  whatever its speed, the first three searches in the solver-wind room ended 6.8-7.4 m off
  (every start off the doors' axis lies in the slow recirculation, 0.01-0.05 m/s, that flows
  back against the jet); uniform everywhere, the uniform-draught room's searches ended a median
  1.2 m off (1 of 10 at 7.4 m) against 0.47 m. Release rate and dispersion are unknown with
  broad priors (q as above; ζ1 N(0.05, 0.05) m²/s; ζ2 N(5, 2) s).
* **The reading model** is the fluctuation likelihood at the lab's room-scale fit
  (intermittency 0.96, log-sd 0.72, no near-source fall: fitted on the filament truth in
  lab:upwind, not on GADEN).
* **Search**: 20,000 particles, 40 hypothesised readings, 450 s (the paper's indoor
  experiment's budget, as ``lab:*``) from 60 s into the simulation (the plume has crossed the
  room by then), the files replayed from 60 s again after their end (GADEN's player loops so),
  acquired below a 1 m RMSE (the paper's 3 m in a 50 m area is 6 %; 1 m is 10 % of a 10 m
  room). Chosen on the samples: the budget, from 240 s, after one search in the uniform-wind
  room ended at 1.04 m, its spread still falling.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import read_text
from dcee.recordings.gaden import FREE, GAS_MOLAR_MASS, GadenSimulation
from dcee.recordings.gaden_files import OBSTACLE

SENSOR_HEIGHT = 0.5
"""m: the ground robot's sensor above the floor."""
CALM = 0.1
"""m/s: a wind measured at the start slower than this tells no direction (the prior of φ is then
uniform); faster, the prior of φ is centred on its direction."""


def is_gaden_folder(path: str | Path) -> bool:
    """Whether ``path`` is a folder laid out as a GADEN simulation (its occupancy grid and a
    ``result`` folder)."""
    path = Path(path)
    return path.is_dir() and (path / "OccupancyGrid3D.csv").exists() and (path / "result").is_dir()


def _direction_deg(wind: np.ndarray) -> float:
    """φ (degrees, where the wind comes from, dcee's convention) of the wind vector (u, v)."""
    return math.degrees(math.atan2(-float(wind[1]), -float(wind[0]))) % 360.0


def gaden_room_configuration(folder: str | Path) -> dict[str, Any]:
    """The scenario (a dict for :func:`dcee.scenarios.validate_scenario`) of the GADEN room in
    ``folder`` (module docstring)."""
    folder = Path(folder).expanduser().resolve()
    sim = GadenSimulation.open(folder)
    first = sim.result(int(sim.iterations[0]))
    grid = sim.grid
    free = np.argwhere(sim.occupancy == FREE)
    if len(free) == 0:
        raise DceeInputError(f"GADEN {folder}", "the occupancy grid has no free cell")
    low = grid.low + free.min(axis=0) * grid.cell
    high = grid.low + (free.max(axis=0) + 1) * grid.cell
    low, high = np.round(low, 6), np.round(high, 6)
    source = np.asarray(first.source_position, dtype=np.float64)
    wind = sim.wind(first.wind_index)

    def wind_at(p: np.ndarray) -> np.ndarray:
        idx, inside = grid.cells(p[None, :])
        i = idx[0] if inside[0] else np.clip(idx[0], 0, np.array(grid.shape) - 1)
        return wind[i[0], i[1], i[2]].astype(np.float64)

    # the start: the free cell at sensor height farthest from the release
    k = min(int((SENSOR_HEIGHT - grid.low[2]) / grid.cell), grid.shape[2] - 1)
    layer = np.argwhere(sim.occupancy[:, :, k] == FREE)
    centres = grid.low[:2] + (layer + 0.5) * grid.cell
    start_xy = centres[np.argmax(np.linalg.norm(centres - source[:2], axis=1))]
    start = np.array([*np.round(start_xy, 6), SENSOR_HEIGHT])
    at_source, at_start = wind_at(source), wind_at(start)
    speed = float(np.hypot(*at_start[:2]))
    room_map = _room_map(sim, k, free.min(axis=0), free.max(axis=0), folder.name)
    if first.gas_type not in GAS_MOLAR_MASS:
        raise DceeInputError(
            f"GADEN {folder}",
            f"gas type {first.gas_type} has no known molar mass; write a scenario file with "
            'truth.model = {kind = "gaden", folder = ..., molar_mass = ...}',
        )
    molar_mass = GAS_MOLAR_MASS[first.gas_type]
    rate = _release_rate(folder, first.moles_per_filament, molar_mass)
    extra = {"world": {"map": room_map}} if room_map is not None else {}
    return extra | {
        "name": f"gaden:{folder.name}",
        "description": (
            f"GADEN simulation {folder.name}: a room {high[0] - low[0]:g} m x "
            f"{high[1] - low[1]:g} m x {high[2] - low[2]:g} m, release at "
            f"({source[0]:g}, {source[1]:g}, {source[2]:g}) m; a ground robot with its sensor "
            f"at {SENSOR_HEIGHT:g} m."
        ),
        "dimensions": 3,
        "unknown": "source",
        "volume": {"low": low.tolist(), "high": high.tolist()},
        "truth": {
            "x": float(source[0]),
            "y": float(source[1]),
            "z": float(source[2]),
            "q": rate,
            "u": max(float(np.hypot(*at_source[:2])), 1e-3),
            "phi": _direction_deg(at_source),
            "zeta1": 0.05,
            "zeta2": 5.0,
            "model": {"kind": "gaden", "folder": str(folder)},
        },
        "prior": {
            "q": {"kind": "gamma", "shape": 1.0, "scale": 0.01},
            "u": {"kind": "normal", "mean": speed if speed >= CALM else 0.3, "sd": 0.3},
            "phi": (
                {"kind": "normal", "mean": _direction_deg(at_start), "sd": 30.0}
                if speed >= CALM
                else {"kind": "uniform", "low": 0.0, "high": 360.0}
            ),
            "zeta1": {"kind": "normal", "mean": 0.05, "sd": 0.05},
            "zeta2": {"kind": "normal", "mean": 5.0, "sd": 2.0},
        },
        "estimator": {
            "likelihood": "fluctuation",
            "intermittency": 0.96,
            "log_sd": 0.72,
            "near_source_length": 0.0,
        },
        "agent": {"start": start.tolist(), "step": 0.5, "speed": 0.5, "climb": 0.0},
        "search": {"particles": 20_000, "hypotheses": 40, "budget": 450.0, "acquired_rmse": 1.0},
    }


def _room_map(
    sim: GadenSimulation, k: int, first: np.ndarray, last: np.ndarray, name: str
) -> str | None:
    """The ROS map file of the occupancy grid's layer ``k`` (its obstacle cells blocked; an
    outlet, a door, is not), or None where no obstacle lies inside the free box ``first`` …
    ``last`` (cell indices, its outermost ring left out); written once per layer's content."""
    import hashlib
    import os
    import tempfile

    from dcee.models.ros_map import write_ros_map
    from dcee.models.site import SiteMap

    layer = sim.occupancy[:, :, k] == OBSTACLE  # (nx, ny); a door (outlet) can be driven into
    # the box's outermost cells hold the walls beside the doors: only an obstacle further in
    # calls for a map
    if not layer[first[0] + 1 : last[0], first[1] + 1 : last[1]].any():
        return None
    grid = sim.grid
    key = hashlib.sha256(
        layer.tobytes() + repr((layer.shape, grid.low.tolist(), grid.cell)).encode()
    ).hexdigest()[:16]
    root = Path(os.environ.get("DCEE_CACHE") or Path.home() / ".cache" / "dcee") / "maps"
    path = root / f"gaden-{key}.yaml"
    if not path.exists():
        root.mkdir(parents=True, exist_ok=True)
        site = SiteMap(
            layer.T.copy(),
            (float(grid.low[0]), float(grid.low[1])),
            float(grid.cell),
            name=f"GADEN {name} at {SENSOR_HEIGHT:g} m",
        )
        with tempfile.TemporaryDirectory(dir=root) as tmp:
            written = write_ros_map(site, Path(tmp) / path.name)
            os.replace(written.with_suffix(".pgm"), path.with_suffix(".pgm"))
            os.replace(written, path)
    return str(path)


def _release_rate(folder: Path, moles: float, molar_mass: float) -> float:
    """g/s: filaments per second (``sim.yaml``'s ``numFilaments_sec``) × mol per filament ×
    g/mol; 0.003 g/s (the samples') where sim.yaml does not say."""
    import yaml

    try:
        settings = yaml.safe_load(read_text(folder / "sim.yaml", "GADEN")) or {}
        per_second = float(settings["numFilaments_sec"])
    except DceeInputError:
        raise  # larger than a settings file may be
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, RecursionError):
        return 0.003
    return per_second * moles * molar_mass
