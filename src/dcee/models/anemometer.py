"""A measured wind: the anemometer a robot carries, as a reading model of the estimator and as
an instrument of the simulator.

A reading is (speed m/s, direction rad): the wind's speed, and the direction it comes *from*,
counter-clockwise from +x, as the plume model's φ (the node converts a wind vector in the map
frame, :func:`wind_from_vector`). Model: speed ~ Normal(u, ``speed_sd``²) and direction ~
von Mises(φ, κ = 1/``direction_sd``²), independent of each other and of every other reading,
where (u, φ) is the source term's wind (the isotropic plume's uniform wind). The readings of a
search enter the estimator through their sufficient statistics (:class:`WindEvidence`), so the
resample-move step's full-history target costs five numbers however many there were.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import i0e

from dcee.errors import DceeInputError

U_COLUMN, PHI_COLUMN = 4, 5
"""Columns of u (m/s) and φ (rad) in an (N, 8) source term."""


@dataclass(frozen=True)
class Anemometer:
    """Noise of one wind reading: ``speed_sd`` m/s and ``direction_sd`` rad (> 0)."""

    speed_sd: float = 0.5
    direction_sd: float = math.radians(10.0)

    def __post_init__(self) -> None:
        for name in ("speed_sd", "direction_sd"):
            v = getattr(self, name)
            if isinstance(v, bool) or not (
                isinstance(v, int | float) and math.isfinite(v) and v > 0
            ):
                raise DceeInputError(f"anemometer.{name}", f"must be a number > 0, got {v!r}")

    @property
    def kappa(self) -> float:
        """von Mises concentration of the direction reading, 1/``direction_sd``²."""
        return 1.0 / self.direction_sd**2

    def check(self, speed: object, direction: object) -> tuple[float, float]:
        """A reading as floats, or :class:`DceeInputError` naming what is allowed."""
        for name, v in (("wind speed", speed), ("wind direction", direction)):
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise DceeInputError(name, f"must be a real number, got {v!r}")
            if not math.isfinite(float(v)):
                raise DceeInputError(name, f"must be finite, got {v!r}")
        if float(speed) < 0:
            raise DceeInputError("wind speed", f"must be >= 0 m/s, got {speed!r}")
        return float(speed), float(direction)

    def log_likelihood(self, theta: np.ndarray, speed: float, direction: float) -> np.ndarray:
        """(N,) log p(speed, direction | Θ) for (N, 8) source terms."""
        return WindEvidence.of(speed, direction).log_likelihood(theta, self)

    def simulate(self, u: float, phi: float, rng: np.random.Generator) -> tuple[float, float]:
        """One reading of the wind (u m/s from φ rad): speed and direction drawn from the model
        (a negative speed draw is reported as 0)."""
        speed = max(0.0, u + self.speed_sd * float(rng.standard_normal()))
        direction = float(rng.vonmises(phi, self.kappa))
        return speed, direction


@dataclass(frozen=True)
class WindEvidence:
    """Sufficient statistics of n wind readings: n, Σ speed, Σ speed², Σ cos(direction),
    Σ sin(direction)."""

    n: int = 0
    sum_speed: float = 0.0
    sum_speed2: float = 0.0
    sum_cos: float = 0.0
    sum_sin: float = 0.0

    @classmethod
    def of(cls, speed: float, direction: float) -> WindEvidence:
        return cls(1, speed, speed * speed, math.cos(direction), math.sin(direction))

    def __add__(self, other: WindEvidence) -> WindEvidence:
        return WindEvidence(
            self.n + other.n,
            self.sum_speed + other.sum_speed,
            self.sum_speed2 + other.sum_speed2,
            self.sum_cos + other.sum_cos,
            self.sum_sin + other.sum_sin,
        )

    def log_likelihood(self, theta: np.ndarray, model: Anemometer) -> np.ndarray:
        """(N,) Σ over the readings of log p(reading | Θ), for (N, 8) source terms."""
        theta = np.atleast_2d(theta)
        if self.n == 0:
            return np.zeros(len(theta))
        u, phi = theta[:, U_COLUMN], theta[:, PHI_COLUMN]
        s2 = model.speed_sd**2
        k = model.kappa
        speed_sq = self.sum_speed2 - 2.0 * u * self.sum_speed + self.n * u * u
        # log(2π I0(κ)) = log(2π) + log(i0e(κ)) + κ (exponentially scaled Bessel: no overflow)
        log_norm_dir = math.log(2.0 * math.pi) + math.log(i0e(k)) + k
        return (
            -0.5 * speed_sq / s2
            - 0.5 * self.n * math.log(2.0 * math.pi * s2)
            + k * (self.sum_cos * np.cos(phi) + self.sum_sin * np.sin(phi))
            - self.n * log_norm_dir
        )


def wind_from_vector(vx: float, vy: float) -> tuple[float, float]:
    """(speed m/s, direction rad the wind comes from, counter-clockwise from +x) of a wind
    velocity (vx, vy) m/s in the map frame (where the air moves to, ENU)."""
    return math.hypot(vx, vy), math.atan2(-vy, -vx)


__all__ = ["PHI_COLUMN", "U_COLUMN", "Anemometer", "WindEvidence", "wind_from_vector"]
