"""Compiled (numba) plume kernels.

NumPy reference: :func:`dcee.models.plume.isotropic_concentration_reference`.

Kernels that loop over particles run in parallel (``prange``); every reduction is sequential
within one output element, so results do not depend on the thread count.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.numeric import exp_scalar, read_only_view

_FOUR_PI = 4.0 * math.pi


@njit(cache=True, inline="always")
def plume_terms(theta: np.ndarray, i: int):
    """Per-particle constants of the plume: the source location (x, y, z), then
    q/(4π ζ1), 1/λ, u cosφ/(2ζ1), u sinφ/(2ζ1), cos φ, sin φ and u/(2ζ1) — computed once,
    used at every position."""
    q = theta[i, 3]
    u = theta[i, 4]
    phi = theta[i, 5]
    z1 = theta[i, 6]
    z2 = theta[i, 7]
    lam = math.sqrt(z1 * z2 / (1.0 + u * u * z2 / (4.0 * z1)))
    c = math.cos(phi)
    s = math.sin(phi)
    k = u / (2.0 * z1)
    return (
        theta[i, 0],
        theta[i, 1],
        theta[i, 2],
        q / (_FOUR_PI * z1),
        1.0 / lam,
        k * c,
        k * s,
        c,
        s,
        k,
    )


@njit(cache=True, inline="always")
def _advected(dx, dy, dz, pref, inv_lam, ax, ay, c, s, k, rmin, meander, decay, meander_z):
    """The advected plume at offset (dx, dy, dz) from the source, wind terms (ax, ay, c, s, k)
    as :func:`plume_terms` gives them (negated: the plume of the reversed wind)."""
    factor = 1.0
    if meander > 0.0 or meander_z > 0.0:
        down = -(dx * c + dy * s)  # distance downwind of the source
        if down > 0.0:
            if meander > 0.0:
                factor = 1.0 / math.sqrt(1.0 + meander * meander * down * k)
                cross = (factor - 1.0) * (-dx * s + dy * c)  # compress the crosswind offset
                dx -= cross * s
                dy += cross * c
            if meander_z > 0.0:
                # the same broadening in the vertical, at its own intensity
                factor_z = 1.0 / math.sqrt(1.0 + meander_z * meander_z * down * k)
                dz *= factor_z
                factor *= factor_z
    r = math.sqrt(dx * dx + dy * dy + dz * dz)
    if r < rmin:
        r = rmin
    spread = r if decay == 1.0 else r**decay
    return factor * pref / spread * math.exp(-r * inv_lam - dx * ax - dy * ay)


@njit(cache=True, inline="always")
def _mixed(dx, dy, dz, pref, inv_lam, ax, ay, c, s, k, rmin, meander, decay, backflow, mz):
    """The point source's plume at offset (dx, dy, dz), with ``backflow`` w mixed in (``mz``:
    the vertical meander)."""
    # one inlined copy of _advected in a loop over the two winds, not two copies: the nested
    # inlining of plume_at's helpers (images × sub-sources × winds) made twelve copies in every
    # kernel that inlines plume_at, and compiling the kernels every search uses took 125-137 s
    # on a fresh machine; with one copy here and below (and plume_at's straight path) 45 s, the
    # same bits for all 128 combinations of the options (2026-12-05). The loops cost the
    # options' own cases their vectorisation (backflow, a disc, a ground: 1.2-1.6 times slower
    # alone; a default filament search's filter updates 3-5 % slower, its decisions not)
    value = 0.0
    reverse = 0.0
    for wind in range(2 if backflow > 0.0 else 1):
        sign = 1.0 if wind == 0 else -1.0  # the reversed wind: its terms negated, exactly
        v = _advected(
            dx, dy, dz, pref, inv_lam, sign * ax, sign * ay, sign * c, sign * s, k, rmin,
            meander, decay, mz,
        )  # fmt: skip
        if wind == 0:
            value = v
        else:
            reverse = v
    if backflow > 0.0:
        value = (1.0 - backflow) * value + backflow * reverse
    return value


DISC_RING = math.sqrt(2.0 / 3.0)
"""Ring radius of the disc rule, in disc radii: the centre weighs 1/4 and six points on this
ring 1/8 each, which matches the uniform disc's mean square offset R²/2."""


