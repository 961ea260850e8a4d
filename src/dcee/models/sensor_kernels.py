"""Compiled (numba) sensor likelihood.

NumPy reference: :meth:`dcee.models.sensor.Sensor.log_likelihood`.

Both likelihood families are written in one *transformed frame* so that every kernel, the
filter's and the planners', serves both:

============  ===========================  ==========================  =================
family        location ``loc(C)``          scale ``σ(C)``              reading ``v(z)``
============  ===========================  ==========================  =================
gaussian      C                            σ_frac·C + σ_min            z
lognormal     ln C − s²/2 [− ln Pd(r)]     s                           ln z
============  ===========================  ==========================  =================

A detection's density is Pd·φ((v − loc)/σ)/σ · |dv/dz| (the Jacobian is 1/z for the log-normal
family; it is the same for every particle, so the planners add it to the log evidence only) and a
non-detection has probability (1 − Pd) + Pd·Φ((v_thr − loc)/σ). Detection only
(``magnitude`` 0): a detection's likelihood is its probability Pd·Φ((loc − v_thr)/σ) times a
log-uniform density of its magnitude on [threshold, max_reading] that no hypothesis changes,
so a reading's size, which a turbulent plume decouples from the mean, carries no weight. With
near-source intermittency Pd depends on the distance r between the sensor and the hypothesised
source, Pd(r) = Pd · (1 − exp(−r / near_length)), so every function takes r as well as C. With
``conserve_mean`` the log-normal location is raised by −ln Pd(r): a detection's mean is C / Pd(r),
a reading's mean C. Sensor parameters arrive as a :class:`SensorParams` record (named fields,
all float64).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from dcee.numeric import HALF_LOG_2PI, log_ndtr, logaddexp, ndtr_upper

TINY_CONCENTRATION = 1e-300
"""The log-normal family's location uses ln(max(C, this)), so C = 0 stays finite."""


class SensorParams(NamedTuple):
    """The sensor model as the compiled kernels read it (see :attr:`Sensor.params`)."""

    lognormal: float  # 1.0 for the log-normal (fluctuation) family, 0.0 for the paper's Gaussian
    threshold: float  # g/m³
    v_threshold: float  # threshold in the transformed frame: thr or ln thr
    pd: float  # detection probability (the fluctuation family's intermittency factor)
    log_pd: float
    near_length: float  # m; > 0: Pd(r) = pd (1 − exp(−r / near_length)); 0: Pd = pd
    sigma_min: float  # gaussian: σ(C) = sigma_frac · C + sigma_min
    sigma_frac: float
    log_sd: float  # lognormal: s∞, the standard deviation of ln z far from the source
    half_s2: float  # s∞² / 2
    log_sd_near: float  # lognormal: s(r) = s∞ + log_sd_near · exp(−r / log_sd_length)
    log_sd_length: float  # m; 0: s = s∞ everywhere
    false_alarm: float
    false_alarm_scale: float
    log_false_alarm: float  # −inf without false alarms
    log_not_false_alarm: float  # log(1 − false_alarm)
    log_keep: float  # log(1 − outlier)
    log_outlier: float  # log(outlier / ln(max_reading / threshold)); −inf without outliers
    c_lin: float  # below this C, log P(missed | C) ≈ lin0 + lin1 · C
    lin0: float
    lin1: float
    magnitude: float  # 1.0: a detection's density in its magnitude; 0.0: detection only
    conserve_mean: float  # 1.0 (log-normal): a detection's mean is C / Pd(r); 0.0: C
    log_flat: float  # log(z · g(z)), g the log-uniform density on [threshold, max_reading]


@njit(cache=True, inline="always")
def log_sd_at(r: float, sp: SensorParams) -> float:
    """s(r), the log-normal family's standard deviation of ln z at distance r m from the
    source: s∞ + log_sd_near · exp(−r / log_sd_length) (s∞ with log_sd_length 0)."""
    if sp.log_sd_length > 0.0:
        return sp.log_sd + sp.log_sd_near * math.exp(-r / sp.log_sd_length)
    return sp.log_sd


