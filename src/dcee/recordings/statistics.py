"""Plume statistics of a recording in its plume frame, and the published figures they are
checked against (docs/scenarios.md, ``tests/test_lbm.py``, ``studies/lbm_statistics.py``).

A recording here is a planar field ``c`` (T, ny, nx) with the source at the origin and the mean
wind along +x (the solver plume's canonical frame). At each distance ``x`` downwind:

* ``sigma_y``: the crosswind standard deviation of the time-mean profile, m;
* ``flux``: ∫ C̄ dy (m · g/m³), the mean scalar flux per unit wind speed through the section
  (turbulent transport u'c' aside), which a conserved scalar keeps with distance;
* ``intensity``: σ_c / C̄ on the centreline (the fluctuation intensity);
* ``intermittency``: the share of frames in which the centreline concentration exceeds a tenth
  of its time mean (the intermittency factor, with a threshold relative to the local mean so
  that it reads the same at every distance);
* ``gamma_ratio``: skewness / (2 · intensity) of the centreline concentration: 1 for a gamma
  distribution, the distribution that fits measured plume concentrations at every position
  (Pang, Talluru & Chauhan 2026; Yee & Chan 1997).

Published figures used as references:

* **Spread (Briggs 1973, open country, as tabulated by Hanna, Briggs & Hosker 1982)**:
  σ_y = a · x · (1 + 0.0001 x)^(−1/2) with a = 0.22 (class A, very unstable), 0.16 (B), 0.11 (C),
  0.08 (D, neutral). :data:`BRIGGS_SIGMA_Y` holds the coefficients.
* **Taylor (1921)**: near the source σ_y ≈ (σ_v / U) · x, the turbulence intensity at the
  source times the distance.
* **Vertical spread (Briggs 1973, open country)**: σ_z = b · x · (1 + c x)^(−1/2) with
  (b, c) = (0.20, 0) (class A), (0.12, 0) (B), (0.08, 0.0002) (C), (0.06, 0.0015) (D).
  Briggs fitted both curves beyond about 100 m: at the tens of metres of a search they are an
  extrapolation, a comparison of order of magnitude rather than a test.
* **Fluctuation intensity and intermittency along the centreline** (Fackrell & Robins 1982
  in a wind tunnel; Mylne & Mason 1991 at 50-1000 m in the field; Yee et al. 1993): the
  intensity is largest near the source and falls quickly with distance; the intermittency
  factor rises towards 1 downwind as the plume outgrows its meander.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BRIGGS_SIGMA_Y = {"A": 0.22, "B": 0.16, "C": 0.11, "D": 0.08}
"""Briggs' open-country σ_y coefficients a (σ_y = a x (1 + 0.0001 x)^(−1/2), x in m)."""
BRIGGS_SIGMA_Z = {"A": (0.20, 0.0), "B": (0.12, 0.0), "C": (0.08, 0.0002), "D": (0.06, 0.0015)}
"""Briggs' open-country σ_z coefficients (b, c) (σ_z = b x (1 + c x)^(−1/2), x in m)."""


def briggs_sigma_z(x: np.ndarray | float, stability: str) -> np.ndarray:
    """Briggs' open-country vertical spread σ_z (m) at ``x`` m downwind for a Pasquill class."""
    b, c = BRIGGS_SIGMA_Z[stability]
    x = np.asarray(x, dtype=np.float64)
    return b * x / np.sqrt(1.0 + c * x)


def briggs_sigma_y(x: np.ndarray | float, stability: str) -> np.ndarray:
    """Briggs' open-country crosswind spread σ_y (m) at ``x`` m downwind for a Pasquill class."""
    x = np.asarray(x, dtype=np.float64)
    return BRIGGS_SIGMA_Y[stability] * x / np.sqrt(1.0 + 1e-4 * x)


@dataclass(frozen=True)
class SectionStatistics:
    """Statistics of one cross-section (module doc), at ``x`` m downwind."""

    x: float
    sigma_y: float
    flux: float
    centre_mean: float
    intensity: float
    intermittency: float
    gamma_ratio: float