_RING_COS = tuple(math.cos(j * math.pi / 3.0) for j in range(6))
_RING_SIN = tuple(math.sin(j * math.pi / 3.0) for j in range(6))
"""cos and sin of the disc rule's ring angles, j · 60° (computed once, not per evaluation)."""


@njit(cache=True, inline="always")
def _point_or_disc(
    dx, dy, dz, pref, inv_lam, ax, ay, c, s, k, rmin, meander, decay, backflow, radius, mz
):
    """The plume at offset (dx, dy, dz) from the source location of a point release
    (``radius`` 0) or of one spread over a horizontal disc (:data:`DISC_RING`)."""
    # the point, or the disc's centre and six ring points, through one inlined copy of _mixed
    disc = radius > 0.0
    ring = radius * DISC_RING
    # a sub-source's distance clamped at half the spacing of the rule's points
    rsub = max(rmin, 0.5 * ring) if disc else rmin
    value = 0.0
    for j in range(7 if disc else 1):
        ox = 0.0
        oy = 0.0
        weight = (0.25 if disc else 1.0) if j == 0 else 0.125
        if j > 0:
            # one ring point straight upwind (c, s), the others every 60°
            cj = _RING_COS[j - 1]
            sj = _RING_SIN[j - 1]
            ox = ring * (c * cj - s * sj)
            oy = ring * (s * cj + c * sj)
        term = _mixed(
            dx - ox, dy - oy, dz, pref, inv_lam, ax, ay, c, s, k, rsub, meander, decay, backflow,
            mz,
        )  # fmt: skip
        value = weight * term if j == 0 else value + weight * term
    return value


@njit(cache=True, inline="always")
def plume_at(
    terms,
    px: float,
    py: float,
    pz: float,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
):
    """(concentration, clamped distance r) at (px, py, pz) from one particle's
    :func:`plume_terms`; see :mod:`dcee.models.plume` for ``meander``, ``decay``, ``backflow``
    (w: (1 − w) · the plume + w · the plume of the reversed wind), ``radius`` (the release
    spread over a horizontal disc: seven sub-sources, :data:`DISC_RING`), ``vertical`` (the
    ratio a of the vertical to the horizontal spread: heights divided by a, the release rate
    too), ``ground`` (the weight of the release's image below the ground z = 0) and
    ``meander_z`` (the meander's vertical intensity). r is the distance to the source location
    (the disc's centre)."""
    sx, sy, sz, pref, inv_lam, ax, ay, c, s, k = terms
    dx = px - sx
    dy = py - sy
    dz = pz - sz
    r0 = math.sqrt(dx * dx + dy * dy + dz * dz)
    if r0 < rmin:
        r0 = rmin
    if vertical == 1.0 and ground == 0.0 and radius <= 0.0 and backflow <= 0.0:
        # the common case in straight-line code: a loop over particles that inlines it stays
        # vectorisable (the loops below kept the paper's plume 1.6 times slower, measured)
        return _advected(
            dx, dy, dz, pref, inv_lam, ax, ay, c, s, k, rmin, meander, decay, meander_z
        ), r0  # fmt: skip
    # the release and, with a ground, its image below it, through one inlined copy of
    # _point_or_disc (heights and the rate divided by a: with a = 1 the same bits as undivided)
    scaled = vertical != 1.0
    inv_a = 1.0 / vertical if scaled else 1.0
    pref_a = pref * inv_a if scaled else pref
    value = 0.0
    for image in range(2 if ground > 0.0 else 1):
        height = dz if image == 0 else pz + sz
        term = _point_or_disc(
            dx, dy, height * inv_a if scaled else height, pref_a, inv_lam, ax, ay, c, s, k, rmin,
            meander, decay, backflow, radius, meander_z,
        )  # fmt: skip
        value = term if image == 0 else value + ground * term
    return value, r0


@njit(cache=True, inline="always")
def constants_at(pc: np.ndarray, i: int):
    """Particle i's :func:`plume_terms` from the (10, N) array of them that planners and the
    filter keep per particle set."""
    return (
        pc[0, i],
        pc[1, i],
        pc[2, i],
        pc[3, i],
        pc[4, i],
        pc[5, i],
        pc[6, i],
        pc[7, i],
        pc[8, i],
        pc[9, i],
    )