@njit(cache=True, inline="always")
def transform(c: float, r: float, sp: SensorParams):
    """(loc, σ) of an expected concentration C at distance r m from the source in the
    transformed frame."""
    if sp.lognormal > 0.0:
        shift = log_detection_probability(r, sp) if sp.conserve_mean > 0.0 else 0.0
        if sp.log_sd_length > 0.0:
            s = log_sd_at(r, sp)
            return math.log(max(c, TINY_CONCENTRATION)) - 0.5 * s * s - shift, s
        return math.log(max(c, TINY_CONCENTRATION)) - sp.half_s2 - shift, sp.log_sd
    return c, sp.sigma_frac * c + sp.sigma_min


@njit(cache=True, inline="always")
def detection_probability(r: float, sp: SensorParams) -> float:
    """Pd(r): the detection probability (intermittency factor) at distance r m from the source."""
    if sp.near_length > 0.0:
        return -sp.pd * math.expm1(-r / sp.near_length)
    return sp.pd


@njit(cache=True, inline="always")
def log_detection_probability(r: float, sp: SensorParams) -> float:
    if sp.near_length > 0.0:
        return sp.log_pd + math.log(-math.expm1(-r / sp.near_length))
    return sp.log_pd


@njit(cache=True, inline="always")
def log_missed(c: float, r: float, sp: SensorParams) -> float:
    """log P(no true detection | C, r) = log((1 − Pd(r)) + Pd(r) Φ((v_thr − loc)/σ)).

    Written as log1p(−Pd Φ(−x)): one erfc and one log1p instead of log Φ, log and logaddexp
    (about 3× cheaper, and exact where Φ(−x) is tiny). With Pd = 1 the log Φ(x) form is kept,
    because 1 − Φ(−x) cancels for x ≪ 0. Far below the threshold (C < c_lin) it is linearised.
    """
    if c < sp.c_lin:
        return sp.lin0 + sp.lin1 * c
    loc, sigma = transform(c, r, sp)
    x = (sp.v_threshold - loc) / sigma
    pd = detection_probability(r, sp)
    if pd < 1.0:
        return math.log1p(-pd * ndtr_upper(x))
    return log_ndtr(x)


@njit(cache=True, inline="always")
def log_likelihood(z: float, c: float, r: float, sp: SensorParams) -> float:
    """log p(z | C, r) of one reading (g/m³; below the threshold = non-detection) for an
    expected concentration C at distance r m from the source."""
    thr = sp.threshold
    if z < thr:
        return log_missed(c, r, sp) + sp.log_not_false_alarm + sp.log_keep
    loc, sigma = transform(c, r, sp)
    log_pd = log_detection_probability(r, sp)
    if sp.magnitude == 0.0:
        # detection only: P(a detection | C, r) times a density of its magnitude that no
        # hypothesis changes (log-uniform), so evidences stay comparable with other models
        ld = log_pd + log_ndtr((loc - sp.v_threshold) / sigma) + sp.log_flat - math.log(z)
    elif sp.lognormal > 0.0:
        log_z = math.log(z)
        x = (log_z - loc) / sigma
        ld = log_pd - 0.5 * x * x - math.log(sigma) - HALF_LOG_2PI - log_z
    else:
        x = (z - loc) / sigma
        ld = log_pd - 0.5 * x * x - math.log(sigma) - HALF_LOG_2PI
    if sp.false_alarm > 0.0:
        fas = sp.false_alarm_scale
        lfa = sp.log_false_alarm + log_missed(c, r, sp) - (z - thr) / fas - math.log(fas)
        ld = logaddexp(ld, lfa)
    ld += sp.log_keep
    if sp.log_outlier > -np.inf:
        ld = logaddexp(ld, sp.log_outlier - math.log(z))
    return ld
