"""Scalar numeric helpers for the compiled kernels (numba), each tested against math/scipy.

``vexp``, ``vlog1p``, ``vlog`` and ``verfc`` are branch-free arithmetic, so LLVM turns loops
that call them into SIMD code (numba's ``math.exp``/``math.log``/``math.erfc`` are scalar libm
calls; this llvmlite wheel has no SVML). Kernels that divide must be compiled with
``error_model="numpy"``: numba's default Python error model checks every division for zero,
and that branch alone keeps LLVM from vectorising the loop (measured: erfc 21 → 2.9 ns); so
does indexing with a signed integer that numba cannot prove non-negative (its wraparound
check), so such loops index with ``np.uint64``. These helpers sit at the bottom of the
layering: every kernel module may use them.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

HALF_LOG_2PI = 0.5 * math.log(2.0 * math.pi)
_INV_SQRT2 = 1.0 / math.sqrt(2.0)


def read_only_view(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (no copy). numba compiles one machine code per argument type,
    and an array's mutability is part of its type: a kernel given a filter's particles once
    writeable and once frozen (``ResampleMove.planning_particles``) compiled twice, 14 s of
    the first search on a fresh machine for the history likelihood alone (2026-12-05).
    Kernels that only read an input take it through this, so each compiles once."""
    view = a.view()
    view.flags.writeable = False
    return view


def _bit_cast(source: types.Type, target: types.Type, llvm_target: ir.Type) -> object:
    """A numba intrinsic that reinterprets a ``source`` value's IEEE-754 bits as ``target``: a
    bit cast, free and vectorisable (numba has no scalar frexp/ldexp that LLVM can
    vectorise)."""

    def cast(typingctx, x):
        if x != source:
            return None

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], llvm_target)

        return target(source), codegen

    cast.__name__ = f"bit_cast_{source}_{target}"
    return intrinsic(cast)


_int_as_float = _bit_cast(types.int64, types.float64, ir.DoubleType())
_float_as_int = _bit_cast(types.float64, types.int64, ir.IntType(64))
_int32_as_float32 = _bit_cast(types.int32, types.float32, ir.FloatType())
_float32_as_int32 = _bit_cast(types.float32, types.int32, ir.IntType(32))


_MANTISSA_BITS = np.int64(0x000FFFFFFFFFFFFF)
_ONE_BITS = np.int64(0x3FF0000000000000)


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
_SQRT2 = math.sqrt(2.0)


@njit(cache=True, inline="always")
def exp_scalar(x: float) -> float:
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
    # 2^−m from its bits (0 ≤ m ≤ 1010 for −700 ≤ x ≤ 0: a normal float, exact)
    scale = _int_as_float((np.int64(1023) - np.int64(m)) << np.int64(52))
    return p * scale


@njit(cache=True, inline="always")
def log1p_scalar(x: float) -> float:
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
    return hi + log1p_scalar(exp_scalar(lo - hi))


