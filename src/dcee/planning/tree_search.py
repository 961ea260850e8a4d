"""Long-horizon planning by Monte-Carlo tree search over move sequences, with any registered cost.

One-step planners compare the next moves only; where no reading within one step can tell the
hypotheses apart (far from every plume the belief still allows) their costs tie and the choice
is arbitrary. A tree search looks ``depth`` moves ahead, so a move is worth what the best
sequence that starts with it is worth: a region where readings become informative three or four
moves away pulls the agent towards it.

The search (open-loop UCT in the sense of Silver & Veness 2010's POMCP, over move sequences
rather than action-observation histories, the form Stone Soup's ``MCTSRolloutSensorManager``
takes too):

* A node is a sequence of moves from the agent's position; its children are the agent's
  admissible moves from the sequence's last position.
* Each expansion adds every child of one node and completes each by a rollout to ``depth``
  moves that keeps the child's heading (a straight line, turning at random only at the search
  volume's edge: the rollout that reaches furthest in ``depth`` moves). All the completed
  sequences of one expansion are scored in one call of the shared predicted-posterior
  machinery (:meth:`~dcee.planning.hypothesis.HypothesisPlanner.sequence_costs`), so every
  sequence is scored on the same hypothesised sources and noise (common random numbers).
* A sequence's cost is the cost planner's expected loss after all its ``depth`` hypothesised
  readings (the reading at every position of the sequence counts: for ``infotaxis`` the
  information of the whole sequence, for ``dcee-cl`` the closed-loop cost after it). All
  scored sequences have the same length, so their costs compare.
* A node's value is the least cost of any scored sequence through it (the agent will choose
  the continuation later, so a node is as good as its best known continuation); a node is
  chosen for expansion by descending from the root to the child of least
  ``(value − min) / (max − min) − c √(ln n_parent / n_child)`` among its siblings (UCB1 on
  values normalised per sibling set, c = ``exploration``), skipping exhausted subtrees.
* ``simulations`` is the budget: the number of sequences scored per decision. The decision's
  costs are the root children's values.

The tree's sequences are scored with a systematic resample of ``subsample`` of the particles
(equally weighted; the cost planner's own option) for speed; the default budget was chosen so
that a 900 s search takes at most 3× a ``dcee-cl`` search (docs/performance.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.planning.base import (
    Belief,
    Planner,
    check_count,
    constructor_options,
    get,
    planner_class,
    register,
    unknown_option,
)
from dcee.planning.hypothesis import HypothesisPlanner

DEFAULT_SIMULATIONS = 48
"""Sequences scored per decision (docs/performance.md: the budget that keeps a 900 s search
under 3× a ``dcee-cl`` search at paper scale)."""
DEFAULT_DEPTH = 4
"""Moves per scored sequence: 8 m of look-ahead for the paper's 2 m steps."""
DEFAULT_SUBSAMPLE = 0.1
"""Share of the particles the tree scores its sequences with (systematic resample)."""
DEFAULT_TREE_HYPOTHESES = 10
"""Hypothesised readings per scored sequence (not the scenario's ``search.hypotheses``, which
sets a one-step planner's: the tree scores ``simulations`` sequences, not 8)."""


@dataclass
class TreeNode:
    """One move sequence of the tree: ``path`` (moves, each a child index at its depth),
    ``sequence`` (len(path), 3) m the positions it visits, ``position`` (3,) m where it ends,
    ``heading`` of its last move (-1 at the root)."""

    path: tuple[int, ...]
    sequence: np.ndarray
    position: np.ndarray
    heading: int
    value: float = math.inf
    rollout_value: float = math.inf
    """the cost of this node's own rollout (inf until scored)"""
    visits: int = 0
    """sequences scored at this node (its own rollout) and below it"""
    scored: bool = False
    exhausted: bool = False
    children: list[TreeNode] = field(default_factory=list)


