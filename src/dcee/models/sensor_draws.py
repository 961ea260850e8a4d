"""Drawing readings from the sensor model of :mod:`dcee.models.sensor`: a simulated
instrument's readings (:meth:`ReadingDraws.simulate`, from pre-drawn noise for common random
numbers) and readings conditioned on a detection (the planners' stratified expectation).

A job of its own beside the likelihood: the likelihood evaluates a reading, these draw one,
and the tests check each against the other (the draws' histogram against the density).
:class:`ReadingDraws` is a base of :class:`dcee.models.sensor.Sensor`, whose fields it reads.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import log_ndtr, ndtri_exp


class ReadingDraws:
    """Readings drawn from the sensor model (the methods of :class:`~dcee.models.sensor.Sensor`
    that simulate; they read its fields)."""

    @property
    def n_noise(self) -> int:
        """Standard random numbers per reading: 4, or 6 with outliers."""
        return 6 if self.outlier > 0 else 4

    def draw_noise(self, rng: np.random.Generator, size: int | tuple[int, ...]) -> np.ndarray:
        """Standard random numbers for :meth:`simulate_from`: shape ``size + (n_noise,)``.

        Columns: uniform for detection, standard normal for the noise, uniform for false alarm,
        standard exponential for its excess, and with outliers a uniform for the outlier and a
        uniform for its value. Drawing the same count per reading keeps seeded streams aligned
        by step, whatever the positions (common random numbers).
        """
        size = (size,) if isinstance(size, int) else tuple(size)
        out = np.empty((*size, self.n_noise))
        out[..., 0] = rng.random(size)
        out[..., 1] = rng.standard_normal(size)
        out[..., 2] = rng.random(size)
        out[..., 3] = rng.standard_exponential(size)
        if self.outlier > 0:
            out[..., 4] = rng.random(size)
            out[..., 5] = rng.random(size)
        return out

    def simulate_from(
        self,
        conc: np.ndarray | float,
        noise: np.ndarray,
        distance: np.ndarray | float = np.inf,
    ) -> np.ndarray:
        """Readings for concentrations ``conc`` from pre-drawn ``noise`` (conc.shape + (n,)),
        ``distance`` m from the source (only used with ``near_length`` or ``log_sd_length``
        > 0).

        Non-detections are returned as 0.0.
        """
        c = np.asarray(conc, dtype=np.float64)
        noise = np.asarray(noise, dtype=np.float64)
        pd = self.detect_prob(distance)
        if self.lognormal:
            s = self.log_sd_at(distance)
            y = c * np.exp(s * noise[..., 1] - 0.5 * s * s)
            if self.conserve_mean:
                y = y / pd
        else:
            y = c + (self.sigma_frac * c + self.sigma_min) * noise[..., 1]
        detected = (noise[..., 0] < pd) & (y >= self.threshold)
        false_alarm = (~detected) & (noise[..., 2] < self.false_alarm)
        fa_value = self.threshold + self.false_alarm_scale * noise[..., 3]
        z = np.where(detected, y, np.where(false_alarm, fa_value, 0.0))
        if self.outlier > 0 and noise.shape[-1] >= 6:
            spike = self.threshold * (self.max_reading / self.threshold) ** noise[..., 5]
            z = np.where(noise[..., 4] < self.outlier, spike, z)
        return z

    def simulate_detection(
        self,
        conc: np.ndarray | float,
        uniforms: np.ndarray,
        distance: np.ndarray | float = np.inf,
    ) -> np.ndarray:
        """Readings drawn from p(z | C, r, z is a detection), exactly, from pre-drawn standard
        uniforms (conc.shape + (2,)): column 0 picks the kind of detection (a true one, a false
        alarm or an outlier) with its probability given C; column 1 places the reading within it
        (a true detection is the family's reading distribution truncated at the threshold,
        inverted in the upper tail so that C far below the threshold stays exact).

        Used by the planners' stratified expectation (:mod:`dcee.planning.predicted`). Where
        C, r admit no detection at all the reading is 0.0 (a non-detection).
        """
        c = np.asarray(conc, dtype=np.float64)
        u = np.asarray(uniforms, dtype=np.float64)
        loc, sigma = self._loc_sigma(c, distance)
        v_thr = math.log(self.threshold) if self.lognormal else self.threshold
        a = (v_thr - loc) / sigma  # the threshold in standard units
        log_tail = log_ndtr(-a)  # log P(y ≥ threshold | C)
        keep = 1.0 - self.outlier
        p_true = keep * self.detect_prob(distance) * np.exp(log_tail)
        p_false = keep * (1.0 - p_true / keep) * self.false_alarm
        total = p_true + p_false + self.outlier
        pick = u[..., 0] * total
        u1 = np.clip(u[..., 1], 1e-300, 1.0)
        with np.errstate(over="ignore", invalid="ignore"):
            x = -ndtri_exp(np.log(u1) + log_tail)  # standard normal truncated to x ≥ a
            v = np.maximum(loc + sigma * x, v_thr)
            true_value = np.exp(v) if self.lognormal else v
        false_value = self.threshold - self.false_alarm_scale * np.log(u1)
        spike = self.threshold * (self.max_reading / self.threshold) ** u1
        other = np.where(pick < p_true + p_false, false_value, spike)
        z = np.where(pick < p_true, true_value, other)
        return np.where(total > 0, np.maximum(z, self.threshold), 0.0)

    def simulate(self, conc: np.ndarray | float, rng: np.random.Generator) -> np.ndarray:
        """Draw readings (g/m³, 0.0 for a non-detection) for expected concentrations ``conc``."""
        c = np.asarray(conc, dtype=np.float64)
        return self.simulate_from(c, self.draw_noise(rng, c.shape))
