"""The climbing agent (``agent.climb``): two more moves change the altitude, inside the area's
altitude range, for every consumer of the move set (planners, the simulation, the gym env)."""

import numpy as np
import pytest

import dcee.gym
from dcee import GridAgent, SearchVolume
from dcee.errors import DceeInputError
from dcee.runs import run_episode
from dcee.scenarios import load_scenario


def test_moves_by_hand():
    agent = GridAgent(SearchVolume((0, 0, 0), (50, 50, 5)), step=2.0, climb=1.0)
    assert agent.n_moves == 10
    np.testing.assert_allclose(agent.moves[8:], [[0, 0, 1.0], [0, 0, -1.0]])
    np.testing.assert_allclose(agent.moves[0], [2.0, 0, 0])
    # at the ceiling only the descent is left of the two; on the floor only the climb
    top, heads = agent.candidates(np.array([10.0, 10.0, 5.0]))
    assert 8 not in heads and 9 in heads
    np.testing.assert_allclose(top[heads == 9][0], [10.0, 10.0, 4.0])
    _, heads = agent.candidates(np.array([10.0, 10.0, 0.0]))
    assert 8 in heads and 9 not in heads
    # climb 0 is the paper's agent: eight headings at one altitude
    flat = GridAgent(SearchVolume((0, 0, 0), (50, 50, 5)), step=2.0)
    assert flat.n_moves == 8 and not flat.moves[:, 2].any()
    with pytest.raises(DceeInputError, match=r"agent\.climb"):
        GridAgent(SearchVolume((0, 0, 0), (50, 50, 5)), climb=-1.0)


def test_a_ground_robot_cannot_climb():
    with pytest.raises(DceeInputError, match=r"agent\.climb"):
        load_scenario("paper:1").with_overrides(**{"agent.climb": 1.0, "agent.model": "unicycle"})


def test_a_climbing_search_flies_other_altitudes_and_counts_them():
    sc = load_scenario("random:16").with_overrides(
        **{"search.particles": 1000, "search.hypotheses": 10, "search.budget": 200.0}
    )
    flat = run_episode(sc, "infotaxis", 0)
    assert {r["z"] for r in flat.records} == {4.0}
    climbing = sc.with_overrides(**{"agent.climb": 1.0})
    a, b = run_episode(climbing, "infotaxis", 0), run_episode(climbing, "infotaxis", 0)
    z = np.array([r["z"] for r in a.records])
    assert np.array_equal(z, [r["z"] for r in b.records])  # reproducible
    assert len(set(z)) > 1 and z.min() >= 0.0 and z.max() <= 5.0
    xyz = np.array([[r["x"], r["y"], r["z"]] for r in a.records])
    steps = np.diff(np.vstack([np.array(sc.agent.start)[None], xyz]), axis=0)
    by_hand = np.hypot(steps[:, 0], steps[:, 1]).sum() + np.abs(steps[:, 2]).sum()
    assert a.summary["path_length"] == pytest.approx(by_hand)


def test_the_gym_env_offers_the_climb():
    sc = load_scenario("paper:1").with_overrides(**{"agent.climb": 1.0})
    env = dcee.gym.SourceSearchEnv(scenario=sc, particles=300, budget=60.0)
    assert env.action_space.n == 10
    _, info = env.reset(seed=0)
    assert info["action_mask"].shape == (10,) and info["action_mask"][8] == 1
    env.step(8)  # up, from 4 m to the 5 m ceiling
    np.testing.assert_allclose(env.position, [2.0, 2.0, 5.0])
    _, _, _, _, info = env.step(9)
    np.testing.assert_allclose(env.position, [2.0, 2.0, 4.0])
    env.step(8)
    _, _, _, _, info = env.step(0)
    assert info["action_mask"][8] == 0  # no higher than the area


def test_the_robot_cycle_refuses_a_climb_it_cannot_see():
    from dcee.robot.cycle import CycleSettings

    sc = load_scenario("paper:1").with_overrides(**{"agent.climb": 1.0})
    with pytest.raises(DceeInputError, match=r"agent\.climb"):
        CycleSettings.from_scenario(sc)


