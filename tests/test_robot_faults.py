"""What a robot's search does when its inputs misbehave for a long mission (issue 80): the
clock jumps back, messages arrive late, twice or in a burst, and the process dies and resumes
from its checkpoint. Each: what the search does, and that nothing is lost beyond the last
reading (docs/guide/robot.md, "Faults on a long mission")."""

from __future__ import annotations

import numpy as np

from dcee.planning import get as get_planner
from dcee.robot.cycle import CLOCK_JUMP, CycleSettings, Pose, SearchCycle
from dcee.robot.simulated import SimulatedRobot
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher


def _scenario():
    return load_scenario("lab:upwind").with_overrides(
        **{
            "search.particles": 800,
            "search.hypotheses": 8,
            "agent.model": "unicycle",
            "search.stop_spread": 0.0,  # fly the whole budget
            "search.budget": 200.0,
        }
    )


def _cycle(sc, searcher=None) -> SearchCycle:
    if searcher is None:
        _, filter_rng, planner_rng, _ = streams(0)
        planner = get_planner("infotaxis", **planner_defaults("infotaxis", sc, None))
        searcher = make_searcher(sc, planner, filter_rng, planner_rng)
    return SearchCycle(searcher, CycleSettings.from_scenario(sc))


def _fly(cycle, robot, until, stamp=lambda t: t, extra=None, after_reading=None) -> None:
    """Robot and cycle in lock step until robot time ``until``; ``stamp`` maps the robot's
    time to the stamps it sends, ``extra(cycle, robot)`` adds messages each step,
    ``after_reading(cycle)`` runs after each reading (as the node writes its checkpoint)."""
    while robot.time < until and cycle.state != "done":
        s = robot.odometry()
        cycle.on_reading(stamp(robot.time), robot.sample())
        if extra is not None:
            extra(cycle, robot)
        out = cycle.on_pose(Pose(stamp(robot.time), s.x, s.y, s.heading, s.v, s.omega))
        if out.goal is not None:
            robot.set_goal(out.goal)
        if out.record is not None and after_reading is not None:
            after_reading(cycle)
        robot.step()


def test_a_clock_that_jumps_back_is_carried_on_not_waited_for() -> None:
    """At 60 s the robot's clock jumps back by 500 s (a reset time source): after three poses
    behind, the search's clock carries on from the last accepted pose; the readings go on at
    the same pace and their times keep increasing (before: every pose dropped until the new
    clock caught up, 500 s of standing still)."""
    sc = _scenario()
    cycle, robot = _cycle(sc), SimulatedRobot(sc, 0)
    _fly(cycle, robot, 60.0)
    before = len(cycle.records)
    _fly(cycle, robot, 160.0, stamp=lambda t: t - 500.0)
    times = [r["time"] for r in cycle.records]
    assert cycle.clock_jumps == 1 and np.all(np.diff(times) > 0)
    assert cycle.clock_offset > 499.0
    assert cycle.rejected.get("pose stamp went backwards", 0) == 2  # the two before the third
    # readings went on at the pace before the jump (100 s more, about 25 s a reading here)
    assert len(cycle.records) - before >= 3


def test_late_and_duplicated_messages_are_not_a_clock_jump() -> None:
    """A pose delivered up to 1 s late is dropped and counted (never reaches the estimator); a
    reading that arrives twice or late during a hold is one more sample of that hold (the
    hold's mean; the estimator still gets one reading per hold)."""
    sc = _scenario()
    cycle, robot = _cycle(sc), SimulatedRobot(sc, 0)

    def late(cycle, robot):
        s = robot.odometry()
        cycle.on_pose(Pose(robot.time - 0.5 * CLOCK_JUMP, s.x, s.y, s.heading, s.v, s.omega))
        cycle.on_reading(robot.time - 3.0, robot.sample())  # a reading from 3 s ago, again

    _fly(cycle, robot, 120.0, extra=late)
    assert cycle.clock_jumps == 0
    assert cycle.rejected["pose stamp went backwards"] > 100
    times = [r["time"] for r in cycle.records]
    assert len(times) >= 4 and np.all(np.diff(times) > 0)
    assert cycle.searcher.filter.n_readings == len(cycle.records)


def test_a_burst_of_a_thousand_readings_in_a_second_is_one_reading() -> None:
    sc = _scenario()
    cycle, robot = _cycle(sc), SimulatedRobot(sc, 0)
    burst = {"done": False}

    def flood(cycle, robot):
        if cycle.state == "holding" and not burst["done"]:
            for k in range(1000):  # 1,000 readings stamped within one second
                cycle.on_reading(robot.time + k / 1000.0, robot.sample())
            burst["done"] = True

    _fly(cycle, robot, 120.0, extra=flood)
    assert burst["done"]
    # one reading per hold reached the estimator, and the hold's samples were let go after it
    assert cycle.searcher.filter.n_readings == len(cycle.records)
    assert len(cycle._samples) < 1000


def test_a_search_killed_after_any_reading_resumes_from_its_checkpoint(tmp_path) -> None:
    """The checkpoint is written after every reading (as the node does): a process killed at
    any moment resumes with every reading up to the last one written, and the resumed search
    goes on deciding exactly as the uninterrupted one (same readings, same goals)."""
    sc = _scenario()
    path = tmp_path / "search.ckpt"
    whole, robot_a = _cycle(sc), SimulatedRobot(sc, 0)
    killed, robot_b = _cycle(sc), SimulatedRobot(sc, 0)
    _fly(whole, robot_a, 80.0)
    # the killed process: its checkpoint written after every reading
    _fly(killed, robot_b, 80.0, after_reading=lambda c: c.searcher.save(path))
    resumed = Searcher.load(path)  # "kill -9": only the file survives
    assert resumed.filter.n_readings == len(killed.records) == len(whole.records)
    cont_whole = _cycle(sc, whole.searcher)
    cont_resumed = _cycle(sc, resumed)
    for c, r in ((cont_whole, robot_a), (cont_resumed, robot_b)):
        c.goal = whole.goal
        _fly(c, r, 160.0)
    a = [rec["reading"] for rec in cont_whole.records]
    b = [rec["reading"] for rec in cont_resumed.records]
    assert len(a) >= 2 and a == b
    np.testing.assert_array_equal(cont_whole.searcher.filter.weights, resumed.filter.weights)
