"""Concentration sensor (the paper's sensor equation, eq. 3) with its exact likelihood.

Generative model of one reading z given the expected concentration C (g/m³):

1. With probability ``pd`` the sensor *detects*: y = C + v, v ~ N(0, σ(C)²),
   σ(C) = ``sigma_frac``·C + ``sigma_min``. If y ≥ ``threshold`` the reading is y.
2. Otherwise (missed, or y below the threshold) it is a *non-detection*. With probability
   ``false_alarm`` a non-detection is replaced by a false alarm, z = threshold + E,
   E ~ Exponential(mean ``false_alarm_scale``); else the reading is reported as 0.

Any reading below the threshold is treated as a non-detection, so a robot may pass its raw
sub-threshold value. The likelihood below is the exact density of this model with respect to
(point mass at "non-detection") + (Lebesgue measure above the threshold), so it integrates to 1
over readings (tested), and :meth:`Sensor.simulate` draws from exactly this model (tested).

Defaults are the paper's: threshold 0.5 mg/m³ = 5e-4 g/m³, Pd = 0.7; σ_min = 1e-4 g/m³ and
σ_frac = 0.5 follow the authors' example code. ``false_alarm`` defaults to 0 (the paper's model).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import log_ndtr

from dcee.errors import DceeInputError


@dataclass(frozen=True)
class Sensor:
    """Point concentration sensor; both simulates readings and gives p(z | C)."""

    threshold: float = 5e-4
    pd: float = 0.7
    sigma_min: float = 1e-4
    sigma_frac: float = 0.5
    false_alarm: float = 0.0
    false_alarm_scale: float = 5e-4

    def __post_init__(self) -> None:
        checks = {
            "threshold": self.threshold > 0,
            "pd": 0 < self.pd <= 1,
            "sigma_min": self.sigma_min > 0,
            "sigma_frac": self.sigma_frac >= 0,
            "false_alarm": 0 <= self.false_alarm < 1,
            "false_alarm_scale": self.false_alarm_scale > 0,
        }
        allowed = {
            "threshold": "> 0",
            "pd": "in (0, 1]",
            "sigma_min": "> 0",
            "sigma_frac": ">= 0",
            "false_alarm": "in [0, 1)",
            "false_alarm_scale": "> 0",
        }
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise DceeInputError(f"sensor.{name}", f"must be {allowed[name]}, got {value}")

    @property
    def params(self) -> np.ndarray:
        """Parameters packed for the compiled kernels (order fixed by ``dcee.kernels``).

        After the six fields come three derived constants for concentrations below
        ``c_lin = 1e-6 σ_min`` (most particle-reading pairs far from a plume), where the kernels
        use log P(missed | C) ≈ L0 + L1·C instead of an erfc: c_lin, L0 = log P(missed | 0) and
        L1 = its derivative at 0. The neglected second-order term is below 1e-15 in absolute
        log-likelihood (tested).
        """
        x0 = self.threshold / self.sigma_min
        log_missed0 = float(
            np.logaddexp(
                np.log1p(-self.pd) if self.pd < 1 else -np.inf, np.log(self.pd) + log_ndtr(x0)
            )
        )
        dx_dc = -(self.sigma_frac * self.threshold + self.sigma_min) / self.sigma_min**2
        pdf = math.exp(-0.5 * x0 * x0) / math.sqrt(2.0 * math.pi)
        slope0 = self.pd * pdf * dx_dc / math.exp(log_missed0)
        return np.array(
            [
                self.threshold,
                self.pd,
                self.sigma_min,
                self.sigma_frac,
                self.false_alarm,
                self.false_alarm_scale,
                1e-6 * self.sigma_min,
                log_missed0,
                slope0,
            ]
        )

    def is_detection(self, reading: np.ndarray | float) -> np.ndarray:
        """True where a reading counts as a detection (at or above the threshold)."""
        return np.asarray(reading) >= self.threshold

    # --- likelihood -------------------------------------------------------------------------

    def log_likelihood(self, reading: np.ndarray | float, conc: np.ndarray | float) -> np.ndarray:
        """log p(z | C), NumPy reference; broadcasts ``reading`` against ``conc``."""
        z = np.asarray(reading, dtype=np.float64)
        c = np.asarray(conc, dtype=np.float64)
        sigma = self.sigma_frac * c + self.sigma_min
        # P(non-detection | C) = (1 − Pd) + Pd Φ((thr − C)/σ)
        log_below = log_ndtr((self.threshold - c) / sigma)
        log_missed = np.logaddexp(
            np.log1p(-self.pd) if self.pd < 1 else -np.inf, np.log(self.pd) + log_below
        )
        log_nd = log_missed + (np.log1p(-self.false_alarm) if self.false_alarm > 0 else 0.0)
        r = (z - c) / sigma
        log_det = np.log(self.pd) - 0.5 * r * r - np.log(sigma) - 0.5 * np.log(2 * np.pi)
        if self.false_alarm > 0:
            log_fa = (
                np.log(self.false_alarm)
                + log_missed
                - (z - self.threshold) / self.false_alarm_scale
                - np.log(self.false_alarm_scale)
            )
            log_det = np.logaddexp(log_det, log_fa)
        return np.where(z < self.threshold, log_nd, log_det)

    def likelihood(self, reading: np.ndarray | float, conc: np.ndarray | float) -> np.ndarray:
        """p(z | C): probability for a non-detection, density (per g/m³) for a detection."""
        return np.exp(self.log_likelihood(reading, conc))

    # --- simulation -------------------------------------------------------------------------

    @staticmethod
    def draw_noise(rng: np.random.Generator, size: int | tuple[int, ...]) -> np.ndarray:
        """Standard random numbers for :meth:`simulate_from`: shape ``size + (4,)``.

        Columns: uniform for detection, standard normal for the noise, uniform for false alarm,
        standard exponential for its excess. Drawing the same count per reading keeps seeded
        streams aligned by step, whatever the positions (common random numbers).
        """
        size = (size,) if isinstance(size, int) else tuple(size)
        out = np.empty((*size, 4))
        out[..., 0] = rng.random(size)
        out[..., 1] = rng.standard_normal(size)
        out[..., 2] = rng.random(size)
        out[..., 3] = rng.standard_exponential(size)
        return out

    def simulate_from(self, conc: np.ndarray | float, noise: np.ndarray) -> np.ndarray:
        """Readings for concentrations ``conc`` from pre-drawn ``noise`` (shape conc.shape+(4,)).

        Non-detections are returned as 0.0.
        """
        c = np.asarray(conc, dtype=np.float64)
        noise = np.asarray(noise, dtype=np.float64)
        y = c + (self.sigma_frac * c + self.sigma_min) * noise[..., 1]
        detected = (noise[..., 0] < self.pd) & (y >= self.threshold)
        false_alarm = (~detected) & (noise[..., 2] < self.false_alarm)
        fa_value = self.threshold + self.false_alarm_scale * noise[..., 3]
        return np.where(detected, y, np.where(false_alarm, fa_value, 0.0))

    def simulate(self, conc: np.ndarray | float, rng: np.random.Generator) -> np.ndarray:
        """Draw readings (g/m³, 0.0 for a non-detection) for expected concentrations ``conc``."""
        c = np.asarray(conc, dtype=np.float64)
        return self.simulate_from(c, self.draw_noise(rng, c.shape))
