"""Scenario files: TOML validated into immutable configuration objects."""

from dcee.scenarios.builtin import builtin_scenarios
from dcee.scenarios.config import Scenario, validate_scenario
from dcee.scenarios.loader import expand_names, load_scenario

__all__ = ["Scenario", "builtin_scenarios", "expand_names", "load_scenario", "validate_scenario"]
