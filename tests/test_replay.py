"""dcee replay without ROS: a search's messages written to a bag with rosbags and replayed
through the same cycle give the same readings and the same posterior."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("rosbags")

from dcee.cli import main
from dcee.planning import get as get_planner
from dcee.robot.bag import BagWriter, read_events, stamp_seconds
from dcee.robot.cycle import CycleSettings, Pose, SearchCycle
from dcee.robot.replay import replay_bag
from dcee.robot.simulated import SimulatedRobot
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import load_scenario

SCENARIO = {"search.particles": 800, "search.hypotheses": 8, "search.budget": 60.0}


def _record_search(bag) -> SearchCycle:
    """A live search (simulated robot + cycle), every message also written to ``bag``."""
    sc = load_scenario("lab:upwind").with_overrides(**SCENARIO)
    robot = SimulatedRobot(sc, 0)
    _, filter_rng, planner_rng, _ = streams(0)
    planner = get_planner("infotaxis", **planner_defaults("infotaxis", sc, None))
    cycle = SearchCycle(
        make_searcher(sc, planner, filter_rng, planner_rng),
        CycleSettings.from_scenario(sc),
        true_location=sc.truth_theta()[:3],
    )
    with BagWriter(bag) as writer:
        while True:
            s = robot.odometry()
            # what a node receives: a float32 reading, a stamp in whole nanoseconds
            value = float(np.float32(robot.sample()))
            t = stamp_seconds(round(robot.time * 1e9))
            pose = (s.x, s.y, s.heading, s.v, s.omega)
            writer.write_search_step(t, pose=pose, reading=value)
            cycle.on_reading(t, value)
            out = cycle.on_pose(Pose(t, *pose))
            if out.goal is not None:
                writer.write_search_step(t, goal=tuple(out.goal))
                robot.set_goal(out.goal)
            if out.finished:
                return cycle
            robot.step()


def test_replay_reproduces_the_search_it_recorded(tmp_path) -> None:
    live = _record_search(tmp_path / "bag")
    sc = load_scenario("lab:upwind").with_overrides(**SCENARIO)
    result = replay_bag(tmp_path / "bag", sc, seed=0)
    assert len(result.records) == len(live.records) > 5
    for a, b in zip(live.records, result.records, strict=True):
        for key in ("time", "x", "y", "reading", "mean_x", "mean_y", "spread", "rmse"):
            assert a[key] == b[key], key
    np.testing.assert_array_equal(result.final_theta, live.searcher.filter.theta)
    events = read_events(tmp_path / "bag")
    assert {e.kind for e in events} == {"pose", "reading", "goal"}


def _replay(*args: str) -> int:
    """``dcee replay ARGS`` in this process; its exit code."""
    with pytest.raises(SystemExit) as exit_:
        main(["replay", *args])
    return exit_.value.code


def test_replay_cli(tmp_path, capsys) -> None:
    _record_search(tmp_path / "bag")
    bag, out = str(tmp_path / "bag"), tmp_path / "out"
    lab = ("--scenario", "lab:upwind", "--out", str(out))
    assert _replay(bag, *lab, "--particles", "800", "--set", "search.budget=60") == 0
    for name in ("steps.parquet", "summary.json", "figure.png", "posterior.npz"):
        assert (out / name).exists()
    assert _replay(str(tmp_path / "nobag"), *lab) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("dcee: error: bag: no bag at")
    assert _replay(bag, *lab, "--calibration", "-1") == 2
    assert "calibration" in capsys.readouterr().err
