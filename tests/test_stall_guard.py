"""The stall guard (Searcher, ``search.stall_guard``): a planner that would pace on one spot
for ever is made to move on, hovering at a located source is left alone, and a search that
never paces is unchanged."""

import numpy as np
import pytest

from dcee import (
    DceeInputError,
    GridAgent,
    IsotropicPlume,
    ParticleFilter,
    Searcher,
    SearchVolume,
    Sensor,
)
from dcee.planning import Planner
from dcee.runs import make_searcher, run_episode, streams
from dcee.runs.metrics import longest_stall
from dcee.scenarios import load_scenario
from tests.helpers import planar_prior

AGENT = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 0.0)), step=2.0, speed=2.0)


class _Homing(Planner):
    """Goes to (10, 10) and then paces around it: the cost is the distance to that point alone,
    so no reading ever changes its mind (the tie of a stalled planner, made exact)."""

    def costs(self, belief, position, candidates, agent, rng):
        return np.hypot(candidates[:, 0] - 10.0, candidates[:, 1] - 10.0), {}


def _fly(
    guard: float, prior_box=(0.0, 40.0), moves: int = 120, **options
) -> tuple[float, Searcher]:
    pf = ParticleFilter(
        planar_prior(x=prior_box, y=prior_box), Sensor.paper_exact(), IsotropicPlume(), 500, seed=0
    )
    rng = np.random.default_rng(0)
    searcher = Searcher(pf, _Homing(), AGENT, rng, stall_guard=guard, **options)
    position, times, path = np.array([2.0, 2.0, 0.0]), [], []
    for k in range(moves):
        searcher.tell(position, 0.0, 2.0 * k)  # nothing is ever detected
        times.append(2.0 * k)
        path.append(position)
        position = searcher.ask()
    stall = longest_stall(np.array(times), np.array(path), np.zeros(len(path), bool), 2.0)
    return stall, searcher


def test_the_guard_ends_a_stall_that_the_planner_would_never_end():
    unguarded, s0 = _fly(0.0)
    assert unguarded > 150 and s0.guard_fired == 0  # it paces around (10, 10) to the end
    guarded, s1 = _fly(30.0)
    assert guarded <= 30.0 + 2 * 2.0 and s1.guard_fired > 0  # every stall broken at 30 s


def test_the_guard_leaves_a_robot_alone_at_a_located_source():
    # a belief concentrated near (10, 10): hovering there is the point of the search
    stall, searcher = _fly(30.0, prior_box=(9.5, 10.5))
    assert searcher.guard_fired == 0 and stall > 150


def test_the_guard_acts_until_the_belief_is_as_narrow_as_the_stop_rule():
    # a belief 1-2 m wide around the wrong place: with the old threshold (3 m, the acquired
    # bar) the robot hovered there; with the default (0.45 m, guard_share 0.15) it moves on
    _, old = _fly(30.0, prior_box=(7.0, 13.0), guard_spread=3.0)
    assert old.guard_fired == 0 and 0.45 < old.estimate().spread < 3.0
    _, new = _fly(30.0, prior_box=(7.0, 13.0))
    assert new.guard_spread == pytest.approx(0.45) and new.guard_fired > 0
    # the scenario's share reaches the searcher: guard_share × acquired_rmse
    sc = load_scenario("paper:1").with_overrides(**{"search.particles": 500})
    assert make_searcher(sc, None, *streams(0)[1:3]).guard_spread == pytest.approx(0.45)
    wide = sc.with_overrides(**{"search.guard_share": 1.0})
    assert make_searcher(wide, None, *streams(0)[1:3]).guard_spread == pytest.approx(3.0)


def test_the_guard_is_off_in_old_checkpoints_and_checked():
    with pytest.raises(DceeInputError, match="stall_guard"):
        Searcher(None, None, AGENT, np.random.default_rng(0), stall_guard=-1)
    state = {"filter": None, "planner": None, "agent": AGENT}
    old = Searcher.__new__(Searcher)
    old.__setstate__(state)  # a checkpoint written before the guard existed
    assert old.stall_guard == 0.0 and old.recent == []
    # one written with the exploration guard on (several releases) before the wander guard
    # existed: it resumes with the wander guard not holding a goal
    pf = ParticleFilter(
        planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)), Sensor.paper_exact(), IsotropicPlume(), 300, 0
    )
    live = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0))
    live.explore_guard = True
    live.tell(np.array([2.0, 2.0, 0.0]), 0.0, 0.0)
    state = live.__getstate__()
    for key in ("wander_fired", "wander_target"):
        state.pop(key)
    resumed = Searcher.__new__(Searcher)
    resumed.__setstate__(state)
    assert resumed.wander_fired == 0 and resumed.wander_target is None
    assert resumed.ask().shape == (3,)