@njit(cache=True, inline="always")
def plume_from_terms(
    x0: float,
    y0: float,
    z0: float,
    pref: float,
    inv_lam: float,
    ax: float,
    ay: float,
    px: float,
    py: float,
    pz: float,
    rmin: float,
):
    """(concentration, clamped distance r) at (px, py, pz) of a particle with the first seven
    :func:`plume_terms` (x0, y0, z0, q/(4π ζ1), 1/λ, u cosφ/(2ζ1), u sinφ/(2ζ1)), without
    meander and with decay 1. Branch-free (selects only) with the vectorisable exp; equals
    :func:`plume_at` with meander 0 and decay 1 to rounding (0 below e^−700).

    It takes scalars, not the (10, N) constants array and an index: an array-and-index helper,
    even inlined, could keep LLVM from vectorising the caller's loop over particles (the
    filter's block plume, compiled on its own: 11.6 against 1.9 ns per particle, 2026-11-22)."""
    dx = px - x0
    dy = py - y0
    dz = pz - z0
    r = max(math.sqrt(dx * dx + dy * dy + dz * dz), rmin)
    # the exponent is ≤ 0 (1/λ ≥ u/(2ζ1)); min() guards against rounding
    arg = min(-r * inv_lam - dx * ax - dy * ay, 0.0)
    value = pref / r * exp_scalar(arg)
    return (value if arg > -700.0 else 0.0), r


@njit(cache=True, parallel=True)
def concentration_distance_grid(
    theta: np.ndarray,
    positions: np.ndarray,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
    conc: np.ndarray,
    dist: np.ndarray,
):
    """conc[m, i] = C(positions[m]; theta[i]) and dist[m, i] the clamped source distance r."""
    n = theta.shape[0]
    m_count = positions.shape[0]
    for i in prange(n):
        terms = plume_terms(theta, i)
        for m in range(m_count):
            c, r = plume_at(
                terms,
                positions[m, 0],
                positions[m, 1],
                positions[m, 2],
                rmin,
                meander,
                decay,
                backflow,
                radius,
                vertical,
                ground,
                meander_z,
            )
            conc[m, i] = c
            dist[m, i] = r


def concentration_matrix(
    theta: np.ndarray,
    positions: np.ndarray,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
    out: np.ndarray,
):
    """out[i, m] = C(positions[m]; theta[i]); out (N, M) C-contiguous."""
    tmp = np.empty((positions.shape[0], theta.shape[0]))
    dist = np.empty_like(tmp)
    concentration_distance_grid(
        read_only_view(theta), read_only_view(positions), rmin, meander, decay, backflow,
        radius, vertical, ground, meander_z, tmp, dist,
    )  # fmt: skip
    out[...] = tmp.T


@njit(cache=True, nogil=True)
def gather_receptor_fields(
    bank: np.ndarray, rows: np.ndarray, cells: np.ndarray, weights: np.ndarray, out: np.ndarray
) -> None:
    """The wall-aware plume's predictions (:class:`dcee.models.site_plume.SitePlume`):
    ``out[n, k] = Σ_c weights[n, c] · bank[rows[k], cells[n, c]]`` for (N, 4) cells and bilinear
    weights of N particles and K receptor-field rows of ``bank`` (float32). One field at a time
    (it stays in cache while every particle reads it); the four terms summed as NumPy's einsum
    pairs them, (0 + 2) + (1 + 3), so the kernel equals its reference
    (:func:`dcee.models.site_plume.gather_receptor_fields_reference`) exactly."""
    for k in range(rows.shape[0]):
        field = bank[rows[k]]
        for n in range(cells.shape[0]):
            a0 = weights[n, 0] * np.float64(field[cells[n, 0]])
            a1 = weights[n, 1] * np.float64(field[cells[n, 1]])
            a2 = weights[n, 2] * np.float64(field[cells[n, 2]])
            a3 = weights[n, 3] * np.float64(field[cells[n, 3]])
            out[n, k] = (a0 + a2) + (a1 + a3)