def section_statistics(
    c: np.ndarray, x: np.ndarray, y: np.ndarray, distances: list[float] | np.ndarray
) -> list[SectionStatistics]:
    """Statistics at each of ``distances`` (m downwind, nearest grid column) of a planar
    recording ``c`` (T, ny, nx) with axes ``x`` (nx,) and ``y`` (ny,), source at the origin."""
    c = np.asarray(c, dtype=np.float64)
    if c.ndim != 3 or c.shape[1:] != (len(y), len(x)):
        raise ValueError(f"c must be (T, {len(y)}, {len(x)}); got {c.shape}")
    dy = float(np.mean(np.diff(y)))
    mean = c.mean(axis=0)
    out = []
    for distance in distances:
        i = int(np.argmin(np.abs(x - distance)))
        profile = mean[:, i]
        total = float(profile.sum())
        centre = float(np.sum(profile * y) / total) if total > 0 else 0.0
        spread = float(np.sqrt(np.sum(profile * (y - centre) ** 2) / total)) if total > 0 else 0.0
        j = int(np.argmin(np.abs(y)))
        series = c[:, j, i]
        m = float(series.mean())
        sd = float(series.std())
        intensity = sd / m if m > 0 else float("nan")
        skew = float(np.mean((series - m) ** 3) / sd**3) if sd > 0 else float("nan")
        out.append(
            SectionStatistics(
                x=float(x[i]),
                sigma_y=spread,
                flux=total * dy,
                centre_mean=m,
                intensity=intensity,
                intermittency=float(np.mean(series > 0.1 * m)) if m > 0 else 0.0,
                gamma_ratio=skew / (2.0 * intensity) if intensity > 0 else float("nan"),
            )
        )
    return out


@dataclass(frozen=True)
class Section3dStatistics:
    """Statistics of one cross-section of a 3-D recording, at ``x`` m downwind: the spreads
    and the centroid height of the time-mean section (m), the flux ∬ C̄ dy dz (m² · g/m³, 1/U
    of the release for a conserved scalar), and at the section's centroid the fluctuation
    intensity and the intermittency factor (module doc)."""

    x: float
    sigma_y: float
    sigma_z: float
    centroid_z: float
    flux: float
    intensity: float
    intermittency: float


def section_statistics_3d(
    c: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    distances: list[float] | np.ndarray,
) -> list[Section3dStatistics]:
    """Statistics at each of ``distances`` (m downwind, nearest grid column) of a 3-D
    recording ``c`` (T, ny, nx, nz) with axes ``x``, ``y``, ``z`` (m above the ground), source
    at x = y = 0. The spreads are the standard deviations of the time-mean section about its
    centroid. Briggs' σ_z is a Gaussian's about the release height, with the ground reflecting
    it: near a release at the ground the spread about the centroid reads about 0.6 of it."""
    c = np.asarray(c)
    if c.ndim != 4 or c.shape[1:] != (len(y), len(x), len(z)):
        raise ValueError(f"c must be (T, {len(y)}, {len(x)}, {len(z)}); got {c.shape}")
    dy, dz = float(np.mean(np.diff(y))), float(np.mean(np.diff(z)))
    out = []
    for distance in distances:
        i = int(np.argmin(np.abs(x - distance)))
        series_all = np.asarray(c[:, :, i, :], dtype=np.float64)  # (T, ny, nz)
        section = series_all.mean(axis=0)
        total = float(section.sum())
        if not total > 0:
            continue
        py, pz = section.sum(axis=1) / total, section.sum(axis=0) / total
        yc, zc = float(np.sum(py * y)), float(np.sum(pz * z))
        sy = float(np.sqrt(np.sum(py * (y - yc) ** 2)))
        sz = float(np.sqrt(np.sum(pz * (z - zc) ** 2)))
        j, k = int(np.argmin(np.abs(y - yc))), int(np.argmin(np.abs(z - zc)))
        series = series_all[:, j, k]
        m = float(series.mean())
        out.append(
            Section3dStatistics(
                x=float(x[i]),
                sigma_y=sy,
                sigma_z=sz,
                centroid_z=zc,
                flux=total * dy * dz,
                intensity=float(series.std()) / m if m > 0 else float("nan"),
                intermittency=float(np.mean(series > 0.1 * m)) if m > 0 else 0.0,
            )
        )
    return out


__all__ = [
    "BRIGGS_SIGMA_Y",
    "BRIGGS_SIGMA_Z",
    "Section3dStatistics",
    "SectionStatistics",
    "briggs_sigma_y",
    "briggs_sigma_z",
    "section_statistics",
    "section_statistics_3d",
]
