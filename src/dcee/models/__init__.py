"""Physical models: plume, sensor, agent."""

from dcee.models.agent import GridAgent, SearchVolume
from dcee.models.plume import (
    MIN_DISTANCE,
    PARAMETER_NAMES,
    IsotropicPlume,
    isotropic_concentration,
    isotropic_concentration_reference,
)
from dcee.models.sensor import Sensor

__all__ = [
    "MIN_DISTANCE",
    "PARAMETER_NAMES",
    "GridAgent",
    "IsotropicPlume",
    "SearchVolume",
    "Sensor",
    "isotropic_concentration",
    "isotropic_concentration_reference",
]
