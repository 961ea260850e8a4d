"""The robot's search cycle without ROS: a simulated unicycle robot in continuous time, the
cycle deciding when it has settled and which samples make a reading."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.planning import get as get_planner
from dcee.robot.cycle import REJECTION_REASONS, CycleSettings, Pose, SearchCycle
from dcee.robot.simulated import SimulatedRobot
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import load_scenario


def _lab(**changes):
    base = {"search.particles": 1500, "search.hypotheses": 10, "agent.model": "unicycle"}
    return load_scenario("lab:upwind").with_overrides(**{**base, **changes})


def _fly(scenario, strategy="infotaxis", seed=0, max_time=None):
    """Robot and cycle in lock step (what the ROS demo does over topics)."""
    robot = SimulatedRobot(scenario, seed)
    _, filter_rng, planner_rng, _ = streams(seed)
    planner = get_planner(strategy, **planner_defaults(strategy, scenario, None))
    searcher = make_searcher(scenario, planner, filter_rng, planner_rng)
    cycle = SearchCycle(
        searcher,
        CycleSettings.from_scenario(scenario),
        true_location=scenario.truth_theta()[:3],
    )
    goals = []
    limit = max_time or scenario.search.budget + 60
    while robot.time < limit:
        s = robot.odometry()
        cycle.on_reading(robot.time, robot.sample())
        out = cycle.on_pose(Pose(robot.time, s.x, s.y, s.heading, s.v, s.omega))
        if out.goal is not None:
            goals.append(out.goal)
            robot.set_goal(out.goal)
        if out.finished:
            break
        robot.step()
    return cycle, goals


def test_cycle_finds_the_source_with_a_unicycle_robot() -> None:
    sc = _lab(**{"search.stop_spread": 0.0})  # fly the whole budget
    cycle, goals = _fly(sc)
    rec = cycle.records
    assert cycle.state == "done"
    times = np.array([r["time"] for r in rec])
    assert np.all(np.diff(times) > 0) and times[-1] <= sc.search.budget
    # each reading follows a drive, a settle and the whole hold
    gaps = np.diff(times)
    assert gaps.min() >= sc.agent.step / sc.agent.speed + sc.dwell - 0.05
    assert 60 < len(rec) < 150  # fewer readings than the grid agent's 150
    # readings are taken where the robot settled, on its goal
    pos = np.array([[r["x"], r["y"]] for r in rec[1:]])
    assert np.hypot(*(pos - np.array(goals)[: len(pos), :2]).T).max() <= 0.05
    assert rec[-1]["rmse"] < sc.search.acquired_rmse


def test_a_robot_stops_once_localised_by_default() -> None:
    """On a robot the default stop rule ends the search: the spread has stayed below
    0.15 x acquired_rmse for the rule's hold, at a reading where the source is located."""
    sc = _lab()
    rule = sc.stop_rule(on_robot=True)
    assert rule is not None and rule.spread == pytest.approx(0.15 * sc.search.acquired_rmse)
    cycle, _ = _fly(sc)
    rec = cycle.records
    assert cycle.state == "done" and cycle.searcher.localised
    assert rec[-1]["time"] < sc.search.budget - 60  # well before the budget
    times = np.array([r["time"] for r in rec])
    spreads = np.array([r["spread"] for r in rec])
    # the recorded search stops at the first reading where the rule holds, no sooner or later
    assert rule.stop_index(times, spreads) == len(rec) - 1
    held = times >= times[-1] - rule.hold
    assert np.all(spreads[held] < rule.spread)
    assert rec[-1]["rmse"] < sc.search.acquired_rmse


