"""dcee-cl and infotaxis in GADEN's two sample rooms (recipe gaden, issue 84)."""

from __future__ import annotations

import json

import numpy as np

from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "gaden"
ROOMS = (("empty-room", "uniform draught"), ("empty-room-cfd", "solver wind (lbmpy D3Q27)"))


VARIANTS = (
    ("searches.json", "the room's wind field (default)"),
    ("searches-own-wind.json", "its own wind at the start (`--set unknown=full`)"),
    ("searches-uav.json", "the room's wind field, a small UAV (`--set agent.climb=0.5`)"),
    ("searches-uav-high.json", "the same UAV from 2 m, 1.5 m above the release"),
    ("searches-uav-high-own-wind.json", "the UAV from 2 m, its own wind (`--set unknown=full`)"),
)
"""Each table of searches and what its estimator knew of the air (issue 84: report both)."""


def _searches(name: str) -> list[dict]:
    path = FOLDER / name
    if not path.exists():
        return []
    return json.loads(path.read_text(encoding="utf-8"))["searches"]


def gaden_rooms_table() -> str:
    """Per room, planner and what the estimator knew of the air: acquired (final RMSE < 1 m) of
    the ten starts, the median final RMSE with its range, the median error of the posterior
    mean and the truth in the 95 % region."""
    rows = []
    tables = [(_searches(name), knows) for name, knows in VARIANTS]
    for room, wind in ROOMS:
        for strategy in ("dcee-cl", "infotaxis"):
            for searches, knows in tables:
                runs = [r for r in searches if r["room"] == room and r["strategy"] == strategy]
                if not runs:
                    continue
                rmse = np.array([r["final_rmse"] for r in runs])
                err = np.array([r["final_mean_error"] for r in runs])
                rows.append(
                    [
                        f"{room} ({wind})",
                        strategy,
                        knows,
                        f"{sum(r['source_acquired'] for r in runs)}/{len(runs)}",
                        f"{np.median(rmse):.2f} ({rmse.min():.2f}-{rmse.max():.2f})",
                        f"{np.median(err):.2f}",
                        f"{sum(r['truth_in_95'] for r in runs)}/{len(runs)}",
                    ]
                )
    header = ["room", "planner", "what the estimator knows; the robot", "acquired",
              "median final RMSE, m (range)", "mean error, m", "truth in 95 %"]  # fmt: skip
    return table(header, rows)


def gaden_starts_table() -> str:
    """Every search: the start, and each planner's final RMSE (m) and detections, with the
    room's wind field, with its own wind only, and as a small UAV (from the robot's height;
    from 2 m with the room's wind and with its own)."""
    by_key = {
        (r["room"], tuple(r["start"]), r["strategy"], k): r
        for k, (name, _) in enumerate(VARIANTS)
        for r in _searches(name)
    }
    rows = []
    for room, _ in ROOMS:
        starts = sorted({k[1] for k in by_key if k[0] == room}, key=lambda s: (s[1], s[0]))
        for start in starts:
            cells = [room, f"({start[0]:g}, {start[1]:g})"]
            for strategy in ("dcee-cl", "infotaxis"):
                for k in range(len(VARIANTS)):
                    r = by_key.get((room, start, strategy, k))
                    cells.append("—" if r is None else f"{r['final_rmse']:.2f} ({r['detections']})")
            rows.append(cells)
    header = ["room", "start (x, y) m", "dcee-cl, room's wind: RMSE (detections)",
              "dcee-cl, own wind", "dcee-cl, UAV", "dcee-cl, UAV from 2 m",
              "dcee-cl, UAV from 2 m, own wind", "infotaxis, room's wind", "infotaxis, own wind",
              "infotaxis, UAV", "infotaxis, UAV from 2 m",
              "infotaxis, UAV from 2 m, own wind"]  # fmt: skip
    return table(header, rows)


def gaden_fit_table() -> str:
    """The room's plume against GADEN's time-mean gas by K (``studies/gaden_room_fit.py``)."""
    doc = json.loads((FOLDER / "room-fit.json").read_text(encoding="utf-8"))
    ks = [f["diffusivity"] for f in doc["rooms"][0]["fits"]]
    rows = []
    for room in doc["rooms"]:
        best = min(room["fits"], key=lambda f: f["log_rms"])
        cells = [
            f"**{f['log_rms']:.2f}**" if f is best else f"{f['log_rms']:.2f}" for f in room["fits"]
        ]
        rows.append([room["room"], str(room["fits"][0]["cubes"]), *cells])
    return table(["room", "cubes compared", *(f"K = {k:g} m²/s" for k in ks)], rows)


def gaden_timing_table() -> str:
    """The GADEN playback's query against the lbm plume's, µs per reading, same run
    (``studies/gaden_timing.py``)."""
    doc = json.loads((FOLDER / "timing.json").read_text(encoding="utf-8"))
    machine = doc["machine"]
    rows = [
        [
            f"{doc['gaden_us_per_reading']:.2f}",
            f"{doc['lbm_us_per_reading']:.2f}",
            f"{doc['ratio_gaden_to_lbm']:.2f}",
            f"{doc['gaden_first_read_ms_per_file']:.2f}",
            f"{machine['processor'] or machine['machine']}, {machine['cpus']} CPUs",
        ]
    ]
    header = ["GADEN, µs per reading", "lbm plume, µs per reading", "ratio",
              "GADEN file's first read, ms", "machine"]  # fmt: skip
    return table(header, rows)
