"""``dcee replay``: run the estimator over a recorded bag — readings, poses and goals as
recorded, no planner in the loop — and write the usual outputs of a search. It is how a user
re-analyses a field run (another particle count, another likelihood, another prior)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.provenance import code_version
from dcee.robot.bag import read_events
from dcee.robot.cycle import CycleSettings, Pose, SearchCycle
from dcee.robot.gps import map_frame, pose_from_fix
from dcee.runs import EpisodeResult, make_searcher, search_summary, streams
from dcee.scenarios import Scenario


def replay_bag(
    bag: str | Path,
    scenario: Scenario,
    seed: int = 0,
    topics: dict[str, str] | None = None,
    calibration: float = 1.0,
) -> EpisodeResult:
    """Replay ``bag`` into ``scenario``'s estimator (its filter built from ``seed``'s filter
    stream): the same search cycle as the node (settle, hold, average, tell), with the goals
    the bag recorded. The scenario's truth is the reference for the RMSE (for a field run:
    where the source really was, when known). A bag whose pose topic carries GNSS fixes
    (sensor_msgs/NavSatFix) is placed in the scenario's map frame (:mod:`dcee.robot.gps`).
    Returns the search as :func:`run_episode` does
    (strategy ``"replay"``)."""
    events = read_events(bag, topics)
    _, filter_rng, planner_rng, _ = streams(seed)
    searcher = make_searcher(scenario, None, filter_rng, planner_rng)
    settings = CycleSettings.from_scenario(scenario, calibration=calibration)
    cycle = SearchCycle(searcher, settings, plan=False, true_location=scenario.truth_theta()[:3])
    frame = map_frame(scenario, "bag") if any(e.kind == "fix" for e in events) else None
    last: Pose | None = None  # the last accepted pose: a fix's speeds start from it
    for e in events:
        if e.kind == "reading":
            cycle.on_reading(e.t, e.value)
        elif e.kind == "goal":
            cycle.on_goal(np.asarray(e.value))
        elif e.kind == "fix":
            assert frame is not None
            dropped = sum(cycle.rejected.values())
            pose = pose_from_fix(frame, e.t, *e.value, last)
            cycle.on_pose(pose)
            if sum(cycle.rejected.values()) == dropped:
                last = pose
        else:
            x, y, heading, v, omega = e.value
            cycle.on_pose(Pose(e.t, x, y, heading, v, omega))
        if cycle.state == "done":
            break
    if not cycle.records:
        raise DceeInputError("bag", f"{bag}: the robot never settled for a whole hold")
    summary = search_summary(cycle.records, scenario, "replay", seed, cycle.path_length, searcher)
    summary.update(bag=str(bag), dropped_readings=cycle.dropped_readings)
    pf = searcher.filter
    config: dict[str, Any] = {
        "scenario": scenario.model_dump(mode="json"),
        "strategy": "replay",
        "seed": seed,
        "planner_options": {},
        "bag": str(bag),
        "code": code_version(),
    }
    summary["code"] = config["code"]
    summary["version"] = config["code"]["version"]
    return EpisodeResult(cycle.records, summary, pf.theta.copy(), pf.weights.copy(), [], config)


__all__ = ["replay_bag"]
