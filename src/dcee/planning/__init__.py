"""Planners: one shared predicted-posterior machinery, one module per cost.

Choose by name: ``dcee.planners.get("dcee")``. Register a new one with
``@dcee.planners.register("name")`` on a :class:`Planner` subclass; nothing else changes. A
planner in another package appears everywhere through the ``dcee.planners`` entry-point group
(see :data:`dcee.planning.base.ENTRY_POINT_GROUP`).
"""

from dcee.planning import (  # noqa: F401
    dcee,
    dcee_closed_loop,
    entrotaxis,
    infotaxis,
    mpc,
    tree_search,
)
from dcee.planning.base import (
    Belief,
    Decision,
    Planner,
    get,
    names,
    planner_class,
    register,
    unregister,
)
from dcee.planning.hypothesis import HypothesisPlanner
from dcee.planning.predicted import EXPECTATIONS, PredictionContext, SequenceStats
from dcee.planning.team import check_team_planner, decide_team

__all__ = [
    "EXPECTATIONS",
    "Belief",
    "Decision",
    "HypothesisPlanner",
    "Planner",
    "PredictionContext",
    "SequenceStats",
    "check_team_planner",
    "decide_team",
    "get",
    "names",
    "planner_class",
    "register",
    "unregister",
]
