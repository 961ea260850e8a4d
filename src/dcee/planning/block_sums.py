"""Sums over one block of particles in a fixed order (numba), shared by the predicted-posterior
kernels: the order of additions depends neither on the thread count nor on the SIMD width."""

from __future__ import annotations

import numpy as np
from numba import njit

BLOCK = 512
"""Particles per work item; fixed, so the summation order never depends on threads."""


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def block_sum(buf: np.ndarray, n: int) -> float:
    """Σ buf[:n] for buf (BLOCK,) by pairwise halving (buf is overwritten). Every pass is an
    element-wise add that LLVM vectorises, and the order of additions is fixed (it does not
    depend on the vector width, as a reassociated loop's would); pairwise, so also accurate."""
    for q in range(n, BLOCK):
        buf[np.uint64(q)] = 0.0
    m = BLOCK
    while m > 1:
        m //= 2
        for q in range(m):
            buf[np.uint64(q)] += buf[np.uint64(q + m)]
    return buf[0]


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def product_sum(a: np.ndarray, b: np.ndarray, i0: int, n: int, buf: np.ndarray) -> float:
    """Σ_q a[q] · b[i0 + q] over q < n (see :func:`block_sum`; buf (BLOCK,) scratch)."""
    for q in range(n):
        buf[np.uint64(q)] = a[np.uint64(q)] * b[np.uint64(i0 + q)]
    return block_sum(buf, n)
