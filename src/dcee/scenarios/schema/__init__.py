"""The scenario schema: pydantic models, one module per group of sections."""

from dcee.scenarios.schema.agent import (
    AUTO_CLIMB,
    AgentSpec,
    SearchSpec,
    UnicycleSpec,
    team_starts,
    unset_climb,
)
from dcee.scenarios.schema.common import FROZEN, Finite, Positive
from dcee.scenarios.schema.estimator import (
    LIKELIHOODS,
    MEANDER_DEFAULT,
    OLD_OUTLIER_DEFAULT,
    OUTLIER_DEFAULT,
    PHYSICAL_TRUNCATION,
    READING_WEIGHT_DEFAULT,
    EstimatorSpec,
    Likelihood,
    PriorSpec,
    SensorSpec,
    default_priors,
)
from dcee.scenarios.schema.scenario import FIELD_MARK, Scenario, validate_scenario
from dcee.scenarios.schema.truth import (
    TRUTH_KINDS,
    TURBULENT_HOLD,
    FilamentSpec,
    PlaybackSpec,
    PuffsSpec,
    Truth,
    TruthKind,
    Volume,
)

__all__ = [
    "AUTO_CLIMB",
    "FIELD_MARK",
    "FROZEN",
    "LIKELIHOODS",
    "MEANDER_DEFAULT",
    "OLD_OUTLIER_DEFAULT",
    "OUTLIER_DEFAULT",
    "PHYSICAL_TRUNCATION",
    "READING_WEIGHT_DEFAULT",
    "TRUTH_KINDS",
    "TURBULENT_HOLD",
    "AgentSpec",
    "EstimatorSpec",
    "FilamentSpec",
    "Finite",
    "Likelihood",
    "PlaybackSpec",
    "Positive",
    "PriorSpec",
    "PuffsSpec",
    "Scenario",
    "SearchSpec",
    "SensorSpec",
    "Truth",
    "TruthKind",
    "UnicycleSpec",
    "Volume",
    "default_priors",
    "team_starts",
    "unset_climb",
    "validate_scenario",
]
