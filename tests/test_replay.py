"""dcee replay without ROS: a search's messages written to a bag with rosbags and replayed
through the same cycle give the same readings and the same posterior."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rosbags")

from dcee.cli import main
from dcee.errors import DceeInputError
from dcee.planning import get as get_planner
from dcee.robot.bag import BagWriter, read_events, stamp_seconds
from dcee.robot.cycle import CycleSettings, Pose, SearchCycle
from dcee.robot.replay import replay_bag
from dcee.robot.simulated import SimulatedRobot
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import load_scenario

SCENARIO = {"search.particles": 800, "search.hypotheses": 8, "search.budget": 60.0}
SITE = {**SCENARIO, "truth.model": "isotropic", "estimator.plume": "open"}
"""At a site, the geography, not the gas: the paper's plume as the truth and the estimator's (the
site's defaults, the fluid solver's plume and the wall-aware one, cost minutes)."""


def _record_search(
    bag, scenario: str = "lab:upwind", fixes=None, overrides: dict = SCENARIO
) -> SearchCycle:
    """A live search (simulated robot + cycle) of ``scenario``, every message also written to
    ``bag``; with ``fixes`` (a second bag), the same search logged by a robot that reports
    GNSS fixes on its pose topic instead of odometry (the scenario's map frame)."""
    sc = load_scenario(scenario).with_overrides(**overrides)
    robot = SimulatedRobot(sc, 0)
    _, filter_rng, planner_rng, _ = streams(0)
    planner = get_planner("infotaxis", **planner_defaults("infotaxis", sc, None))
    cycle = SearchCycle(
        make_searcher(sc, planner, filter_rng, planner_rng),
        CycleSettings.from_scenario(sc),
        true_location=sc.truth_theta()[:3],
    )
    writers = [BagWriter(bag)] + ([BagWriter(fixes)] if fixes is not None else [])
    try:
        while True:
            s = robot.odometry()
            # what a node receives: a float32 reading, a stamp in whole nanoseconds
            value = float(np.float32(robot.sample()))
            t = stamp_seconds(round(robot.time * 1e9))
            pose = (s.x, s.y, s.heading, s.v, s.omega)
            writers[0].write_search_step(t, pose=pose, reading=value)
            if fixes is not None:
                lon, lat = sc.world.frame.local_frame().to_geo(np.array([s.x]), np.array([s.y]))
                writers[1].write_fix(t, float(lat[0]), float(lon[0]), topic="odom")
                writers[1].write_search_step(t, reading=value)
            cycle.on_reading(t, value)
            out = cycle.on_pose(Pose(t, *pose))
            if out.goal is not None:
                for writer in writers:
                    writer.write_search_step(t, goal=tuple(out.goal))
                robot.set_goal(out.goal)
            if out.finished:
                return cycle
            robot.step()
    finally:
        for writer in writers:
            writer.close()


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


def test_replay_places_gnss_fixes_on_the_sites_map(tmp_path) -> None:
    """A robot that logs latitude and longitude (sensor_msgs/NavSatFix on its pose topic) is
    replayed in the site's local frame: it reads at the odometry's positions (within 5 cm: its
    speeds come from successive fixes, so it may settle a control step apart) and ends near the
    same estimate."""
    pytest.importorskip("pyproj")
    _record_search(tmp_path / "odom", "area:example-works", tmp_path / "gnss", SITE)
    sc = load_scenario("area:example-works").with_overrides(**SITE)
    a = replay_bag(tmp_path / "odom", sc, seed=0)
    b = replay_bag(tmp_path / "gnss", sc, seed=0)
    assert {e.kind for e in read_events(tmp_path / "gnss")} == {"fix", "reading", "goal"}
    assert len(b.records) >= 5 and abs(len(a.records) - len(b.records)) <= 1
    for ra, rb in zip(a.records, b.records, strict=False):
        assert math.hypot(ra["x"] - rb["x"], ra["y"] - rb["y"]) < 0.05  # the settle may differ
    est_a = np.array(a.summary["final_mean"])
    est_b = np.array(b.summary["final_mean"])
    assert np.linalg.norm(est_a - est_b) < 0.5
    with pytest.raises(DceeInputError, match="geographic coordinates"):
        replay_bag(tmp_path / "gnss", load_scenario("lab:upwind"), seed=0)
