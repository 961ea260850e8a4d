"""Ground truth: what the sensor really sees. The estimator never reads it."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from dcee.models.plume import IsotropicPlume


class TruthModel(ABC):
    """Ground-truth concentration field, possibly time-varying."""

    name: str = ""

    @abstractmethod
    def concentration(self, position: np.ndarray, time: float) -> float:
        """Concentration (g/m³) at ``position`` (3,) m at ``time`` s."""

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) concentrations at (K, 3) positions (for figures)."""
        return np.array([self.concentration(p, time) for p in positions])


class IsotropicTruth(TruthModel):
    """The paper's simulation truth: the same isotropic plume the estimator assumes."""

    name = "isotropic"

    def __init__(self, theta: np.ndarray, plume: IsotropicPlume | None = None) -> None:
        self.theta = np.asarray(theta, dtype=np.float64).reshape(1, 8)
        self.plume = plume or IsotropicPlume()

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.plume.concentration(self.theta, np.reshape(position, (1, 3)))[0, 0])

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        return self.plume.concentration(self.theta, positions)[0]


def make_truth(kind: str, theta: np.ndarray) -> TruthModel:
    """Truth model by the scenario's ``truth.model`` name."""
    if kind == "isotropic":
        return IsotropicTruth(theta)
    raise ValueError(f"unknown truth model {kind!r}")
