"""Scalar numeric helpers for the compiled kernels (numba), each tested against math/scipy.

``vexp`` and ``vlog1p`` are branch-free arithmetic, so LLVM turns loops that call them into
SIMD code (numba's ``math.exp``/``math.log1p`` are scalar libm calls; this llvmlite wheel has
no SVML). They sit at the bottom of the layering: every kernel module may use them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

HALF_LOG_2PI = 0.5 * math.log(2.0 * math.pi)
_INV_SQRT2 = 1.0 / math.sqrt(2.0)


@njit(cache=True, inline="always")
def log_ndtr(x: float) -> float:
    """log Φ(x), accurate also far in the lower tail (asymptotic series below −37)."""
    if x > -37.0:
        return math.log(0.5 * math.erfc(-x * _INV_SQRT2))
    x2 = 1.0 / (x * x)
    series = 1.0 - x2 + 3.0 * x2 * x2 - 15.0 * x2 * x2 * x2 + 105.0 * x2 * x2 * x2 * x2
    return -0.5 * x * x - math.log(-x) - HALF_LOG_2PI + math.log(series)


@njit(cache=True, inline="always")
def ndtr_upper(x: float) -> float:
    """1 − Φ(x) = Φ(−x)."""
    return 0.5 * math.erfc(x * _INV_SQRT2)


@njit(cache=True, inline="always")
def logaddexp(a: float, b: float) -> float:
    """log(e^a + e^b), exact for −inf arguments (scalar libm calls)."""
    if a == -np.inf:
        return b
    if b == -np.inf:
        return a
    if a > b:
        return a + math.log1p(math.exp(b - a))
    return b + math.log1p(math.exp(a - b))


# --- exp that the compiler can vectorise ---------------------------------------------------
# exp(x) = 2^(−m) · e^r with m = round(−x / ln 2), r = x + m ln 2 (Cody-Waite split of ln 2) and
# |r| ≤ ln 2 / 2, a degree-12 Taylor polynomial for e^r, and 2^(−m) assembled from the bits of m.
# Relative error < 1e-15 for −700 ≤ x ≤ 0 (tested against math.exp); x < −700 is treated as −700
# (e^-700 ≈ 1e-304, negligible next to the terms that matter), so only call it with x ≤ 0.
_LN2_HI = 6.93145751953125e-1  # ln 2 with its low bits cleared: m · _LN2_HI is exact
_LN2_LO = 1.42860682030941723212e-6
_INV_LN2 = 1.0 / math.log(2.0)


@njit(cache=True, inline="always")
def _vexp(x: float) -> float:
    """exp(x) for x ≤ 0, vectorisable (see above)."""
    x = max(x, -700.0)
    m = math.floor(-x * _INV_LN2 + 0.5)
    r = (x + m * _LN2_HI) + m * _LN2_LO
    p = 1.0 / 479001600.0
    p = 1.0 / 39916800.0 + r * p
    p = 1.0 / 3628800.0 + r * p
    p = 1.0 / 362880.0 + r * p
    p = 1.0 / 40320.0 + r * p
    p = 1.0 / 5040.0 + r * p
    p = 1.0 / 720.0 + r * p
    p = 1.0 / 120.0 + r * p
    p = 1.0 / 24.0 + r * p
    p = 1.0 / 6.0 + r * p
    p = 0.5 + r * p
    p = 1.0 + r * p
    p = 1.0 + r * p
    mi = np.int64(m)
    scale = 1.0
    scale *= 0.5 if mi & 1 else 1.0
    scale *= 0.25 if mi & 2 else 1.0
    scale *= 0.0625 if mi & 4 else 1.0
    scale *= 3.90625e-3 if mi & 8 else 1.0  # 2^-8
    scale *= 1.52587890625e-05 if mi & 16 else 1.0  # 2^-16
    scale *= 2.3283064365386963e-10 if mi & 32 else 1.0  # 2^-32
    scale *= 5.421010862427522e-20 if mi & 64 else 1.0  # 2^-64
    scale *= 2.938735877055719e-39 if mi & 128 else 1.0  # 2^-128
    scale *= 8.636168555094445e-78 if mi & 256 else 1.0  # 2^-256
    scale *= 7.458340731200207e-155 if mi & 512 else 1.0  # 2^-512
    return p * scale


@njit(cache=True, inline="always")
def _vlog1p(x: float) -> float:
    """log(1 + x) for 0 ≤ x ≤ 1, vectorisable: 2 atanh(t), t = x / (2 + x) ≤ 1/3, by its odd
    series to t^33 (truncation < 3e-17 relative). Used for log-sum-exp of two terms."""
    t = x / (2.0 + x)
    t2 = t * t
    p = 1.0 / 33.0
    p = 1.0 / 31.0 + t2 * p
    p = 1.0 / 29.0 + t2 * p
    p = 1.0 / 27.0 + t2 * p
    p = 1.0 / 25.0 + t2 * p
    p = 1.0 / 23.0 + t2 * p
    p = 1.0 / 21.0 + t2 * p
    p = 1.0 / 19.0 + t2 * p
    p = 1.0 / 17.0 + t2 * p
    p = 1.0 / 15.0 + t2 * p
    p = 1.0 / 13.0 + t2 * p
    p = 1.0 / 11.0 + t2 * p
    p = 1.0 / 9.0 + t2 * p
    p = 1.0 / 7.0 + t2 * p
    p = 1.0 / 5.0 + t2 * p
    p = 1.0 / 3.0 + t2 * p
    p = 1.0 + t2 * p
    return 2.0 * t * p


@njit(cache=True, inline="always")
def vlogaddexp(a: float, b: float) -> float:
    """log(e^a + e^b) for finite a, b (or one of them −inf), vectorisable."""
    hi = max(a, b)
    lo = min(a, b)
    if hi == -np.inf:
        return hi
    return hi + _vlog1p(_vexp(lo - hi))


@njit(cache=True)
def vexp(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = exp(x[i]) for x ≤ 0 with the vectorisable exp (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = _vexp(x[i])


@njit(cache=True)
def vlog1p(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = log1p(x[i]) for 0 ≤ x ≤ 1 with the vectorisable series (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = _vlog1p(x[i])
