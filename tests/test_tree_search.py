"""The Monte-Carlo tree search planner (``dcee-mcts``): a hand-checked tree, the exhaustive
limit against brute force over every sequence, and its options."""

import math

import numpy as np
import pytest

from dcee import DceeInputError, GridAgent, IsotropicPlume, SearchVolume, Sensor, planners
from dcee.planning import Belief
from dcee.planning.tree_search import TreeNode, search_tree
from tests.helpers import theta_at

AGENT = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 0.0)), step=2.0)
START = np.array([10.0, 10.0, 0.0])

# Two moves per node (0 and 1), two moves deep. Rollouts repeat the last move, so a child is
# first scored by its straight continuation: (0, 0) costs 5 and (1, 1) costs 3, and the best
# first move looks like 1. The best sequence, (0, 1) at cost 1, turns after the first move.
LEAF_COST = {(0, 0): 5.0, (0, 1): 1.0, (1, 0): 3.0, (1, 1): 3.0}


def _hand_tree(simulations: int) -> tuple[TreeNode, int]:
    def children_of(node):
        return [
            TreeNode((*node.path, m), np.vstack([node.sequence, [m, 0, 0]]), np.zeros(3), m)
            for m in (0, 1)
        ]

    def complete(node):
        moves = [*node.path]
        while len(moves) < 2:
            moves.append(moves[-1])  # keep the heading
        return np.array([[m, 0.0, 0.0] for m in moves])

    def score(seqs):
        return np.array([LEAF_COST[tuple(int(m) for m in s[:, 0])] for s in seqs])

    root = TreeNode((), np.empty((0, 3)), np.zeros(3), -1)
    scored = search_tree(root, children_of, complete, score, 2, simulations, 1.0)
    return root, scored


def test_a_hand_checked_tree_finds_the_sequence_that_turns():
    root, scored = _hand_tree(2)  # the root's children only: each by its rollout
    assert scored == 2 and [c.value for c in root.children] == [5.0, 3.0]
    root, scored = _hand_tree(100)  # the budget covers the tree: exact values, then it stops
    assert scored == 6 and root.exhausted
    assert [c.value for c in root.children] == [1.0, 3.0]  # min over each first move's leaves
    assert root.value == 1.0 and root.visits == 6


def _spread_belief(n=400, seed=3):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(2.0, 38.0, size=(n, 2))
    theta = theta_at([(*p, 0.0) for p in pts], q=2.0, u=3.0, phi=math.radians(200))
    return Belief(theta, np.full(n, 1 / n), Sensor.paper_exact(), IsotropicPlume())


@pytest.mark.parametrize("cost", ["dcee-cl", "infotaxis"])
def test_exhaustive_budget_equals_brute_force_over_every_two_move_sequence(cost):
    belief = _spread_belief()
    tree = planners.get(
        "dcee-mcts", cost=cost, depth=2, simulations=10_000, subsample=1.0, n_hypotheses=6
    )
    d = tree.decide(belief, START, AGENT, np.random.default_rng(7))
    assert d.info["sequences_scored"] == 8 + 64
    # the same context (same random numbers) scoring all 64 sequences at once
    one_step = planners.get(cost, n_hypotheses=6)
    b, ctx = one_step.context(belief, np.random.default_rng(7), 2)
    seqs = np.array(
        [[p1, p2] for p1 in AGENT.candidates(START)[0] for p2 in AGENT.candidates(p1)[0]]
    )
    brute = one_step.sequence_costs(seqs, ctx, b).reshape(8, 8).min(axis=1)
    np.testing.assert_allclose(d.costs, brute, rtol=1e-12)


def test_tree_search_is_reproducible_and_within_budget():
    belief = _spread_belief()
    planner = planners.get("dcee-mcts", simulations=24, depth=3, subsample=1.0)
    a = planner.decide(belief, START, AGENT, np.random.default_rng(1))
    b = planner.decide(belief, START, AGENT, np.random.default_rng(1))
    np.testing.assert_array_equal(a.costs, b.costs)
    assert a.index == b.index and 24 <= a.info["sequences_scored"] < 24 + 8


def test_tree_search_options_are_checked():
    assert planners.get("dcee-mcts:simulations=16:cost=infotaxis").options()["cost"] == "infotaxis"
    for spec, field in (
        ("dcee-mcts:simulations=0", "simulations"),
        ("dcee-mcts:depth=40", "depth"),
        ("dcee-mcts:cost=mpc", "cost"),
        ("dcee-mcts:cost=dcee-mcts", "cost"),
        ("dcee-mcts:exploration=-1", "exploration"),
        ("dcee-mcts:reach=-2", "reach"),
    ):
        with pytest.raises(DceeInputError, match=field):
            planners.get(spec)


def test_tree_search_plans_for_each_robot_of_a_team():
    from dcee.planning import decide_team

    belief = _spread_belief()
    planner = planners.get("dcee-mcts", simulations=16, depth=2, subsample=1.0)
    positions = np.array([START, START + np.array([2.0, 0.0, 0.0])])
    out = decide_team(planner, belief, positions, AGENT, np.random.default_rng(0))
    assert len(out) == 2 and not np.allclose(out[0].position, out[1].position)


def test_a_misspelt_tree_option_names_the_tree():
    with pytest.raises(
        DceeInputError, match="dcee-mcts: no option 'simulatons'; did you mean 'simulations'"
    ):
        planners.get("dcee-mcts:simulatons=3")
    with pytest.raises(DceeInputError, match="dcee-cl:raech=6: no option 'raech'; did you mean"):
        planners.get("dcee-cl:raech=6")


def test_an_agent_keeps_each_position_s_move_set_read_only():
    """The tree search asks for the same positions' moves thousands of times per decision: the
    agent keeps them, the same arrays each time, read-only so no caller can change what the
    next one gets, and equal to the moves worked out afresh."""
    agent = GridAgent(SearchVolume((0.0, 0.0, 4.0), (10.0, 10.0, 4.0)), step=2.0)
    first = agent.candidates(np.array([1.0, 1.0, 4.0]))
    again = agent.candidates(np.array([1.0, 1.0, 4.0]))
    assert first[0] is again[0] and first[1] is again[1]
    assert not first[0].flags.writeable and not first[1].flags.writeable
    fresh = GridAgent(SearchVolume((0.0, 0.0, 4.0), (10.0, 10.0, 4.0)), step=2.0)
    np.testing.assert_array_equal(fresh.candidates(np.array([1.0, 1.0, 4.0]))[0], first[0])
    # a corner keeps only the moves into the volume
    assert set(agent.candidates(np.array([0.0, 0.0, 4.0]))[1].tolist()) == {0, 1, 2}