def search_tree(
    root: TreeNode,
    children_of: Callable[[TreeNode], list[TreeNode]],
    complete: Callable[[TreeNode], np.ndarray],
    score: Callable[[np.ndarray], np.ndarray],
    depth: int,
    simulations: int,
    exploration: float,
) -> int:
    """Grow the tree below ``root`` (see the module docstring) until ``simulations`` sequences
    have been scored or every sequence of ``depth`` moves has been; returns how many were.

    children_of(node): the node's children (new nodes, not yet scored); complete(node): the
    (depth, 3) positions of the node's sequence continued by its rollout; score((S, depth, 3)):
    (S,) costs. Values and visits are written into the nodes.
    """
    scored = 0
    while scored < simulations and not root.exhausted:
        node, ancestors = root, [root]
        while node.children:  # descend to a node whose children are not yet made
            live = [c for c in node.children if not c.exhausted]
            node = _ucb_choice(live, node.visits, exploration)
            ancestors.append(node)
        kids = children_of(node) if len(node.path) < depth else []
        if not kids:  # a full-length sequence (or no admissible move): nothing more below
            node.exhausted = True
            _backup(ancestors)
            continue
        costs = score(np.stack([complete(k) for k in kids]))
        for k, c in zip(kids, costs, strict=True):
            k.value = k.rollout_value = float(c)
            k.visits, k.scored = 1, True
            k.exhausted = len(k.path) >= depth
        node.children = kids
        scored += len(kids)
        _backup(ancestors)
    return scored


def _ucb_choice(live: Sequence[TreeNode], parent_visits: int, exploration: float) -> TreeNode:
    """The sibling of least (value − min) / (max − min) − c √(ln n_parent / n_child), the
    first on ties; an infinite value is never chosen over a finite one. Plain Python: a
    handful of siblings, where NumPy's per-call cost was most of the time."""
    finite = [c.value for c in live if math.isfinite(c.value)]
    low = min(finite) if finite else 0.0
    span = max(finite) - low if finite else 0.0
    log_parent = math.log(max(parent_visits, 1))
    best, best_score = live[0], math.inf
    for c in live:
        if not math.isfinite(c.value):
            norm = math.inf
        else:
            norm = (c.value - low) / span if span > 0 else 0.0
        score = norm - exploration * math.sqrt(log_parent / c.visits)
        if score < best_score:
            best, best_score = c, score
    return best


def _backup(ancestors: list[TreeNode]) -> None:
    """Values (least cost of a scored sequence through the node: its own rollout or one
    below it) and visits (sequences scored there and below) from the leaf upwards."""
    for node in reversed(ancestors):
        if node.children:
            node.value = min(node.rollout_value, *(c.value for c in node.children))
            node.visits = int(node.scored) + sum(c.visits for c in node.children)
            node.exhausted = all(c.exhausted for c in node.children)


