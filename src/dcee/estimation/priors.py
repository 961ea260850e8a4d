"""Priors over the source term Θ = (x, y, z, q, u, φ, ζ1, ζ2).

Each parameter has one distribution; :class:`Fixed` marks a known parameter. The physical
constraints q > 0, u ≥ 0, ζ1 > 0, ζ2 > 0 are enforced on top of any distribution, so a proposal that
breaks them has zero prior density whatever the configured prior says.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import gammaln, ndtr, ndtri

from dcee.errors import DceeInputError
from dcee.models.plume import PARAMETER_NAMES

# (lower bound, strict) of each parameter's physical support.
PHYSICAL_LOWER: dict[str, tuple[float, bool]] = {
    "q": (0.0, True),
    "u": (0.0, False),
    "zeta1": (0.0, True),
    "zeta2": (0.0, True),
}


@dataclass(frozen=True)
class Fixed:
    """A known parameter."""

    value: float

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return np.full(n, self.value)

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        return np.zeros_like(x)

    @property
    def scale(self) -> float:
        return 0.0


@dataclass(frozen=True)
class Uniform:
    low: float
    high: float

    def __post_init__(self) -> None:
        if not self.high > self.low:
            raise DceeInputError(
                "prior.uniform", f"needs high > low, got [{self.low}, {self.high}]"
            )

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return self.low + (self.high - self.low) * rng.random(n)

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        inside = (x >= self.low) & (x <= self.high)
        return np.where(inside, -math.log(self.high - self.low), -np.inf)

    @property
    def scale(self) -> float:
        return (self.high - self.low) / math.sqrt(12.0)


@dataclass(frozen=True)
class Gamma:
    """Gamma(shape k, scale θ): mean kθ."""

    shape: float
    scale_param: float

    def __post_init__(self) -> None:
        if not (self.shape > 0 and self.scale_param > 0):
            raise DceeInputError("prior.gamma", "needs shape > 0 and scale > 0")

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.gamma(self.shape, self.scale_param, n)

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        k, s = self.shape, self.scale_param
        with np.errstate(divide="ignore", invalid="ignore"):
            val = (k - 1) * np.log(x) - x / s - gammaln(k) - k * math.log(s)
        return np.where(x > 0, val, -np.inf)

    @property
    def scale(self) -> float:
        return math.sqrt(self.shape) * self.scale_param


@dataclass(frozen=True)
class Normal:
    """Normal(mean, sd) truncated to [low, high] (either may be infinite)."""

    mean: float
    sd: float
    low: float = -math.inf
    high: float = math.inf

    def __post_init__(self) -> None:
        if not self.sd > 0:
            raise DceeInputError("prior.normal", f"needs sd > 0, got {self.sd}")
        if not self.high > self.low:
            raise DceeInputError("prior.normal", f"needs high > low, got [{self.low}, {self.high}]")

    def _cdf_bounds(self) -> tuple[float, float]:
        a = float(ndtr((self.low - self.mean) / self.sd))
        b = float(ndtr((self.high - self.mean) / self.sd))
        return a, b

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        # Inverse-CDF sampling on the truncated range: exact and one uniform per draw.
        a, b = self._cdf_bounds()
        if not b > a:
            raise DceeInputError("prior.normal", "truncation leaves no probability mass")
        u = a + (b - a) * rng.random(n)
        x = self.mean + self.sd * ndtri(np.clip(u, 1e-300, 1 - 1e-16))
        return np.clip(x, self.low, self.high)

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        a, b = self._cdf_bounds()
        val = -0.5 * ((x - self.mean) / self.sd) ** 2 - math.log(self.sd * math.sqrt(2 * math.pi))
        val = val - math.log(b - a)
        return np.where((x >= self.low) & (x <= self.high), val, -np.inf)

    @property
    def scale(self) -> float:
        return self.sd


Distribution = Fixed | Uniform | Gamma | Normal


@dataclass(frozen=True)
class SourcePrior:
    """Independent prior per parameter, in :data:`PARAMETER_NAMES` order."""

    distributions: tuple[Distribution, ...]

    def __post_init__(self) -> None:
        if len(self.distributions) != len(PARAMETER_NAMES):
            raise DceeInputError("prior", f"needs {len(PARAMETER_NAMES)} distributions")
        if not self.unknown:
            raise DceeInputError("prior", "at least one parameter must be unknown")
        _check_radians(self.distributions[PARAMETER_NAMES.index("phi")])

    @classmethod
    def from_dict(cls, dists: dict[str, Distribution]) -> SourcePrior:
        missing = [n for n in PARAMETER_NAMES if n not in dists]
        if missing:
            raise DceeInputError("prior", f"missing parameters {missing}")
        return cls(tuple(dists[n] for n in PARAMETER_NAMES))

    @property
    def unknown(self) -> tuple[int, ...]:
        """Column indices of the unknown (non-fixed) parameters."""
        return tuple(i for i, d in enumerate(self.distributions) if not isinstance(d, Fixed))

    @property
    def unknown_names(self) -> tuple[str, ...]:
        return tuple(PARAMETER_NAMES[i] for i in self.unknown)

    @property
    def scales(self) -> np.ndarray:
        """(D,) prior spread (sd) of each unknown parameter."""
        return np.array([self.distributions[i].scale for i in self.unknown])

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """(n, 8) draws; physical constraints enforced by rejection (rarely needed)."""
        out = np.column_stack([d.sample(rng, n) for d in self.distributions])
        for _ in range(100):
            bad = ~np.isfinite(self.log_density(out))
            if not bad.any():
                return out
            k = int(bad.sum())
            out[bad] = np.column_stack([d.sample(rng, k) for d in self.distributions])
        culprits = []
        for i in self.unknown:
            name = PARAMETER_NAMES[i]
            col = self.distributions[i].sample(rng, 1000)
            low, strict = PHYSICAL_LOWER.get(name, (-np.inf, False))
            valid = np.isfinite(self.distributions[i].log_pdf(col)) & (
                col > low if strict else col >= low
            )
            if valid.mean() < 0.5:
                culprits.append(f"{name}: {1 - valid.mean():.0%} of its draws are invalid")
        why = "; ".join(culprits) or "the parameters' draws are rarely valid together"
        raise DceeInputError(
            "prior", f"puts (almost) no mass on physically valid parameters ({why})"
        )

    def log_density(self, theta: np.ndarray) -> np.ndarray:
        """(N,) log prior density over the unknown columns; −inf outside the support."""
        total = np.zeros(theta.shape[0])
        for i in self.unknown:
            total += self.distributions[i].log_pdf(theta[:, i])
        for name, (low, strict) in PHYSICAL_LOWER.items():
            col = theta[:, PARAMETER_NAMES.index(name)]
            bad = col <= low if strict else col < low
            total[bad] = -np.inf
        return total


def _check_radians(phi: Distribution) -> None:
    """The wind direction is in radians here (degrees only in scenario files and on the command
    line): a value beyond ±2π is almost surely degrees, so it is refused with a hint."""
    values = {
        "value": getattr(phi, "value", None),
        "low": getattr(phi, "low", None),
        "high": getattr(phi, "high", None),
        "mean": getattr(phi, "mean", None),
        "sd": getattr(phi, "sd", None),
    }
    for key, v in values.items():
        if v is not None and math.isfinite(v) and abs(v) > 2 * math.pi + 1e-9:
            raise DceeInputError(
                f"prior.phi.{key}",
                f"the Python API takes the wind direction in radians (|phi| <= 2π), got {v:g}; "
                f"degrees? use math.radians({v:g})",
            )
