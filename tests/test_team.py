"""Several robots, one belief: sequential greedy joint planning and the team search loop."""

import json

import numpy as np
import pandas as pd
import pytest

from dcee import DceeInputError, GridAgent, SearchVolume, planners
from dcee.planning import decide_team
from dcee.runs import run_episode
from dcee.scenarios import load_scenario
from tests.helpers import run_cli
from tests.test_planners import AGENT, START, _spread_belief, _two_point_belief


def test_one_robot_team_is_the_single_robot_decision():
    belief = _spread_belief()
    for name in ("dcee-cl", "infotaxis", "mpc"):
        planner = planners.get(name)
        (team,) = decide_team(planner, belief, START[None, :], AGENT, np.random.default_rng(4))
        alone = planner.decide(belief, START, AGENT, np.random.default_rng(4))
        np.testing.assert_array_equal(team.costs, alone.costs)
        assert team.heading == alone.heading


def test_a_later_robot_values_only_what_it_adds():
    # Hypothesis A 3 m east of both robots, B 20 m north; a weak release only a sensor near A
    # detects. Robot 0 takes the most informative move (east, 1 m from A). Robot 1 may not take
    # the same cell; its joint information gain is then robot 0's alone wherever its own
    # reading is uninformative (far from A), and more only next to A (NE, SE) -- but less
    # than the same move would be worth alone (diminishing returns).
    belief = _two_point_belief(200)
    planner = planners.get("infotaxis:expectation=stratified:hypotheses=400")
    rng = np.random.default_rng
    first, second = decide_team(planner, belief, np.array([START, START]), AGENT, rng(0))
    alone = planner.decide(belief, START, AGENT, rng(0))
    assert first.heading == 0 and 0 not in second.headings
    joint = dict(zip(second.headings.tolist(), second.costs, strict=True))
    for far in (3, 4, 5):
        assert joint[far] == pytest.approx(alone.costs[0], abs=1e-3)
    assert second.heading in (1, 7)
    for near in (1, 7):
        gain_joint = alone.costs[0] - joint[near]
        gain_alone = -alone.costs[near]
        assert 0.03 < gain_joint < gain_alone


def test_a_boxed_in_robot_stays_and_unsupported_planners_are_refused():
    one_way = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 0.0)), step=2.0, n_headings=1)
    belief = _spread_belief()
    moves = decide_team(
        planners.get("mpc"), belief, np.array([START, START]), one_way, np.random.default_rng(0)
    )
    assert moves[0] is not None and moves[1] is None
    for spec in ("dcee-ms", "dcee-cl-tree", "infotaxis:horizon=2"):
        with pytest.raises(DceeInputError, match="agents"):
            decide_team(planners.get(spec), belief, np.array([START, START]), AGENT, None)


def test_a_robot_outside_the_area_heads_into_it():
    """A robot further than one move outside the area (launched from beyond its edge) gets
    the nearest point of the area as its goal; before, it had no move and stayed out."""
    belief = _spread_belief()
    outside = np.array([START[0], -5.0, START[2]])
    inside, entering = decide_team(
        planners.get("dcee-cl"), belief, np.array([START, outside]), AGENT,
        np.random.default_rng(0),
    )  # fmt: skip
    assert inside is not None and inside.info != {"entry": True}
    assert entering is not None and entering.info == {"entry": True}
    np.testing.assert_allclose(entering.position, [START[0], 0.0, START[2]], atol=1e-5)
    assert AGENT.volume.contains(entering.position[None])[0]


def test_team_search_shares_one_filter_and_is_deterministic():
    scenario = load_scenario("paper:1").with_overrides(
        **{"search.particles": 500, "search.budget": 30.0, "agent.count": 3}
    )
    a = run_episode(scenario, "infotaxis", 2)
    b = run_episode(scenario, "infotaxis", 2)
    steps = pd.DataFrame(a.records)
    pd.testing.assert_frame_equal(steps, pd.DataFrame(b.records).assign(
        update_seconds=steps.update_seconds, decision_seconds=steps.decision_seconds
    ))  # fmt: skip
    s = a.summary
    assert s["agents"] == 3 and s["readings"] == 3 * (s["steps"] + 1)
    assert steps[steps.step == 0].robot.tolist() == [0, 1, 2]
    np.testing.assert_allclose(steps[steps.step == 0][["x", "y"]], [[2, 2], [2, 4], [2, 6]])
    # never two robots in one place after the start
    for _, group in steps.groupby("time"):
        assert len({(x, y) for x, y in zip(group.x, group.y, strict=True)}) == 3
    # path: three robots, 2 m per move each
    assert s["path_length"] == pytest.approx(3 * 2.0 * s["steps"])