@njit(cache=True)
def vexp(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = exp(x[i]) for x ≤ 0 with the vectorisable exp (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = exp_scalar(x[i])


@njit(cache=True)
def vlog1p(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = log1p(x[i]) for 0 ≤ x ≤ 1 with the vectorisable series (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = log1p_scalar(x[i])


# --- erfc, Φ and log that the compiler can vectorise (issue 17) -------------------------------
# erfc(y) = e^(−y²) · erfcx(y) for y ≥ 0, with (y + K) · erfcx(y) a Chebyshev series in
# t = (y − K)/(y + K) ∈ [−1, 1) (K = 3; coefficients from studies/fit_erfcx.py, relative error
# < 1e-14 against scipy.special.erfcx on [0, 1e6]), evaluated as the same polynomial in powers
# of t by Horner's rule (_ERFCX_POWERS: numpy's cheb2poly of the series, tested; Σ|a_k| = 3.0,
# so no cancellation): 24 fused multiply-adds where Clenshaw's recurrence took 24 and as many
# subtractions, half the time per value (178 → 94 µs for 44,000 values, one core, lab
# 2026-12-05), the same largest error against scipy (4.0e-15). log(x) = m ln 2 + log1p(x 2^−m − 1)
# with m and x 2^−m ∈ [1, 2) read from the float's bits (no frexp, which numba only has as a scalar
# call).
_ERFCX_K = 3.0
_ERFCX_CHEB = (
    1.4134382239808718,
    -1.131476849074697,
    0.3541081003424861,
    -0.08508704009908587,
    0.014615273272815577,
    -0.0013795571636295227,
    -6.429066714269583e-05,
    3.904342109700625e-05,
    -2.6427850743427207e-06,
    -8.23944015919793e-07,
    1.3247975758016788e-07,
    1.9195224395238778e-08,
    -5.030507708370746e-09,
    -5.842010763322025e-10,
    1.8742300198431857e-10,
    2.4374344807077615e-11,
    -6.991301208084987e-12,
    -1.2571416298189248e-12,
    2.4553105868896866e-13,
    7.059135694242251e-14,
    -7.442238254161089e-15,
    -3.1872876911280614e-15,
    -8.164480785155627e-16,
    -6.280369834735103e-17,
    -1.2560739669470208e-16,
)
_ERFCX_POWERS = (
    1.0740069070883378,
    -0.883394453169885,
    0.5902283571041358,
    -0.31046726190113544,
    0.11952776128845326,
    -0.02682723460248894,
    -0.0012124166574628338,
    0.0030340617140000455,
    -0.0005483094193117422,
    -0.00027677594206967926,
    0.00010756025099266497,
    3.039074264262238e-05,
    -1.7467570237306214e-05,
    -4.731053693648649e-06,
    2.7621434201622248e-06,
    9.701828476691367e-07,
    -4.0928108308012543e-07,
    -2.0437002727029336e-07,
    5.435050142444879e-08,
    3.2264564987978334e-08,
    -1.1080011346809263e-08,
    -1.8274610096520464e-09,
    4.60981155587904e-09,
    -2.634178031930878e-10,
    -1.0536712127723514e-09,
)
_LN2 = math.log(2.0)


@njit(cache=True, inline="always")
def _verfc_pos(y: float) -> float:
    """erfc(y) for y ≥ 0, vectorisable; relative error < 1e-13 while e^(−y²) is a normal
    float (y < 26.5), 0 beyond."""
    inv = 1.0 / (y + _ERFCX_K)
    t = (y - _ERFCX_K) * inv
    # Horner's rule in t, the literals of _ERFCX_POWERS (unrolled so that the loop that calls
    # this vectorises)
    p = -1.0536712127723514e-09
    p = -2.634178031930878e-10 + t * p
    p = 4.60981155587904e-09 + t * p
    p = -1.8274610096520464e-09 + t * p
    p = -1.1080011346809263e-08 + t * p
    p = 3.2264564987978334e-08 + t * p
    p = 5.435050142444879e-08 + t * p
    p = -2.0437002727029336e-07 + t * p
    p = -4.0928108308012543e-07 + t * p
    p = 9.701828476691367e-07 + t * p
    p = 2.7621434201622248e-06 + t * p
    p = -4.731053693648649e-06 + t * p
    p = -1.7467570237306214e-05 + t * p
    p = 3.039074264262238e-05 + t * p
    p = 0.00010756025099266497 + t * p
    p = -0.00027677594206967926 + t * p
    p = -0.0005483094193117422 + t * p
    p = 0.0030340617140000455 + t * p
    p = -0.0012124166574628338 + t * p
    p = -0.02682723460248894 + t * p
    p = 0.11952776128845326 + t * p
    p = -0.31046726190113544 + t * p
    p = 0.5902283571041358 + t * p
    p = -0.883394453169885 + t * p
    series = 1.0740069070883378 + t * p
    y2 = y * y
    value = exp_scalar(max(-y2, -700.0)) * series * inv
    return value if y2 < 700.0 else 0.0


@njit(cache=True, inline="always")
def vndtr_upper(x: float) -> float:
    """Φ(−x) = 1 − Φ(x), vectorisable; absolute error < 1e-16, relative < 1e-13 for
    x < 37."""
    e = 0.5 * _verfc_pos(abs(x) * _INV_SQRT2)
    return e if x >= 0.0 else 1.0 - e


@njit(cache=True, inline="always")
def log_scalar(x: float) -> float:
    """log(x) for a normal float x > 0, vectorisable; relative error < 2e-16. x = 2^m · f
    with f ∈ [√2/2, √2) read from its bits (halved, m + 1, above √2), then 2 atanh(t) with
    t = (f − 1)/(f + 1), |t| ≤ 0.172, by its odd series to t^19 (truncation < 3e-17 relative;
    ten terms where the unreduced f ∈ [1, 2) of :func:`log1p_scalar` needs seventeen)."""
    bits = _float_as_int(x)
    m = np.float64((bits >> np.int64(52)) - np.int64(1023))
    f = _int_as_float((bits & _MANTISSA_BITS) | _ONE_BITS)
    above = f > _SQRT2
    f = 0.5 * f if above else f  # exact
    m = m + 1.0 if above else m
    t = (f - 1.0) / (f + 1.0)
    t2 = t * t
    p = 1.0 / 19.0
    p = 1.0 / 17.0 + t2 * p
    p = 1.0 / 15.0 + t2 * p
    p = 1.0 / 13.0 + t2 * p
    p = 1.0 / 11.0 + t2 * p
    p = 1.0 / 9.0 + t2 * p
    p = 1.0 / 7.0 + t2 * p
    p = 1.0 / 5.0 + t2 * p
    p = 1.0 / 3.0 + t2 * p
    p = 1.0 + t2 * p
    return m * _LN2_HI + (m * _LN2_LO + 2.0 * t * p)


@njit(cache=True, inline="always")
def vlog1m(y: float) -> float:
    """log(1 − y) for 0 ≤ y < 1 (1 − y a normal float), vectorisable; absolute error < 3e-16
    (a series below y = 1e-3, where 1 − y would round)."""
    series = -y * (1.0 + y * (0.5 + y * (1.0 / 3.0 + y * (0.25 + y * 0.2))))
    return series if y < 1e-3 else log_scalar(1.0 - y)


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def verfc(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = erfc(x[i]) for x ≥ 0 with the vectorisable series (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = _verfc_pos(x[i])


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def vlog(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = log(x[i]) for normal floats x > 0 with the vectorisable log (for tests)."""
    for i in range(x.shape[0]):
        out[i] = log_scalar(x[i])


# --- single precision (the planners' opt-in ``precision="single"``) ------------------------
# float32 arithmetic: twice the SIMD lanes of float64 and shorter polynomials for a relative
# error of a few 1e-7. Every literal is a float32 and every intermediate is cast back, because
# numba promotes float32 mixed with a Python float (or an int64) to float64.


_F32 = np.float32
EXP_F32_FLOOR = _F32(-87.0)
"""exp_f32 treats x below this as this (e^-87 ≈ 1.6e-38, the smallest normal float32's range)."""
LOG_F32_TINY = np.finfo(np.float32).tiny
"""Inputs of log_f32 below this, the smallest normal float32, are read as this."""
_LN2_HI_F32 = _F32(0.693359375)  # Cody-Waite split of ln 2 for float32 (Cephes)
_LN2_LO_F32 = _F32(-2.12194440e-4)
_INV_LN2_F32 = _F32(1.0 / math.log(2.0))
_LN2_F32 = _F32(math.log(2.0))
_SQRT2_F32 = _F32(math.sqrt(2.0))


@njit(cache=True, inline="always", fastmath={"contract"})
def exp_f32(x: np.float32) -> np.float32:
    """exp(x) for a float32 x ≤ 0, vectorisable, relative error < 3e-7 (x < −87: e^-87).
    2^−m · e^r with |r| ≤ ln 2 / 2 and Cephes' degree-7 minimax polynomial for e^r."""
    x = max(x, EXP_F32_FLOOR)
    m = _F32(math.floor(x * -_INV_LN2_F32 + _F32(0.5)))
    r = _F32(_F32(x + m * _LN2_HI_F32) + m * _LN2_LO_F32)
    p = _F32(1.9875691500e-4)
    p = _F32(_F32(1.3981999507e-3) + r * p)
    p = _F32(_F32(8.3334519073e-3) + r * p)
    p = _F32(_F32(4.1665795894e-2) + r * p)
    p = _F32(_F32(1.6666665459e-1) + r * p)
    p = _F32(_F32(5.0000001201e-1) + r * p)
    p = _F32(_F32(1.0) + r * _F32(_F32(1.0) + r * p))
    scale = _int32_as_float32(np.int32((np.int32(127) - np.int32(m)) << np.int32(23)))
    return _F32(p * scale)


@njit(cache=True, inline="always", fastmath={"contract"})
def log_f32(x: np.float32) -> np.float32:
    """log(x) for a float32 x > 0, vectorisable, absolute error < 2e-7 · max(1, |log x|)
    (x below :data:`LOG_F32_TINY` is read as it): x = 2^e · f, f ∈ [√2/2, √2), and
    2 atanh((f − 1)/(f + 1)) by its odd series to the 9th power."""
    bits = _float32_as_int32(max(x, LOG_F32_TINY))
    e = np.int32((bits >> np.int32(23)) - np.int32(127))
    f = _int32_as_float32(np.int32((bits & np.int32(0x007FFFFF)) | np.int32(0x3F800000)))
    above = f > _SQRT2_F32
    f = _F32(_F32(0.5) * f) if above else f
    e = np.int32(e + np.int32(1)) if above else e
    t = _F32(_F32(f - _F32(1.0)) / _F32(f + _F32(1.0)))
    t2 = _F32(t * t)
    p = _F32(1.0 / 9.0)
    p = _F32(_F32(1.0 / 7.0) + t2 * p)
    p = _F32(_F32(1.0 / 5.0) + t2 * p)
    p = _F32(_F32(1.0 / 3.0) + t2 * p)
    p = _F32(_F32(1.0) + t2 * p)
    return _F32(_F32(e) * _LN2_F32 + _F32(_F32(2.0) * t) * p)


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def vexp_f32(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = exp_f32(x[i]) for float32 arrays (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = exp_f32(x[i])


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def vlog_f32(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = log_f32(x[i]) for float32 arrays (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = log_f32(x[i])
