"""The survey (``search.survey``): a boustrophedon over the area flown before the planner takes
over: lanes across the mean wind at the asked spacing, flown straight and in order, then the
search as before; off by default (nothing changes)."""

import math

import numpy as np
import pytest

from dcee import DceeInputError, GridAgent, ParticleFilter, Searcher, SearchVolume, Sensor
from dcee.exploration import survey_route
from dcee.models.plume import IsotropicPlume
from dcee.planning import Planner
from dcee.scenarios import load_scenario
from tests.helpers import planar_prior

AGENT = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 0.0)), step=2.0, speed=2.0)


class _Homing(Planner):
    """Goes to (10, 10): the cost is the distance to that point alone."""

    def costs(self, belief, position, candidates, agent, rng):
        return np.hypot(candidates[:, 0] - 10.0, candidates[:, 1] - 10.0), {}


def test_the_lanes_cross_the_wind_and_are_flown_in_order_from_the_robot():
    here = np.array([2.0, 2.0, 0.0])
    # wind along x (φ = 0, or blowing towards -x): lanes along y at x = 7.5, 22.5, 37.5
    for phi in (0.0, math.pi, 0.3):
        route = np.array(survey_route(AGENT, here, 15.0, phi))
        expected = [
            (7.5, 1.0),
            (7.5, 39.0),
            (22.5, 39.0),
            (22.5, 1.0),
            (37.5, 1.0),
            (37.5, 39.0),
        ]
        assert np.allclose(route[:, :2], expected) and np.all(route[:, 2] == 0.0)
    # wind along y: lanes along x; from the far corner the order reverses
    far = np.array([39.0, 39.0, 0.0])
    route = np.array(survey_route(AGENT, far, 15.0, math.pi / 2))
    assert np.allclose(
        route[:, :2],
        [(39.0, 37.5), (1.0, 37.5), (1.0, 22.5), (39.0, 22.5), (39.0, 7.5), (1.0, 7.5)],
    )
    # a spacing wider than the area: one lane through the middle
    assert np.allclose(np.array(survey_route(AGENT, here, 100.0, 0.0))[:, :2], [(20, 1), (20, 39)])


def test_a_site_survey_names_only_free_cells_the_robot_can_reach():
    agent = load_scenario("site:block").make_agent()
    here = np.array([2.0, 2.0, 4.0])
    full = survey_route(GridAgent(agent.volume, step=agent.step), here, 5.0, 0.0)
    route = np.array(survey_route(agent, here, 5.0, 0.0))
    assert 0 < len(route) < len(full)  # some lane ends fall inside buildings: left out
    assert not agent.site.is_blocked(route).any() and agent.site.reachable(here, route).all()


def _fly(survey: float, moves: int = 150) -> tuple[np.ndarray, Searcher]:
    pf = ParticleFilter(
        planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)), Sensor.paper_exact(), IsotropicPlume(), 500, 0
    )
    s = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0), stall_guard=0.0, survey=survey)
    position, path = np.array([2.0, 2.0, 0.0]), []
    for k in range(moves):
        s.tell(position, 0.0, 2.0 * k)
        path.append(position)
        position = s.ask()
    return np.array(path), s


def test_the_robot_flies_every_lane_straight_then_the_planner_takes_over():
    path, s = _fly(15.0)
    # the prior's wind direction (the paper's, from the prior): lanes across it
    phi = float(s.filter.theta[0, 5])
    route = survey_route(AGENT, np.array([2.0, 2.0, 0.0]), 15.0, phi)
    a = 0 if abs(math.cos(phi)) >= abs(math.sin(phi)) else 1
    # every waypoint is passed within a step, in order
    hits = [int(np.argmax(np.hypot(*(path[:, :2] - w[:2]).T) <= AGENT.step)) for w in route]
    assert all(
        np.hypot(*(path[h, :2] - w[:2])) <= AGENT.step for h, w in zip(hits, route, strict=True)
    )
    assert hits == sorted(hits) and s.survey_left == [] and s.survey_fired >= hits[-1] - 1
    # each lane is flown straight: between its two ends the robot keeps to the lane's line
    for k in range(0, len(route), 2):
        lane = path[hits[k] : hits[k + 1] + 1]
        assert np.all(np.abs(lane[:, a] - route[k][a]) <= AGENT.step)
        gaps = np.diff(np.sort(lane[:, 1 - a]))
        assert gaps.max() <= AGENT.step * 1.01  # no stretch of the lane skipped
    # then the planner alone: home to (10, 10) and stay there
    assert np.hypot(*(path[-1, :2] - 10.0)) <= AGENT.step


def test_no_survey_changes_nothing():
    path0, s0 = _fly(0.0, moves=40)
    pf = ParticleFilter(
        planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)), Sensor.paper_exact(), IsotropicPlume(), 500, 0
    )
    s = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0), stall_guard=0.0)
    position, path = np.array([2.0, 2.0, 0.0]), []
    for k in range(40):
        s.tell(position, 0.0, 2.0 * k)
        path.append(position)
        position = s.ask()
    assert np.array_equal(np.array(path), path0) and s0.survey_fired == 0
    assert s0.survey_left is None  # never planned


def test_a_bad_spacing_is_refused_and_old_checkpoints_have_no_survey():
    pf = ParticleFilter(
        planar_prior(x=(0.0, 40.0), y=(0.0, 40.0)), Sensor.paper_exact(), IsotropicPlume(), 100, 0
    )
    for bad in (-1.0, math.nan, True, "5"):
        with pytest.raises(DceeInputError, match="survey"):
            Searcher(pf, _Homing(), AGENT, np.random.default_rng(0), survey=bad)
    s = Searcher(pf, _Homing(), AGENT, np.random.default_rng(0))
    state = s.__dict__.copy()
    for key in ("survey", "survey_left", "survey_fired"):
        del state[key]
    old = Searcher.__new__(Searcher)
    old.__setstate__(state)
    assert old.survey == 0.0 and old.survey_left is None and old.survey_fired == 0
