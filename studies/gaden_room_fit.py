"""How well the room's plume (:mod:`dcee.models.room_plume`) follows GADEN's gas, by its
diffusivity K: the time-mean concentration GADEN's player gives at the sensor's height
(0.5 m) over 60-300 s of each sample room (every 2 s), on the model's 0.2 m cubes' centres,
against the model's steady field for the true release; log-RMS of their ratio after the best
scale (its median), over the cubes where GADEN's mean exceeds 0.05 ppm. Chose
:data:`~dcee.models.room_plume.ROOM_DIFFUSIVITY` (on the two samples, the only GADEN
simulations here).

    python studies/gaden_room_fit.py tests/data/gaden/empty-room tests/data/gaden/empty-room-cfd \\
        --json docs/results/gaden/room-fit.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

DIFFUSIVITIES = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05)
HEIGHT = 0.5
TIMES = np.arange(60.0, 300.0, 2.0)
FLOOR = 0.05  # ppm


def fit(folder: str) -> dict:
    from dcee.models.room_plume import RoomPlume
    from dcee.recordings.gaden import GadenSimulation
    from dcee.scenarios.builders import gaden_room_flow

    sim = GadenSimulation.open(folder)
    first = sim.result(int(sim.iterations[0]))
    flow = gaden_room_flow(str(folder), float(TIMES[0]))  # the estimator's own cubes and wind
    nx, ny = flow.fluid.shape[:2]
    xs = flow.origin[0] + (np.arange(nx) + 0.5) * flow.h
    ys = flow.origin[1] + (np.arange(ny) + 0.5) * flow.h
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    points = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, HEIGHT)])
    mean = np.mean([sim.concentration(points, t) for t in TIMES], axis=0)
    theta = np.array([[*first.source_position, 1.0, 0.0, 0.0, 0.0, 0.0]])
    rows = []
    for k in DIFFUSIVITIES:
        model = RoomPlume(flow, k).concentration(theta, points)[0]
        use = (mean > FLOOR) & (model > 0)
        ratio = np.log(mean[use]) - np.log(model[use])
        rms = float(np.sqrt(np.mean((ratio - np.median(ratio)) ** 2)))
        rows.append({"diffusivity": k, "log_rms": round(rms, 3), "cubes": int(use.sum())})
    return {"room": Path(folder).name, "cube": flow.h, "fits": rows}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rooms", nargs="+")
    ap.add_argument("--json", required=True)
    args = ap.parse_args(argv)
    from dcee.provenance import code_version

    rooms = [fit(r) for r in args.rooms]
    for room in rooms:
        cells = ", ".join(f"{r['diffusivity']:g}: {r['log_rms']:.2f}" for r in room["fits"])
        print(f"{room['room']}: log-RMS by K (m²/s) {cells}")
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"code_version": code_version(), "rooms": rooms}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