def test_cli_run_and_bench_take_agents(tmp_path, capsys):
    out = tmp_path / "team"
    argv = "run --scenario paper:1 --strategy infotaxis --agents 3 --particles 400 --budget 20 -q"
    code, stdout, _ = run_cli([*argv.split(), "--out", str(out)], capsys)
    assert code == 0, stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["agents"] == 3
    assert set(pd.read_parquet(out / "steps.parquet").robot) == {0, 1, 2}
    assert (out / "figure.png").stat().st_size > 10_000
    argv = "run --scenario paper:1 --strategy dcee-ms --agents 2"
    code, _, err = run_cli(argv.split(), capsys)
    assert code == 2 and "agents" in err and len(err.strip().splitlines()) == 1
    code, _, err = run_cli("run --scenario paper:1 --agents 0".split(), capsys)
    assert code == 2 and "agent.count" in err
    bench = tmp_path / "bench"
    code, stdout, _ = run_cli(
        [*"bench --suite smoke --strategies mpc --repeats 1 --agents 2 --workers 1 --out".split(),
         str(bench)],
        capsys,
    )  # fmt: skip
    assert code == 0, stdout
    assert json.loads((bench / "campaign.json").read_text())["settings"]["overrides"] == {
        "agent.count": 2
    }


def test_searcher_asks_for_a_team_and_rejects_bad_positions():
    from dcee import ParticleFilter, Searcher

    sc = load_scenario("lab:downwind")
    pf = ParticleFilter(sc.make_prior(), sc.make_sensor(), n_particles=500, seed=0)
    s = Searcher(pf, planners.get("infotaxis"), sc.make_agent(), np.random.default_rng(0))
    starts = np.array(sc.agent.start) + np.array([[0.0, 0.0, 0.0], [0.0, 0.3, 0.0]])
    with pytest.raises(DceeInputError, match="ask"):
        s.ask_team(starts)
    for p in starts:
        s.tell(p, 0.0, time=3.0)
    nxt = s.ask_team(starts)
    assert nxt.shape == (2, 3) and len(s.last_team_decisions) == 2
    np.testing.assert_allclose(np.linalg.norm(nxt - starts, axis=1), 0.3)
    assert not np.allclose(nxt[0], nxt[1])
    for bad in (starts[0], [[1.0, 2.0]], [[np.nan, 0.0, 0.0]], "here"):
        with pytest.raises(DceeInputError, match="positions"):
            s.ask_team(bad)
    bare = Searcher(pf, None, sc.make_agent(), np.random.default_rng(0))
    bare.tell(starts[0], 0.0, time=4.0)
    with pytest.raises(DceeInputError, match="planner"):
        bare.ask_team(starts)


def test_team_figure_draws_each_robots_altitude():
    """The altitude panel of a team's figure has one trace a robot (the records interleave
    the robots at each time: one trace through them all zigzagged between robots)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from dcee.analysis.figures import draw_search_figure
    from dcee.simulation import make_truth

    scenario = load_scenario("paper:1").with_overrides(
        **{"search.particles": 400, "search.budget": 12.0, "agent.count": 2, "agent.climb": 1.0}
    )
    result = run_episode(scenario, "infotaxis", 0)
    fig = draw_search_figure(result, scenario, make_truth(scenario, 0))
    try:
        ax_z = next(ax for ax in fig.axes if ax.get_ylabel() == "height (m)")
        lines = {ln.get_label(): ln for ln in ax_z.get_lines()}
        steps = pd.DataFrame(result.records)
        for k in (0, 1):
            z = lines[f"robot {k} sensor"].get_ydata()
            np.testing.assert_allclose(z, steps[steps.robot == k].z)
        estimate = lines["source height, estimate ± sd"].get_xdata()
        assert len(estimate) == len(steps[steps.robot == 0])
    finally:
        plt.close(fig)
