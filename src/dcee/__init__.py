"""dcee: find the source of an airborne release with a mobile sensor.

Particle-filter source term estimation and Dual Control for Exploration and Exploitation (DCEE)
planning, after Chen, Rhodes & Liu, Automatica 133 (2021) 109851.
"""

from importlib.metadata import PackageNotFoundError, version

from dcee import planners
from dcee.errors import DceeInputError
from dcee.estimation import ParticleFilter, SourcePrior
from dcee.models import GridAgent, IsotropicPlume, SearchVolume, Sensor, isotropic_concentration
from dcee.searcher import Searcher, SourceEstimate

try:
    __version__ = version("dcee")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0"

__all__ = [
    "DceeInputError",
    "GridAgent",
    "IsotropicPlume",
    "ParticleFilter",
    "SearchVolume",
    "Searcher",
    "Sensor",
    "SourceEstimate",
    "SourcePrior",
    "__version__",
    "isotropic_concentration",
    "planners",
]