def test_a_search_that_never_paces_is_unchanged_by_the_guard():
    sc = load_scenario("paper:1").with_overrides(
        **{"search.particles": 1000, "search.hypotheses": 10, "search.budget": 120.0}
    )
    a = run_episode(sc, "infotaxis", 0)
    b = run_episode(sc.with_overrides(**{"search.stall_guard": 0.0}), "infotaxis", 0)
    assert a.summary["longest_stall"] < 30 and a.summary["stall_guard_fired"] == 0
    assert [r["x"] for r in a.records] == [r["x"] for r in b.records]
    assert a.summary["final_rmse"] == b.summary["final_rmse"]


def test_campaigns_stored_before_the_guard_resume_only_without_it():
    from dcee.runs import scenario_identity

    now = load_scenario("paper:2")
    stored = now.model_dump(mode="json")
    del stored["search"]["stall_guard"]  # a campaign stored before the guard ran without it
    off = now.with_overrides(**{"search.stall_guard": 0.0}).model_dump(mode="json")
    assert scenario_identity(stored) == scenario_identity(off)
    assert scenario_identity(stored) != scenario_identity(now.model_dump(mode="json"))


def test_a_cornered_climbing_robot_must_still_leave_its_spot():
    # Anchor (47.56, 48.38), the robot 2 m away in the corner (48.97, 49.80) of a 50 m area
    # (random:1049's stall): no move takes it further from the anchor, so before the guard
    # left every move admissible and climbing on the spot held the stall for 75 s. Now the
    # moves that leave its horizontal position are offered: west, south and south-west.
    from dcee.searcher import LeavingAgent

    agent = GridAgent(SearchVolume((0.0, 0.0, 0.0), (50.0, 50.0, 5.0)), step=2.0, climb=1.0)
    here = np.array([48.970563, 49.798990, 2.0])
    leaving = LeavingAgent(agent, np.array([47.556349, 48.384776, 1.0]), here)
    cands, heads = leaving.candidates(here)
    assert set(heads.tolist()) == {4, 5, 6}  # 180°, 225°, 270°: no climb (8), no descent (9)
    assert np.all(np.hypot(*(cands[:, :2] - here[:2]).T) > 1.0)
    # where some move does leave the anchor, only those are offered, as before
    away, _ = LeavingAgent(agent, here, here).candidates(here)
    assert np.all(np.hypot(*(away[:, :2] - here[:2]).T) > 1.0)


def test_the_wander_guard_sends_a_robot_out_of_a_region_it_keeps_to():
    """Positions round a 3 m circle for 70 s with nothing detected and a belief 16 m wide: the
    guard names a goal outside the 7.5 m region, holds it until the robot is a step from it,
    and the search that kept to one region no longer does."""
    from dcee.searcher import WANDER_GUARD, WANDER_RADIUS

    pf = ParticleFilter(
        planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)), Sensor.paper_exact(), IsotropicPlume(), 800, 0
    )
    s = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0), stall_guard=0.0)
    s.explore_guard = True
    centre = np.array([20.0, 20.0, 0.0])
    for k in range(15):
        a = 2 * np.pi * k / 6
        s.tell(centre + 3.0 * np.array([np.cos(a), np.sin(a), 0.0]), 0.0, 5.0 * k)
    assert s.estimate().spread > WANDER_RADIUS and 5.0 * 14 >= WANDER_GUARD
    goal = s.wander_goal()
    assert goal is not None and s.wander_fired == 1
    assert np.hypot(*(goal[:2] - s.recent[0][1][:2])) > WANDER_RADIUS
    assert np.array_equal(s.wander_goal(), goal)  # held
    s.tell(goal + np.array([1.0, 0.0, 0.0]), 0.0, 200.0)
    assert s.wander_goal() is None or not np.array_equal(s.wander_goal(), goal)
    # held only while the belief is wider than the region: once readings on the way narrow it
    # to the region's radius, the reason to leave is gone and the goal is dropped (before, it
    # was held until the stop rule's spread: area:fontvieille seed 1 went on 80 m out)
    s.tell(centre, 0.0, 205.0)  # on the way back, far from the goal
    s.wander_target = goal.copy()
    assert s.estimate().spread > WANDER_RADIUS and np.array_equal(s.wander_goal(), goal)
    theta = pf.theta.copy()
    theta[:, :2] = np.array([30.0, 30.0]) + np.random.default_rng(1).normal(0, 1.0, (len(theta), 2))
    pf.theta[:] = theta
    assert 0.45 < s.estimate().spread <= WANDER_RADIUS  # narrower than the region, not located
    assert s.wander_goal() is None and s.wander_target is None
    # a whole search: the homing planner paces round (10, 10) to the end without the guard
    # (the stall guard off), and leaves that region within the guard's time with it
    for guarded in (False, True):
        pf = ParticleFilter(
            planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)),
            Sensor.paper_exact(),
            IsotropicPlume(),
            500,
            seed=0,
        )
        s = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0), stall_guard=0.0)
        s.explore_guard = guarded
        position, times, path = np.array([2.0, 2.0, 0.0]), [], []
        for k in range(120):
            s.tell(position, 0.0, 2.0 * k)
            times.append(2.0 * k)
            path.append(position)
            position = s.ask()
        wander = longest_stall(
            np.array(times), np.array(path), np.zeros(len(path), bool), WANDER_RADIUS
        )
        if guarded:
            assert wander <= WANDER_GUARD + 10.0 and s.explore_fired > 0, wander
        else:
            assert wander > 150.0 and s.explore_fired == 0