def test_an_unset_climb_follows_the_expected_plume_and_the_platform():
    """agent.climb unset: 1 m (AUTO_CLIMB) for the grid UAV with the fluctuation likelihood,
    0 with the paper's likelihood (the paper's agent), on the ground robot and on a robot's
    cycle; a value set is kept everywhere."""
    from dcee.robot.cycle import CycleSettings
    from dcee.runs import make_searcher, scenario_identity
    from dcee.scenarios import AUTO_CLIMB, to_toml

    paper = load_scenario("random:16")
    turbulent = paper.with_overrides(**{"estimator.likelihood": "fluctuation"})
    assert paper.agent.climb is None and paper.climb == 0.0
    assert AUTO_CLIMB == 1.0 and turbulent.climb == 1.0
    assert turbulent.make_agent().n_moves == 10
    assert turbulent.make_agent(on_robot=True).n_moves == 8
    rng = np.random.default_rng(0)
    assert make_searcher(turbulent, None, rng, rng).agent.climb == 0.0  # a robot: planar poses
    CycleSettings.from_scenario(turbulent)  # unset is not refused on a robot
    fixed = turbulent.with_overrides(**{"agent.climb": 0.0})
    assert fixed.climb == 0.0 and fixed.make_agent().n_moves == 8
    ground = turbulent.with_overrides(**{"agent.model": "unicycle"})
    assert ground.climb == 0.0
    # dcee show: the resolved value as a comment, and the file reads back unset
    assert "# climb = 1.0  (unset: the default for this scenario)" in to_toml(turbulent)
    # a stored campaign compares its unset climb as the number it resolved to
    stored = turbulent.model_dump(mode="json")
    explicit = turbulent.with_overrides(**{"agent.climb": 1.0}).model_dump(mode="json")
    assert scenario_identity(stored) == scenario_identity(explicit)
    assert scenario_identity(stored) != scenario_identity(fixed.model_dump(mode="json"))
    before = paper.model_dump(mode="json")
    del before["agent"]["climb"]  # a paper campaign stored before the setting existed
    assert scenario_identity(before) == scenario_identity(paper.model_dump(mode="json"))
    # the count of releases unknown: 1 m with the paper's likelihood too (issue 45), not on a
    # robot or the ground robot; one release known keeps the paper's fixed altitude
    several = paper.with_overrides(**{"estimator.max_sources": 3})
    assert several.agent.climb is None and several.climb == AUTO_CLIMB
    assert several.make_agent().n_moves == 10 and several.make_agent(on_robot=True).n_moves == 8
    assert several.with_overrides(**{"agent.model": "unicycle"}).climb == 0.0
    assert paper.with_overrides(**{"estimator.max_sources": 1}).climb == 0.0
    # not measured at a site: the paper's fixed altitude there
    assert load_scenario("site:nogo").with_overrides(**{"estimator.max_sources": 2}).climb == 0.0
    stored = several.model_dump(mode="json")
    assert scenario_identity(stored) == scenario_identity(
        several.with_overrides(**{"agent.climb": 1.0}).model_dump(mode="json")
    )
    assert scenario_identity(stored) != scenario_identity(
        several.with_overrides(**{"agent.climb": 0.0}).model_dump(mode="json")
    )


def test_the_command_line_says_when_an_unset_climb_resolves_to_a_climbing_uav(capsys):
    from dcee.console import climb_notice

    paper = load_scenario("random:16")
    turbulent = paper.with_overrides(**{"estimator.likelihood": "fluctuation"})
    climb_notice([paper, turbulent.with_overrides(**{"agent.climb": 1.0})])
    assert capsys.readouterr().err == ""  # the paper's agent, or a climb the user set
    climb_notice(turbulent, quiet=True)
    assert capsys.readouterr().err == ""
    climb_notice(turbulent)
    err = capsys.readouterr().err
    assert "agent.climb unset" in err and "1 m" in err and err.count("\n") == 1
    climb_notice(paper.with_overrides(**{"estimator.max_sources": 2}))
    err = capsys.readouterr().err
    assert "count of releases is unknown" in err and err.count("\n") == 1


def test_a_least_altitude_keeps_the_climbing_uav_above_it_and_the_prior_whole(capsys, tmp_path):
    """agent.min_altitude: the agent's moves stay at or above it (the descent from it is
    inadmissible), the releases' prior keeps the area's whole altitude range, a stored campaign
    without the setting keeps its identity, and a value outside the area or above the start is
    refused in one line with exit 2 before anything is written."""
    from dcee.runs import scenario_identity
    from tests.helpers import run_cli

    sc = load_scenario("random:16").with_overrides(
        **{"search.particles": 1000, "search.hypotheses": 10, "search.budget": 200.0}
    )
    high = sc.with_overrides(**{"agent.climb": 1.0, "agent.min_altitude": 3.0})
    agent = high.make_agent()
    assert agent.volume.low[2] == 3.0 and high.volume.low[2] == 0.0
    _, heads = agent.candidates(np.array([10.0, 10.0, 3.0]))
    assert 8 in heads and 9 not in heads  # up, not down
    _, heads = agent.candidates(np.array([10.0, 10.0, 4.0]))
    assert 9 in heads
    result = run_episode(high, "infotaxis", 0)
    z = np.array([r["z"] for r in result.records])
    assert z.min() >= 3.0 and len(set(z)) > 1
    # the filter's prior over the release's height is the area's (0-5 m), not the agent's
    z_prior = high.make_prior().sample(np.random.default_rng(0), 1000)[:, 2]
    assert z_prior.min() < 1.0 and z_prior.max() > 4.0
    # the gym environment's action mask offers no descent from the least altitude
    env = dcee.gym.SourceSearchEnv(
        scenario=high.with_overrides(**{"agent.min_altitude": 4.0}), particles=300, budget=60.0
    )
    _, info = env.reset(seed=0)
    assert info["action_mask"][8] == 1 and info["action_mask"][9] == 0
    # unset: the area's floor, as before the setting existed
    assert sc.make_agent().volume.low[2] == 0.0
    stored = sc.model_dump(mode="json")
    del stored["agent"]["min_altitude"]
    assert scenario_identity(stored) == scenario_identity(sc.model_dump(mode="json"))
    assert scenario_identity(stored) != scenario_identity(high.model_dump(mode="json"))
    for value, why in (("4.5", "above agent.start's altitude 4 m"), ("-1", "altitude range")):
        out = tmp_path / f"run{value}"
        argv = ["run", "--scenario", "paper:1", "--set", f"agent.min_altitude={value}"]
        code, _, err = run_cli([*argv, "--out", str(out)], capsys)
        assert code == 2 and "agent.min_altitude" in err and why in err, err
        assert err.strip().count("\n") == 0 and not out.exists()
