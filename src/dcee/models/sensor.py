"""Concentration sensor and its likelihood: the paper's model and a fluctuation-aware one.

Generative model of one reading z given the expected (time-mean) concentration C (g/m³):

1. With probability ``outlier`` the reading is an *outlier*: z is log-uniform on
   [``threshold``, ``max_reading``] whatever C (a spike, a glitch, another source). This bounds
   the influence of any one reading: no particle's likelihood can fall below
   outlier · g(z), so one absurd reading cannot collapse the filter.
2. Otherwise, with probability ``pd`` the sensor *detects*: y is drawn from the family's reading
   distribution around C; if y ≥ ``threshold`` the reading is y.

   * ``family = "gaussian"`` (the paper's eq. 3): y = C + v, v ~ N(0, σ(C)²),
     σ(C) = ``sigma_frac``·C + ``sigma_min``.
   * ``family = "lognormal"`` (concentration fluctuations): ln y ~ N(ln C − s²/2, s²), s =
     ``log_sd``, so E[y] = C. A turbulent plume's hold-averaged concentration is intermittent
     (zero for a share of the time: 1 − ``pd``, the intermittency factor) and, when present,
     close to log-normal with a spread of the order of its mean (Yee & Chan 1997; Yee 2017
     uses the same two-part form with a clipped gamma). This is the ``"fluctuation"``
     likelihood of the scenarios.

   With ``log_sd_length`` > 0 the spread grows near the source, s(r) = ``log_sd`` +
   ``log_sd_near`` · exp(−r / ``log_sd_length``): hold-averaged readings of a turbulent plume
   fluctuate most close to the release and are smoothed by mixing downwind (fitted to the
   filament truth: 2Δℓ ≈ 1,150 for the two parameters, docs/scenarios.md).

   With ``near_length`` > 0 the detection probability falls near the source:
   Pd(r) = ``pd`` · (1 − exp(−r / near_length)) at distance r from the (hypothesised) source.
   Close to a release the plume is a thin, meandering thread that a held sensor rarely meets,
   so non-detections are common exactly where the mean concentration is highest; a constant Pd
   then pulls the estimate downwind (measured, docs/scenarios.md).

3. Otherwise (missed, or y below the threshold) it is a *non-detection*. With probability
   ``false_alarm`` a non-detection is replaced by a false alarm, z = threshold + E,
   E ~ Exponential(mean ``false_alarm_scale``); else the reading is reported as 0.

Any reading below the threshold is treated as a non-detection, so a robot may pass its raw
sub-threshold value; a reading above ``max_reading`` (the instrument's physical range) is
refused. The likelihood below is the exact density of this model with respect to (point mass at
"non-detection") + (Lebesgue measure above the threshold), so it integrates to 1 over readings
(tested), and :meth:`Sensor.simulate` draws from exactly this model (tested).

Defaults are the paper's: threshold 0.5 mg/m³ = 5e-4 g/m³, Pd = 0.7; σ_min = 1e-4 g/m³ and
σ_frac = 0.5 follow the authors' example code; ``false_alarm`` defaults to 0. ``outlier``
defaults to :data:`OUTLIER_DEFAULT` (0.01), the same outlier safety as every scenario's
estimator, so a filter built from the classes alone is as safe as one built from a scenario;
the paper's exact model (``outlier`` = 0) is :meth:`Sensor.paper_exact`. A sensor used to
*simulate* readings draws outliers at that rate too: the scenarios' simulated instrument
(:meth:`dcee.scenarios.Scenario.make_sensor`) sets 0, spikes being injected on purpose
(:class:`dcee.simulation.InjectedTruth`). ``max_reading`` = 1e4 g/m³: no gas in air at ambient
conditions is denser than about 10 kg/m³, so a larger reading is a fault, not a measurement.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.special import log_ndtr

from dcee.errors import DceeInputError
from dcee.models.plume import MIN_DISTANCE
from dcee.models.sensor_draws import ReadingDraws
from dcee.models.sensor_kernels import SensorParams

Family = Literal["gaussian", "lognormal"]

OUTLIER_DEFAULT = 0.01
"""Outlier weight of every reading model unless set (the :class:`Sensor` class and the scenarios'
``estimator.outlier``, every likelihood, the paper's included), so that one reading no hypothesis
can explain (a spike, a stuck or saturated sensor) never captures the posterior. Chosen on the
tuning configurations (random:1-6, dcee-cl, one 10⁶ × reading at 40, 60 or 100 s,
``studies/spike_study.py``): weight 0 lost 14 of 18 acquired searches to the spike, 0.001 and
0.01 none; 0.01, the larger, bounds a reading's likelihood ratio 10× tighter. 0 is the paper's
exact likelihood (:meth:`Sensor.paper_exact`; ``estimator.outlier = 0`` in a scenario)."""


@dataclass(frozen=True)
class Sensor(ReadingDraws):
    """Point concentration sensor; both simulates readings and gives p(z | C)."""

    threshold: float = 5e-4
    pd: float = 0.7
    sigma_min: float = 1e-4
    sigma_frac: float = 0.5
    false_alarm: float = 0.0
    false_alarm_scale: float = 5e-4
    family: Family = "gaussian"
    log_sd: float = 1.0
    outlier: float = OUTLIER_DEFAULT
    """weight of the outlier component (log-uniform on [threshold, max_reading]);
    :data:`OUTLIER_DEFAULT` unless set, 0 = the paper's exact model (:meth:`paper_exact`)"""
    max_reading: float = 1e4
    near_length: float = 0.0
    log_sd_near: float = 0.0
    log_sd_length: float = 0.0
    conserve_mean: bool = False
    """log-normal family: a detection's mean is C / Pd(r) (True), so a reading's mean, zeros
    included, is the plume's time mean C (Yee & Chan 1997: the in-plume conditional mean is the
    mean over the intermittency factor); False: a detection's mean is C, so the reading's mean is
    Pd(r) · C"""
    magnitude: bool = True
    """True: a detection weighs by its magnitude's density (the paper's eq. 3, the log-normal
    family); False: by its probability only, times a log-uniform density on [threshold,
    max_reading] that every hypothesis shares (detection-only readings)"""

    def __post_init__(self) -> None:
        if self.family not in ("gaussian", "lognormal"):
            raise DceeInputError(
                "sensor.family", f"must be gaussian or lognormal, got {self.family!r}"
            )
        checks = {
            "threshold": (self.threshold > 0, "> 0"),
            "pd": (0 < self.pd <= 1, "in (0, 1]"),
            "sigma_min": (self.sigma_min > 0, "> 0"),
            "sigma_frac": (self.sigma_frac >= 0, ">= 0"),
            "false_alarm": (0 <= self.false_alarm < 1, "in [0, 1)"),
            "false_alarm_scale": (self.false_alarm_scale > 0, "> 0"),
            "log_sd": (0 < self.log_sd <= 5, "in (0, 5]"),
            "outlier": (0 <= self.outlier < 1, "in [0, 1)"),
            "max_reading": (self.max_reading > self.threshold, "> threshold"),
            "near_length": (0 <= self.near_length <= 1e3, "in [0, 1000] m"),
            "log_sd_near": (0 <= self.log_sd_near <= 10, "in [0, 10]"),
            "log_sd_length": (0 <= self.log_sd_length <= 1e3, "in [0, 1000] m"),
        }
        for name, (ok, allowed) in checks.items():
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise DceeInputError(f"sensor.{name}", f"must be {allowed}, got {value}")

    @classmethod
    def paper_exact(cls, **settings: float | str | bool) -> Sensor:
        """The paper's eq. 3 exactly: no outlier component (``outlier`` = 0), by name, so that
        no filter loses its outlier safety by omission. ``settings``: any other field."""
        return cls(**{**settings, "outlier": 0.0})  # type: ignore[arg-type]

    @property
    def lognormal(self) -> bool:
        return self.family == "lognormal"

    @functools.cached_property
    def params(self) -> SensorParams:
        """The model as the compiled kernels read it (:class:`SensorParams`); computed once
        per (immutable) sensor.

        Below ``c_lin`` the kernels use log P(missed | C) ≈ lin0 + lin1·C instead of an erfc.
        Gaussian family: c_lin = 1e-6 σ_min, lin0 = log P(missed | 0), lin1 its derivative at
        0; the neglected second-order term is below 1e-15 in absolute log-likelihood (tested).
        Log-normal family: c_lin puts the threshold 9 s above the location, where
        P(missed) = 1 − Pd Φ(−9) = 1 to 1e-18, so lin0 = lin1 = 0.
        """
        if self.lognormal:
            # the largest spread (at the source) puts the threshold fewest s above the location
            s = self.log_sd + (self.log_sd_near if self.log_sd_length > 0 else 0.0)
            v_thr = math.log(self.threshold)
            c_lin = self.threshold * math.exp(0.5 * s * s - 9.0 * s) if s < 9 else -1.0
            if self.conserve_mean:
                # the location rises by −ln Pd(r); the kernels clamp r at the plume's minimum
                # distance, so the smallest Pd they see is Pd(MIN_DISTANCE)
                c_lin *= float(self.detect_prob(MIN_DISTANCE))
            lin0 = lin1 = 0.0
        else:
            v_thr = self.threshold
            x0 = self.threshold / self.sigma_min
            lin0 = float(
                np.logaddexp(
                    np.log1p(-self.pd) if self.pd < 1 else -np.inf,
                    np.log(self.pd) + log_ndtr(x0),
                )
            )
            dx_dc = -(self.sigma_frac * self.threshold + self.sigma_min) / self.sigma_min**2
            pdf = math.exp(-0.5 * x0 * x0) / math.sqrt(2.0 * math.pi)
            lin1 = self.pd * pdf * dx_dc / math.exp(lin0)
            # with a distance-dependent Pd the constant linearisation does not hold: never use it
            c_lin = 1e-6 * self.sigma_min if self.near_length == 0 else -1.0
        return SensorParams(
            lognormal=1.0 if self.lognormal else 0.0,
            threshold=self.threshold,
            v_threshold=v_thr,
            pd=self.pd,
            log_pd=math.log(self.pd),
            near_length=self.near_length,
            sigma_min=self.sigma_min,
            sigma_frac=self.sigma_frac,
            log_sd=self.log_sd,
            half_s2=0.5 * self.log_sd**2,
            log_sd_near=self.log_sd_near,
            log_sd_length=self.log_sd_length,
            false_alarm=self.false_alarm,
            false_alarm_scale=self.false_alarm_scale,
            log_false_alarm=math.log(self.false_alarm) if self.false_alarm > 0 else -math.inf,
            log_not_false_alarm=math.log1p(-self.false_alarm),
            log_keep=math.log1p(-self.outlier),
            log_outlier=self._log_outlier_times_z(),
            c_lin=c_lin,
            lin0=lin0,
            lin1=lin1,
            magnitude=1.0 if self.magnitude else 0.0,
            conserve_mean=1.0 if self.lognormal and self.conserve_mean else 0.0,
            log_flat=self._log_flat,
        )

    @property
    def _log_flat(self) -> float:
        """log(g(z) · z), g the log-uniform density on [threshold, max_reading] (the same for
        every z): the outliers' and the detection-only magnitudes' density."""
        return -math.log(math.log(self.max_reading / self.threshold))

    def _log_outlier_times_z(self) -> float:
        """log(outlier · g(z) · z) with g the log-uniform density on [threshold, max_reading]."""
        if self.outlier == 0:
            return -math.inf
        return math.log(self.outlier) + self._log_flat

    def is_detection(self, reading: np.ndarray | float) -> np.ndarray:
        """True where a reading counts as a detection (at or above the threshold)."""
        return np.asarray(reading) >= self.threshold

    def check_reading(self, reading: object) -> float:
        """A told reading as a float, or :class:`DceeInputError` naming what is allowed."""
        if isinstance(reading, bool | str | bytes) or not isinstance(
            reading, int | float | np.integer | np.floating | np.ndarray
        ):
            raise DceeInputError("reading", f"must be a real number in g/m³, got {reading!r}")
        if isinstance(reading, np.ndarray) and (
            reading.shape != () or reading.dtype.kind not in "iuf"
        ):
            raise DceeInputError("reading", f"must be a real number in g/m³, got {reading!r}")
        value = float(reading)
        if not math.isfinite(value):
            raise DceeInputError("reading", f"must be a finite number, got {value}")
        if value > self.max_reading:
            raise DceeInputError(
                "reading",
                f"{value:g} g/m³ is above the sensor's physical maximum sensor.max_reading = "
                f"{self.max_reading:g} g/m³ (a fault, not a measurement)",
            )
        return value

    # --- likelihood -------------------------------------------------------------------------

    def log_sd_at(self, distance: np.ndarray | float = np.inf) -> np.ndarray:
        """s(r): the log-normal family's standard deviation of ln z at ``distance`` m from the
        source, ``log_sd`` + ``log_sd_near`` · exp(−r / ``log_sd_length``) (constant with
        ``log_sd_length`` = 0)."""
        r = np.asarray(distance, dtype=np.float64)
        if self.log_sd_length == 0:
            return np.full_like(r, self.log_sd)
        return self.log_sd + self.log_sd_near * np.exp(-r / self.log_sd_length)

    def _loc_sigma(
        self, c: np.ndarray, distance: np.ndarray | float = np.inf
    ) -> tuple[np.ndarray, np.ndarray]:
        if self.lognormal:
            s = self.log_sd_at(distance)
            loc = np.log(np.maximum(c, 1e-300)) - 0.5 * s**2
            if self.conserve_mean:
                loc = loc - np.log(self.detect_prob(distance))
            return np.broadcast_arrays(loc, s)
        return c, self.sigma_frac * c + self.sigma_min

    def detect_prob(self, distance: np.ndarray | float = np.inf) -> np.ndarray:
        """Pd(r): detection probability at ``distance`` m from the source (see ``near_length``)."""
        r = np.asarray(distance, dtype=np.float64)
        if self.near_length == 0:
            return np.full_like(r, self.pd)
        return -self.pd * np.expm1(-r / self.near_length)

    def log_likelihood(
        self,
        reading: np.ndarray | float,
        conc: np.ndarray | float,
        distance: np.ndarray | float = np.inf,
    ) -> np.ndarray:
        """log p(z | C, r), NumPy reference; broadcasts ``reading``, ``conc`` and ``distance``
        (m from the source; only used with ``near_length`` or ``log_sd_length`` > 0)."""
        z = np.asarray(reading, dtype=np.float64)
        c = np.asarray(conc, dtype=np.float64)
        pd = self.detect_prob(distance)
        loc, sigma = self._loc_sigma(c, distance)
        v_thr = math.log(self.threshold) if self.lognormal else self.threshold
        # P(no true detection | C) = (1 − Pd) + Pd Φ((v_thr − loc)/σ)
        log_below = log_ndtr((v_thr - loc) / sigma)
        with np.errstate(divide="ignore"):
            log_missed = np.logaddexp(np.log1p(-pd), np.log(pd) + log_below)
        log_keep = math.log1p(-self.outlier)
        log_nd = log_missed + math.log1p(-self.false_alarm) + log_keep
        zd = np.maximum(z, self.threshold)  # detections only; the rest is masked below
        v = np.log(zd) if self.lognormal else zd
        if self.magnitude:
            r = (v - loc) / sigma
            log_det = np.log(pd) - 0.5 * r * r - np.log(sigma) - 0.5 * np.log(2 * np.pi)
            if self.lognormal:
                log_det = log_det - np.log(zd)
        else:  # detection only: P(z ≥ thr | C, r) · g(z), g log-uniform
            log_det = np.log(pd) + log_ndtr((loc - v_thr) / sigma) + self._log_flat - np.log(zd)
        if self.false_alarm > 0:
            log_fa = (
                np.log(self.false_alarm)
                + log_missed
                - (zd - self.threshold) / self.false_alarm_scale
                - np.log(self.false_alarm_scale)
            )
            log_det = np.logaddexp(log_det, log_fa)
        log_det = log_det + log_keep
        if self.outlier > 0:
            log_det = np.logaddexp(log_det, self._log_outlier_times_z() - np.log(zd))
        return np.where(z < self.threshold, log_nd, log_det)

    def likelihood(
        self,
        reading: np.ndarray | float,
        conc: np.ndarray | float,
        distance: np.ndarray | float = np.inf,
    ) -> np.ndarray:
        """p(z | C, r): probability for a non-detection, density (per g/m³) for a detection."""
        return np.exp(self.log_likelihood(reading, conc, distance))

    def transformed_readings(
        self, readings: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What the planners' kernels need of readings (any shape), in the transformed frame:
        (v, false-alarm term, outlier term, log Jacobian), see :mod:`dcee.models.sensor_kernels`.

        Non-detections get v = v_thr − 1 (below the threshold; never a detection). The log
        Jacobian (−ln z for log-normal detections, else 0) is common to every particle, so it
        only shifts the log evidence; the other terms are relative to it.
        """
        z = np.asarray(readings, dtype=np.float64)
        det = z >= self.threshold
        zd = np.where(det, z, self.threshold)
        log_z = np.log(zd)
        if self.lognormal:
            v = np.where(det, log_z, math.log(self.threshold) - 1.0)
            jac = np.where(det, -log_z, 0.0)
        else:
            v = np.where(det, z, 0.5 * self.threshold)
            jac = np.zeros_like(z)
        fa = (
            math.log(self.false_alarm)
            - (zd - self.threshold) / self.false_alarm_scale
            - math.log(self.false_alarm_scale)
            - jac
            if self.false_alarm > 0
            else np.full_like(z, -np.inf)
        )
        out = self._log_outlier_times_z() - log_z - jac
        return v, fa, out, jac