def test_a_goal_round_a_corner_no_whole_step_follows_is_still_approached():
    """``site:block``, where entrotaxis stepped back and forth for 150 s: from (43.6, 44) the
    travel distance to a goal round the courtyard building falls by less than half a step
    for every move (0.93 m at most), so the guard offered every move. It now offers the moves
    that bring the robot closer at all, and the robot walked along them reaches the goal."""
    from dcee.exploration import ApproachingAgent, travel_xy

    agent = load_scenario("site:block").make_agent()
    goal = np.array([43.8, 10.4, 4.0])
    here = np.array([43.556349, 44.041631, 4.0])
    cands, _ = ApproachingAgent(agent, goal, here).candidates(here)
    now = travel_xy(agent.site, goal, here[None])[0]
    after = travel_xy(agent.site, goal, cands)
    assert 0 < len(cands) < len(agent.candidates(here)[0]) and np.all(after < now)
    for _ in range(40):  # greedy along the offered moves: never back, and there in the end
        cands, _ = ApproachingAgent(agent, goal, here).candidates(here)
        after = travel_xy(agent.site, goal, cands)
        assert after.min() < travel_xy(agent.site, goal, here[None])[0]
        here = cands[int(np.argmin(after))]
        if np.hypot(*(here[:2] - goal[:2])) <= agent.step:
            break
    assert np.hypot(*(here[:2] - goal[:2])) <= agent.step


def test_a_guard_never_names_a_goal_it_cannot_steer_to():
    """``site:block``, mpc, seed 0: the exploration guard named (31.25, 39.58), a point inside a
    building. The robot reaches it at the building's face, but the travel distance back from
    it is infinite (a blocked cell is left only to another blocked one), so every move
    measured infinitely far and the guard steered nowhere for 155 s. Goals are now free cells
    reachable from the robot, and from every one of them the way back is finite."""
    from dcee.exploration import ApproachingAgent, area_grid, reachable_points, travel_xy

    agent = load_scenario("site:block").make_agent()
    here = np.array([27.556349, 38.727922, 4.0])
    inside = np.array([[31.25, 39.58333333, 4.0]])
    assert agent.site.is_blocked(inside)[0] and agent.site.reachable(here, inside)[0]
    assert not np.isfinite(travel_xy(agent.site, inside[0], here[None])[0])
    assert len(reachable_points(agent, here, inside)) == 0
    grid = area_grid(agent, 4.0)
    goals = reachable_points(agent, here, grid)
    assert 0 < len(goals) < len(grid) and not agent.site.is_blocked(goals).any()
    for goal in goals[:: max(1, len(goals) // 40)]:  # about 40, a Dijkstra each
        assert np.isfinite(travel_xy(agent.site, goal, here[None])[0])
        cands, _ = ApproachingAgent(agent, goal, here).candidates(here)
        assert np.all(travel_xy(agent.site, goal, cands) < travel_xy(agent.site, goal, here[None]))
