"""``dcee.planners``: the planner registry (alias of :mod:`dcee.planning`)."""

from dcee.planning import (
    Belief,
    Decision,
    OneStepPlanner,
    Planner,
    PredictionContext,
    SequenceStats,
    get,
    names,
    register,
)

__all__ = [
    "Belief",
    "Decision",
    "OneStepPlanner",
    "Planner",
    "PredictionContext",
    "SequenceStats",
    "get",
    "names",
    "register",
]
