"""``dcee.planners``: the planner registry (an alias of :mod:`dcee.planning`)."""

from dcee.planning import *  # noqa: F403
from dcee.planning import __all__  # noqa: F401
