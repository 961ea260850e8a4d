"""The Gymnasium environment: the standard API checks, determinism, and that a planner acting in
it makes exactly the search `dcee run` makes."""

import re
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import dcee.gym
from dcee import DceeInputError
from dcee.runs import run_episode
from dcee.scenarios import load_scenario

SMALL = {"scenario": "paper:1", "particles": 300, "budget": 60.0}


def test_registered_env_passes_the_gymnasium_checker():
    env = gymnasium.make(dcee.gym.ENV_ID, render_mode="rgb_array", **SMALL)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=False)
    assert not caught, [str(w.message) for w in caught]  # not even a warning
    check_env(env)  # as made (gymnasium only suggests checking the unwrapped env)
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs)
    assert info["action_mask"].dtype == np.int8 and info["action_mask"].shape == (8,)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3


def test_same_seed_same_episode_and_observation_fields():
    def roll(seed):
        env = dcee.gym.SourceSearchEnv(**SMALL)
        obs, _ = env.reset(seed=seed)
        out = [obs]
        for k in range(10):
            obs, *_ = env.step(k % 8)
            out.append(obs)
        return np.array(out)

    a, b, c = roll(3), roll(3), roll(4)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.shape == (11, len(dcee.gym.OBSERVATION_FIELDS))
    # the start of paper:1 is (2, 2, 4) m in a 50 × 50 × 5 m area
    np.testing.assert_allclose(a[0, :3], [2 / 50, 2 / 50, 4 / 5], rtol=1e-6)
    np.testing.assert_allclose(a[:, -1] * 60.0, 1.0 + 2.0 * np.arange(11), rtol=1e-6)


def test_inadmissible_moves_keep_the_robot_in_place_and_are_masked():
    env = dcee.gym.SourceSearchEnv(**SMALL)
    _, info = env.reset(seed=0)
    assert info["action_mask"].all()  # from (2, 2) every 2 m step stays in [0, 50]²
    _, _, _, _, info = env.step(4)  # −x, to (0, 2): on the edge
    # a further −x step would leave the area: masked, and the robot stays
    assert info["action_mask"][4] == 0 and info["action_mask"][0] == 1
    before = env.position
    np.testing.assert_allclose(before[:2], [0.0, 2.0])
    _, _, _, _, info = env.step(4)
    assert info["inadmissible"] and np.array_equal(env.position, before)
    _, _, _, _, info = env.step(0)
    assert not info["inadmissible"]
    np.testing.assert_allclose(env.position, before + np.array([2.0, 0.0, 0.0]))


def test_episode_ends_by_budget_or_convergence_with_documented_rewards():
    env = dcee.gym.SourceSearchEnv(**SMALL, time_penalty=0.1)
    _, info = env.reset(seed=2)
    spreads, rewards, truncated, steps = [info["spread"]], [], False, 0
    while not truncated:
        _, r, terminated, truncated, info = env.step(0 if info["action_mask"][0] else 2)
        assert not terminated  # 300 particles and 60 s do not converge to 0.5 m
        rewards.append(r)
        spreads.append(info["spread"])
        steps += 1
    # 60 s budget, first reading at 1 s, 2 s per move: 29 moves fit
    assert steps == 29
    np.testing.assert_allclose(rewards, -np.diff(spreads) - 0.1, rtol=1e-12)
    with pytest.raises(DceeInputError, match="step"):
        env.step(0)
    # a loose convergence criterion ends the episode with the bonus
    env = dcee.gym.SourceSearchEnv(**SMALL, converged_spread=1e3, success_bonus=5.0)
    env.reset(seed=2)
    _, r, terminated, truncated, _ = env.step(0)
    assert terminated and not truncated and r > 4.0


@pytest.mark.parametrize("strategy", ["infotaxis", "dcee-cl"])
def test_a_planner_policy_reproduces_dcee_run(strategy):
    scenario = load_scenario("paper:5").with_overrides(
        **{"search.particles": 400, "search.budget": 40.0}
    )
    reference = run_episode(scenario, strategy, 7)
    table = dcee.gym.evaluate(
        [dcee.gym.PlannerPolicy(strategy)], [7], scenario=scenario, particles=None
    )
    row = table.iloc[0]
    assert row["strategy"] == strategy
    for key in ("final_rmse", "final_spread", "detections", "steps", "path_length"):
        assert row[key] == reference.summary[key], key


def test_evaluate_scores_policies_on_common_seeds():
    table = dcee.gym.evaluate(
        [dcee.gym.RandomPolicy(), dcee.gym.PlannerPolicy("mpc")], [0, 1], **SMALL
    )
    assert list(table["strategy"]) == ["random", "random", "mpc", "mpc"]
    assert {"final_rmse", "source_acquired", "time_to_rmse_1m", "return"} <= set(table.columns)
    # both policies saw the same first reading (same truth noise)
    again = dcee.gym.evaluate([dcee.gym.RandomPolicy()], [0, 1], **SMALL)
    np.testing.assert_array_equal(again["final_rmse"], table["final_rmse"][:2])