def test_cycle_averages_over_the_hold_and_calibrates() -> None:
    sc = _lab()
    searcher = make_searcher(sc, None, *streams(0)[1:3])
    settings = CycleSettings.from_scenario(sc, average=1.0, calibration=2.0)
    cycle = SearchCycle(searcher, settings, plan=False)
    t = 0.0
    for _ in range(200):  # standing still at the start: settle 0.2 s, then hold 1.5 s
        cycle.on_reading(t, 1e-3 if t < 1.0 else 3e-3)
        out = cycle.on_pose(Pose(t, 0.3, 3.2))
        if out.record is not None:
            break
        t = round(t + 0.05, 10)
    assert out.record is not None
    # hold from 0.2 s to 1.7 s; the last 1 s (0.7-1.7 s) averages 0.3 s of 1e-3 and 0.7 s of 3e-3
    window = [1e-3 if u < 1.0 else 3e-3 for u in np.arange(0.7, 1.7 + 1e-9, 0.05).round(10)]
    assert out.record["reading"] == pytest.approx(2.0 * np.mean(window))
    assert out.record["time"] == pytest.approx(1.7)
    assert cycle.state == "waiting" and out.goal is None
    # non-finite samples are dropped, not told
    cycle.on_reading(t, float("nan"))
    cycle.on_reading(t, -1.0)
    assert cycle.dropped_readings == 2


def test_clean_airs_noise_below_zero_is_a_measurement_and_a_fault_is_not() -> None:
    """A zero-centred instrument in clean air reads a little below zero half the time: those
    samples are kept (the hold's mean is about zero, a non-detection), where dropping them
    kept only the positive half and its mean read gas (above the threshold). A sample
    further below zero than the noise floor (the sensor's threshold by default) is a fault:
    dropped and counted."""
    sc = _lab()
    threshold = sc.sensor.threshold
    rng = np.random.default_rng(3)
    noise = rng.uniform(-1.9 * threshold, 1.9 * threshold, 200)  # zero-centred, mostly small
    noise = np.clip(noise, -0.95 * threshold, None)  # within the floor below zero
    searcher = make_searcher(sc, None, *streams(0)[1:3])
    cycle = SearchCycle(searcher, CycleSettings.from_scenario(sc, average=1.0), plan=False)
    t = 0.0
    for k in range(200):
        cycle.on_reading(t, float(noise[k]))
        cycle.on_reading(t, -1.5 * threshold)  # a fault
        out = cycle.on_pose(Pose(t, 0.3, 3.2))
        if out.record is not None:
            break
        t = round(t + 0.05, 10)
    assert out.record is not None
    window = noise[14 : k + 1]  # the last 1 s of the hold, 0.7-1.7 s
    assert out.record["reading"] == pytest.approx(window.mean())
    assert out.record["reading"] < threshold < window[window >= 0].mean()
    assert cycle.rejected == {"reading below the noise floor": k + 1}
    # a floor set by hand: 0 keeps no sample below zero
    strict = CycleSettings.from_scenario(sc, noise_floor=0.0)
    cycle = SearchCycle(make_searcher(sc, None, *streams(0)[1:3]), strict, plan=False)
    cycle.on_reading(0.0, -1e-9)
    assert cycle.rejected == {"reading below the noise floor": 1}
    with pytest.raises(DceeInputError, match="noise_floor"):
        CycleSettings.from_scenario(sc, noise_floor=math.nan)


def test_cycle_waits_for_settling() -> None:
    sc = _lab()
    cycle = SearchCycle(make_searcher(sc, None, *streams(0)[1:3]), CycleSettings.from_scenario(sc))
    for k in range(100):  # still moving: never a reading
        t = 0.05 * k
        cycle.on_reading(t, 1e-3)
        assert cycle.on_pose(Pose(t, 0.3 + 0.01 * k, 3.2, 0.0, 0.2, 0.0)).record is None
    assert cycle.state == "driving"


def test_cycle_reports_a_hold_without_readings() -> None:
    sc = _lab()
    searcher = make_searcher(sc, None, *streams(0)[1:3])
    cycle = SearchCycle(searcher, CycleSettings.from_scenario(sc), plan=False)
    t = 0.0
    while t < 10.0:  # standing still, no concentration messages at all
        assert cycle.on_pose(Pose(t, 0.3, 3.2)).record is None
        t += 0.1
    assert cycle.state == "holding" and cycle.starved
    cycle.on_reading(t, 1e-3)
    assert not cycle.starved
    assert cycle.on_pose(Pose(t, 0.3, 3.2)).record is not None


def test_cycle_settings_validation() -> None:
    sc = _lab()
    with pytest.raises(DceeInputError, match="calibration"):
        CycleSettings.from_scenario(sc, calibration=math.nan)
    with pytest.raises(DceeInputError, match="average"):
        CycleSettings.from_scenario(sc, average=10.0)


