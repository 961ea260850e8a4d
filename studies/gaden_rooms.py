"""dcee-cl and infotaxis in GADEN's rooms (issue 84): each room's scenario as ``dcee run --truth
DIR`` builds it (:mod:`dcee.scenarios.gaden_room`), from ten starts spread over the room at the
robot's sensor height (x 1, 3, 5, 7, 9 m × y 1, 5 m), seed 0. One JSON per search under
``--out`` (a rerun skips what is there: an interrupted study loses no finished search), then
``searches.json`` with every search and the code version.

    python studies/gaden_rooms.py tests/data/gaden/empty-room tests/data/gaden/empty-room-cfd \\
        --out results/gaden-rooms --table docs/results/gaden/searches.json

``--set KEY=VALUE`` (repeatable) flies a variant of the room's scenario, e.g. what a robot alone
could know, ``--set unknown=full --set estimator.plume=open``; ``--start-height H`` starts every
search H m above the floor instead of at the robot's sensor height (a UAV above the release).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

STARTS = [(x, y) for y in (1.0, 5.0) for x in (1.0, 3.0, 5.0, 7.0, 9.0)]
STRATEGIES = ("dcee-cl", "infotaxis")
KEYS = (
    "final_rmse",
    "final_mean_error",
    "final_spread",
    "source_acquired",
    "truth_in_95",
    "detections",
    "readings",
    "path_length",
    "decision_seconds_mean",
)


def one(
    room: str,
    start: tuple[float, float],
    strategy: str,
    out: str,
    overrides: dict | None = None,
    height: float | None = None,
) -> dict:
    import numba

    from dcee.runs import run_episode
    from dcee.scenarios import load_scenario
    from dcee.scenarios.gaden_room import SENSOR_HEIGHT

    numba.set_num_threads(1)
    path = Path(out) / Path(room).name / strategy / f"{start[0]:g}-{start[1]:g}.json"
    if path.exists():
        return json.loads(path.read_text())
    z = SENSOR_HEIGHT if height is None else height
    settings = {"agent.start": [*start, z], **(overrides or {})}
    scenario = load_scenario(room).with_overrides(**settings)
    result = run_episode(scenario, strategy, 0)
    row = {"room": Path(room).name, "start": list(start), "strategy": strategy}
    row |= {"settings": overrides} if overrides else {}
    row |= {"start_height": height} if height is not None else {}
    row |= {k: result.summary[k] for k in KEYS}
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(row, indent=1))
    os.replace(tmp, path)
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rooms", nargs="+")
    ap.add_argument("--out", required=True)
    ap.add_argument("--table", required=True)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--start-height", type=float, default=None, metavar="M")
    args = ap.parse_args(argv)
    from dcee.provenance import code_version
    from dcee.scenarios import parse_setting

    overrides = dict(parse_setting(s) for s in args.settings)
    jobs = [
        (r, s, st, args.out, overrides, args.start_height)
        for r in args.rooms
        for st in STRATEGIES
        for s in STARTS
    ]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, *zip(*jobs, strict=True)))
    table = Path(args.table)
    table.parent.mkdir(parents=True, exist_ok=True)
    table.write_text(json.dumps({"code_version": code_version(), "searches": rows}, indent=1))
    print(f"{len(rows)} searches -> {table}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
