"""Several robots, one belief: the joint next moves by sequential greedy planning.

Robot 1 chooses its move as a single robot would. Robot k then chooses among its admissible
moves, with the moves of robots 1..k−1 fixed, by the planner's cost of the *joint* reading
sequence (p_1, …, p_{k−1}, candidate): the hypothesised readings of the earlier robots enter the
predicted posterior that robot k's loss is charged on (the stages of the shared
predicted-posterior machinery, :class:`~dcee.planning.predicted.PredictionContext`, here stand
for robots rather than time). So a later robot values what it would learn *beyond* what the
earlier ones will already read, and the team spreads out where spreading is informative. One
context serves every robot: the candidates of all robots are compared on common random numbers.

A move onto a position an earlier robot has just chosen is excluded (collision); a robot with
no admissible, collision-free move stays where it is. Planners without hypothesised readings
(MPC) have no joint cost: each robot then chooses by its own cost, collisions still excluded.
Multistage planners (horizon > 1) and the scenario tree plan one robot only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.planning.base import Belief, Decision, Planner, entry_decision
from dcee.planning.hypothesis import HypothesisPlanner


def check_team_planner(planner: Planner) -> None:
    """:class:`DceeInputError` (field ``agents``) unless ``planner`` can plan for a team."""
    if isinstance(planner, HypothesisPlanner):
        if planner.horizon != 1:
            raise DceeInputError(
                "agents", f"{planner.name} plans {planner.horizon} moves ahead for one robot only"
            )
        if type(planner).costs is not HypothesisPlanner.costs:
            raise DceeInputError("agents", f"{planner.name} plans for one robot only")


def decide_team(
    planner: Planner,
    belief: Belief,
    positions: np.ndarray,
    agent: GridAgent,
    rng: np.random.Generator,
) -> list[Decision | None]:
    """Next moves of K robots at ``positions`` (K, 3) m sharing ``belief``: one
    :class:`Decision` per robot, or None for a robot that has to stay where it is."""
    check_team_planner(planner)
    positions = np.asarray(positions, dtype=np.float64)
    joint = isinstance(planner, HypothesisPlanner)
    if joint:
        belief, ctx = planner.context(belief, rng, len(positions))
    chosen: list[np.ndarray] = []
    out: list[Decision | None] = []
    for position in positions:
        candidates, headings = agent.candidates(position)
        entry = entry_decision(agent, position) if len(candidates) == 0 else None
        if entry is not None:  # outside the area, beyond one move: head for it first
            out.append(entry)
            chosen.append(entry.position)
            continue
        if chosen:
            taken = np.array(chosen)
            free = ~np.any(
                np.all(np.abs(candidates[:, None, :] - taken[None, :, :]) < 1e-9, axis=2), axis=1
            )
            candidates, headings = candidates[free], headings[free]
        if len(candidates) == 0:
            out.append(None)
            chosen.append(position)
            continue
        if joint:
            prefix = np.broadcast_to(
                np.array(chosen).reshape(-1, 3), (len(candidates), len(chosen), 3)
            )
            seqs = np.concatenate([prefix, candidates[:, None, :]], axis=1)
            costs = planner.sequence_costs(seqs, ctx, belief)
            info: dict[str, Any] = {"robots_before": len(chosen)}
        else:
            costs, info = planner.costs(belief, position, candidates, agent, rng)
        decision = Decision(int(np.argmin(costs)), candidates, costs, headings, info)
        out.append(decision)
        chosen.append(decision.position)
    return out
