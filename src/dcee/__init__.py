"""dcee: find the source of an airborne release with a mobile sensor.

Particle-filter source term estimation and Dual Control for Exploration and Exploitation (DCEE)
planning, after Chen, Rhodes & Liu, Automatica 133 (2021) 109851.

The public names below are imported on first use (PEP 562), so that ``import dcee.errors`` or
``dcee --help`` does not pay for NumPy, SciPy and the compiled kernels.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from dcee.kernel_cache import key_numba_cache
from dcee.kernel_target import widen_vectors_when_numba_loads
from dcee.provenance import package_version

key_numba_cache()  # before numba is imported: compiled kernels keyed by the source (why: there)
widen_vectors_when_numba_loads()  # 512-bit vectors where the CPU has AVX-512 (why: there)

__version__ = package_version()

_LAZY = {
    "DceeInputError": "dcee.errors",
    "GridAgent": "dcee.models",
    "IsotropicPlume": "dcee.models",
    "SearchVolume": "dcee.models",
    "Sensor": "dcee.models",
    "isotropic_concentration": "dcee.models",
    "ParticleFilter": "dcee.estimation",
    "SourcePrior": "dcee.estimation",
    "Searcher": "dcee.searcher",
    "SourceEstimate": "dcee.searcher",
}

if TYPE_CHECKING:  # pragma: no cover
    from dcee import planners
    from dcee.errors import DceeInputError
    from dcee.estimation import ParticleFilter, SourcePrior
    from dcee.models import (
        GridAgent,
        IsotropicPlume,
        SearchVolume,
        Sensor,
        isotropic_concentration,
    )
    from dcee.searcher import Searcher, SourceEstimate


def __getattr__(name: str) -> Any:
    if name == "planners":
        return importlib.import_module("dcee.planners")
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'dcee' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY, "planners"])


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
