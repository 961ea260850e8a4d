"""Motion below the planner: the grid agent's idealisation and the unicycle robot."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.models.motion import MOTION_MODELS, GridMotion, UnicycleMotion, make_motion, wrap_angle
from dcee.runs import run_episode
from dcee.scenarios import load_scenario


def test_registry_and_errors() -> None:
    assert {"grid", "unicycle"} <= set(MOTION_MODELS)
    with pytest.raises(DceeInputError, match=r"agent\.model"):
        make_motion("hovercraft")
    with pytest.raises(DceeInputError, match="max_speed"):
        UnicycleMotion(max_speed=0.0)


def test_grid_motion_is_the_paper_agent() -> None:
    m = GridMotion(step=2.0, speed=2.0)
    tr = m.travel((0.0, 0.0, 0.0), np.array([0.0, 2.0, 1.0]))
    assert tr.duration == 1.0 and tr.arrived
    assert tr.pose[:2] == (0.0, 2.0)
    assert tr.pose[2] == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("heading_deg", [0, 45, 90, 135, 180, 225, 270, 315])
def test_unicycle_arrives_and_respects_its_limits(heading_deg: int) -> None:
    m = UnicycleMotion()
    a = math.radians(heading_deg)
    goal = np.array([0.3 * math.cos(a), 0.3 * math.sin(a)])
    tr = m.travel((0.0, 0.0, 0.0), goal)
    assert tr.arrived
    assert math.hypot(tr.pose[0] - goal[0], tr.pose[1] - goal[1]) <= m.goal_tolerance
    t, x, y, th = tr.path.T
    assert np.all(np.diff(t) > 0)  # time ordering
    dt = np.diff(t)
    speed = np.hypot(np.diff(x), np.diff(y)) / dt
    assert speed.max() <= m.max_speed + 1e-9
    assert np.abs(np.diff(speed)).max() / dt.min() <= m.max_accel * 2 + 1e-6  # per-step ramp
    turn = np.abs([wrap_angle(d) for d in np.diff(th)]) / dt
    assert turn.max() <= m.max_turn_rate + 1e-9
    # a straight drive cannot beat max speed; a turn about costs its angle at the turn rate
    assert tr.duration >= 0.3 / m.max_speed
    if heading_deg == 180:
        assert tr.duration >= (math.pi - m.turn_in_place) / m.max_turn_rate


def test_unicycle_time_limit_stops_the_drive() -> None:
    m = UnicycleMotion(time_limit=1.0)
    tr = m.travel((0.0, 0.0, 0.0), np.array([5.0, 0.0]))
    assert not tr.arrived and tr.duration == pytest.approx(1.0)


def test_unicycle_searches_take_time_from_the_dynamics_and_are_deterministic() -> None:
    sc = load_scenario("lab:upwind").with_overrides(
        **{
            "search.particles": 500,
            "search.budget": 60.0,
            "agent.model": "unicycle",
            "agent.localisation_sd": 0.02,
        }
    )
    a = run_episode(sc, "mpc", seed=1)
    b = run_episode(sc, "mpc", seed=1)
    clocks = ("update_seconds", "decision_seconds")  # wall-clock timings differ, nothing else
    strip = [[{k: v for k, v in r.items() if k not in clocks} for r in x.records] for x in (a, b)]
    assert strip[0] == strip[1]  # determinism per seed
    times = np.array([r["time"] for r in a.records])
    travel = np.array([r["travel_time"] for r in a.records[1:]])
    assert np.all(np.diff(times) > 0) and times[-1] <= 60.0 + 1e-9
    np.testing.assert_allclose(np.diff(times), travel + sc.dwell)
    assert travel.min() >= sc.agent.step / sc.agent.speed - 1e-9
    told = np.array([[r["told_x"], r["told_y"]] for r in a.records])
    true = np.array([[r["x"], r["y"]] for r in a.records])
    err = told - true
    assert 0.005 < err.std() < 0.04  # the localisation error is there, at its scale
    # the grid agent: 1.5 s + 1.5 s hold per move, readings exactly on the waypoints
    grid = run_episode(sc.with_overrides(**{"agent.model": "grid"}), "mpc", seed=1)
    assert len(grid.records) > len(a.records)
    np.testing.assert_allclose(np.diff([r["time"] for r in grid.records]), 3.0)