def test_vectorised_envs_step_together():
    envs = gymnasium.make_vec(dcee.gym.ENV_ID, num_envs=2, vectorization_mode="sync", **SMALL)
    obs, _ = envs.reset(seed=[0, 1])
    assert obs.shape == (2, len(dcee.gym.OBSERVATION_FIELDS))
    obs, reward, terminated, truncated, _ = envs.step(np.array([0, 1]))
    assert reward.shape == terminated.shape == truncated.shape == (2,)
    assert obs.dtype == np.float32
    envs.close()


def test_bad_keywords_are_user_errors():
    for kwargs, field in [
        ({"reward": "fun"}, "reward"),
        ({"time_penalty": -1.0}, "time_penalty"),
        ({"render_mode": "human"}, "render_mode"),
        ({"particles": 0}, "particles"),
        ({"particle": 100}, "particle"),  # a misspelt keyword names itself and the allowed ones
    ]:
        with pytest.raises(DceeInputError, match=field):
            dcee.gym.SourceSearchEnv(**{**SMALL, **kwargs})
    env = dcee.gym.SourceSearchEnv(**SMALL)
    with pytest.raises(DceeInputError, match="reset"):
        env.step(0)
    env.reset(seed=0)
    with pytest.raises(DceeInputError, match="action"):
        env.step(8)


def test_multi_robot_env_passes_the_pettingzoo_tests():
    from pettingzoo.test import parallel_api_test, parallel_seed_test

    parallel_api_test(dcee.gym.multi_search_env(agents=3, **SMALL), num_cycles=40)
    parallel_seed_test(lambda: dcee.gym.multi_search_env(agents=2, **SMALL), num_cycles=40)


def test_an_environment_whose_particles_would_not_fit_is_refused(monkeypatch):
    from dcee import search_memory

    monkeypatch.setattr(search_memory, "available_bytes", lambda: 2**30)  # 1 GiB free
    with pytest.raises(DceeInputError, match="1,000,000 particles need about") as exc:
        gymnasium.make("dcee/SourceSearch-v0", scenario="paper:1", particles=10**6)
    assert exc.value.field == "particles"
    with pytest.raises(DceeInputError, match="particles need about"):
        dcee.gym.multi_search_env(agents=2, scenario="paper:1", particles=10**6)


def test_multi_robot_env_refuses_actions_it_cannot_place():
    env = dcee.gym.multi_search_env(agents=2, **SMALL)
    env.reset(seed=5)
    for actions, words in [
        ({"robot_0": 2}, "missing ['robot_1']"),
        ({"robot_0": 2, "robot_1": 2, "robot_2": 0}, "no robot named ['robot_2']"),  # was ignored
        ([2, 2], "must be a dict"),
    ]:
        with pytest.raises(DceeInputError, match=re.escape(words)):
            env.step(actions)


def test_multi_robot_env_shares_one_belief_and_blocks_collisions():
    env = dcee.gym.multi_search_env(agents=2, **SMALL)
    obs, infos = env.reset(seed=5)
    np.testing.assert_allclose(env.simulation.positions[:, :2], [[2, 2], [2, 4]])
    # both step +y: robot 0 onto (2, 4), which robot 1 leaves for (2, 6) -- allowed
    obs, rewards, _, _, infos = env.step({"robot_0": 2, "robot_1": 2})
    assert not any(i["blocked"] for i in infos.values())
    np.testing.assert_allclose(env.simulation.positions[:, :2], [[2, 4], [2, 6]])
    # the shared belief: the same belief summary in both observations, their own positions
    np.testing.assert_array_equal(obs["robot_0"][5:], obs["robot_1"][5:])
    np.testing.assert_allclose(obs["robot_1"][:2] * 50, [2, 6], rtol=1e-6)
    assert rewards["robot_0"] == rewards["robot_1"]
    # robots 4 m apart both step onto the cell between them: the later one is blocked
    env.simulation.positions = np.array([[2.0, 0.0, 4.0], [2.0, 4.0, 4.0]])
    _, _, _, _, infos = env.step({"robot_0": 2, "robot_1": 6})
    assert not infos["robot_0"]["blocked"] and infos["robot_1"]["blocked"]
    np.testing.assert_allclose(env.simulation.positions[:, :2], [[2, 2], [2, 4]])
    # one record per robot and step, every reading in the one filter
    assert len(env.simulation.records) == 2 * 3
    assert env.simulation.filter.n_readings == 6