@register("dcee-mcts")
class TreeSearchPlanner(Planner):
    """Monte-Carlo tree search over move sequences of ``depth`` moves, scored by a registered
    hypothesis planner's cost (``cost``: dcee-cl by default, or infotaxis, entrotaxis, dcee),
    ``simulations`` sequences per decision (module docstring). Options the cost planner takes
    (``reach``, ``n_hypotheses``, ``expectation``, …) pass through to it; ``subsample`` is the
    share of particles the tree uses."""

    summary = "Monte-Carlo tree search over move sequences with any cost (long look-ahead)"

    def __init__(
        self,
        cost: str = "dcee-cl",
        simulations: int = DEFAULT_SIMULATIONS,
        depth: int = DEFAULT_DEPTH,
        exploration: float = 1.0,
        subsample: float = DEFAULT_SUBSAMPLE,
        n_hypotheses: int = DEFAULT_TREE_HYPOTHESES,
        **cost_options: Any,
    ) -> None:
        if not isinstance(cost, str) or cost == self.name or ":" in cost:
            raise DceeInputError("cost", f"must be a registered planner name, got {cost!r}")
        if not issubclass(planner_class(cost), HypothesisPlanner):
            raise DceeInputError(
                "cost", f"{cost!r} does not score sequences of hypothesised readings"
            )
        self.simulations = check_count("simulations", simulations)
        self.depth = check_count("depth", depth)
        if self.depth > 12:
            raise DceeInputError("depth", f"must be an integer in [1, 12], got {depth!r}")
        if isinstance(exploration, bool) or not (
            isinstance(exploration, int | float) and 0 <= exploration <= 100
        ):
            raise DceeInputError(
                "exploration", f"must be a number in [0, 100], got {exploration!r}"
            )
        self.exploration = float(exploration)
        self.cost_name = cost
        # the tree asks the cost planner for one context of `depth` stages; its own horizon
        # (beam search) is not used
        own = {"cost", "simulations", "depth", "exploration", "subsample", "n_hypotheses"}
        allowed = own | constructor_options(planner_class(cost))
        for key in cost_options:  # name the tree, whose spec the user wrote
            if key not in allowed:
                raise unknown_option(self.name, key, allowed)
        if cost_options.get("precision", "double") != "double" and self.depth > 1:
            raise DceeInputError(
                "precision",
                f"{cost_options['precision']!r} applies to one-reading predictions; the tree "
                f"scores sequences of depth={self.depth} readings in double precision",
            )
        # the tree's sequences are computed exactly unless a precision is asked for (depth 1)
        cost_options = {"precision": "double", **cost_options}
        self.cost: HypothesisPlanner = get(  # type: ignore[assignment]
            cost, subsample=subsample, n_hypotheses=n_hypotheses, **cost_options
        )

    def options(self) -> dict[str, Any]:
        cost_options = self.cost.options()
        cost_options.pop("horizon", None)
        cost_options.pop("beam_width", None)
        return {
            "cost": self.cost_name,
            "simulations": self.simulations,
            "depth": self.depth,
            "exploration": self.exploration,
            **cost_options,
        }

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self.cost.bind_agent(agent)
        belief, ctx = self.cost.context(belief, rng, self.depth)
        turn = np.random.default_rng(rng.integers(2**63))  # rollouts' turns at the edges
        # the heading of each candidate given (a team's robot gets a subset of its moves)
        every, every_heading = agent.candidates(position)
        match = np.all(np.abs(candidates[:, None, :] - every[None, :, :]) < 1e-9, axis=2)
        first_headings = np.where(match.any(axis=1), every_heading[match.argmax(axis=1)], -1)

        def children_of(node: TreeNode) -> list[TreeNode]:
            if node.path:
                nxt, heads = agent.candidates(node.position)
            else:  # the root's children are the candidates given
                nxt, heads = candidates, first_headings
            return [
                TreeNode((*node.path, i), np.concatenate((node.sequence, p[None])), p, int(h))
                for i, (p, h) in enumerate(zip(nxt, heads, strict=True))
            ]

        # the move that keeps a heading from a position, or None: rollouts follow the same
        # straight lines from the root again and again (a per-decision table, not a NumPy
        # search of the move set at every step: 0.4 of a 6 ms decision, lab, 2026-12-05)
        straight: dict[tuple[bytes, int], int | None] = {}

        def complete(node: TreeNode) -> np.ndarray:
            """The node's moves, then its heading kept (a random turn at an edge)."""
            out = np.empty((self.depth, 3))
            done = len(node.sequence)
            out[:done] = node.sequence
            pos, heading = node.position, node.heading
            for t in range(done, self.depth):
                nxt, heads = agent.candidates(pos)
                key = (pos.tobytes(), heading)
                if key not in straight:
                    same = np.flatnonzero(heads == heading)
                    straight[key] = int(same[0]) if len(same) else None
                k = straight[key]
                if k is None:
                    k = int(turn.integers(len(heads)))
                pos, heading = nxt[k], int(heads[k])
                out[t] = pos
            return out

        root = TreeNode((), np.empty((0, 3)), np.asarray(position, float), -1)
        scored = search_tree(
            root,
            children_of,
            complete,
            lambda seqs: self.cost.sequence_costs(seqs, ctx, belief),
            self.depth,
            self.simulations,
            self.exploration,
        )
        costs = np.array([c.value for c in root.children])
        return costs, {"sequences_scored": scored}