def test_hostile_messages_are_dropped_counted_and_never_reach_the_estimator() -> None:
    """Readings above the maximum, inf/NaN/negative, NaN or far-away poses and stamps going
    backwards, each injected in bursts into a search with a robot at rest at every goal:
    the cycle drops and counts every one, the estimator sees only the good readings, and the
    search finishes as the clean one does (the same readings, so the same result)."""
    sc = _lab(**{"search.budget": 120.0})
    clean, _ = _fly(sc)
    robot = SimulatedRobot(sc, 0)
    _, filter_rng, planner_rng, _ = streams(0)
    planner = get_planner("infotaxis", **planner_defaults("infotaxis", sc, None))
    cycle = SearchCycle(
        make_searcher(sc, planner, filter_rng, planner_rng),
        CycleSettings.from_scenario(sc),
        true_location=sc.truth_theta()[:3],
    )
    max_reading = cycle.searcher.filter.sensor.max_reading
    bad_readings = [1e9, max_reading * 2, math.inf, -math.inf, math.nan, -1.0, True]
    k = 0
    while robot.time < sc.search.budget + 60:
        s = robot.odometry()
        good = Pose(robot.time, s.x, s.y, s.heading, s.v, s.omega)
        if k % 7 == 3:  # a burst of hostile messages between two good ones
            for value in bad_readings:
                cycle.on_reading(robot.time, value)
            for bad in (
                Pose(robot.time, math.nan, s.y),
                Pose(robot.time, s.x, s.y, math.nan),
                Pose(math.inf, s.x, s.y),
                Pose(robot.time, 1e6, -1e6),
                Pose(robot.time - 5.0, s.x, s.y),
            ):
                assert cycle.on_pose(bad).goal is None
        cycle.on_reading(robot.time, robot.sample())
        out = cycle.on_pose(good)
        if out.goal is not None:
            robot.set_goal(out.goal)
        if out.finished:
            break
        robot.step()
        k += 1
    bursts = (k + 3) // 7
    assert bursts > 5
    assert cycle.rejected["reading above max_reading"] == 2 * bursts
    assert cycle.rejected["reading not finite"] == 3 * bursts
    assert cycle.rejected["reading below the noise floor"] == bursts
    assert cycle.rejected["reading not a number"] == bursts
    assert cycle.rejected["pose not finite"] == 3 * bursts
    assert cycle.rejected["pose far outside the area"] == bursts
    assert cycle.rejected["pose stamp went backwards"] == bursts
    assert set(cycle.rejected) <= set(REJECTION_REASONS)
    # the estimator saw exactly the clean search's readings
    assert [r["reading"] for r in cycle.records] == [r["reading"] for r in clean.records]
    assert cycle.records[-1]["rmse"] == clean.records[-1]["rmse"]


def test_wind_samples_are_averaged_into_anemometer_readings() -> None:
    """20 Hz wind samples become one reading per anemometer period, their mean; impossible
    samples are dropped and counted."""
    sc = _lab(**{"anemometer.enabled": True, "anemometer.period": 1.0})
    cycle = SearchCycle(
        make_searcher(sc, None, *streams(0)[1:3]),
        CycleSettings.from_scenario(sc),
        wind_period=sc.anemometer.period,
    )
    told = []
    for k in range(41):  # 2 s at 20 Hz: air moving towards +x at 1.4-1.6 m/s
        vx = 1.5 + (0.1 if k % 2 else -0.1)
        if cycle.on_wind(0.05 * k, vx, 0.0):
            told.append(cycle.searcher.filter.wind)
    for bad in ((math.nan, 0.0), (0.0, math.inf), (150.0, 0.0)):
        assert not cycle.on_wind(2.1, *bad)
    assert cycle.wind_readings == 2 and len(told) == 2
    w = cycle.searcher.filter.wind
    assert w.n == 2
    assert w.sum_speed == pytest.approx(3.0, abs=0.02)  # two means of about 1.5 m/s
    assert w.sum_cos == pytest.approx(-2.0, abs=1e-6)  # from -x: phi = pi
    assert cycle.rejected == {"wind not finite": 2, "wind above 100 m/s": 1}
