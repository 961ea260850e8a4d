"""Ground truth: what the sensor really sees. The estimator never reads it."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.plume import IsotropicPlume

if TYPE_CHECKING:
    from dcee.scenarios.config import Scenario


class TruthModel(ABC):
    """Ground-truth concentration field, possibly time-varying."""

    name: str = ""
    label: str = "truth"
    """what a figure's colour bar calls this field"""

    @abstractmethod
    def concentration(self, position: np.ndarray, time: float) -> float:
        """Concentration (g/m³) at ``position`` (3,) m at ``time`` s."""

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) concentrations at (K, 3) positions (for figures)."""
        return np.array([self.concentration(p, time) for p in positions])

    @property
    def time_step(self) -> float | None:
        """Seconds between changes of the field; None if it does not change in time."""
        return None

    def sensed(
        self, position: np.ndarray, time: float, average: float = 0.0, response_time: float = 0.0
    ) -> float:
        """What a sensor held at ``position`` reads at ``time`` s (g/m³, before sensor noise).

        The field is sampled at the truth's time step over the last ``average`` seconds
        (the samples end at ``time``), passed through a first-order response with time
        constant ``response_time`` s (its state starts at the window's first sample), and
        averaged. A field that does not change in time is read once: averaging changes nothing.
        """
        dt = self.time_step
        if dt is None or average <= 0.0:
            return self.concentration(position, time)
        n = max(1, round(average / dt))
        times = time - dt * np.arange(n - 1, -1, -1)
        times = times[times >= 0.0]
        c = np.array([self.concentration(position, float(t)) for t in times])
        if response_time > 0.0:
            alpha = 1.0 - math.exp(-dt / response_time)
            y = c[0]
            for k in range(len(c)):
                y += alpha * (c[k] - y)
                c[k] = y
        return float(c.mean())


class IsotropicTruth(TruthModel):
    """The paper's simulation truth: the same isotropic plume the estimator assumes."""

    name = "isotropic"
    label = "isotropic truth (mean field)"

    def __init__(self, theta: np.ndarray, plume: IsotropicPlume | None = None) -> None:
        self.theta = np.asarray(theta, dtype=np.float64).reshape(1, 8)
        self.plume = plume or IsotropicPlume()

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.plume.concentration(self.theta, np.reshape(position, (1, 3)))[0, 0])

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        return self.plume.concentration(self.theta, positions)[0]


class InjectedTruth(TruthModel):
    """Another truth with chosen concentrations injected at chosen times: fault injection (a
    spike, a stuck sensor) to test what one reading does to a search.

    ``injections`` maps a reading time (s) to the concentration (g/m³) sensed then."""

    def __init__(self, inner: TruthModel, injections: dict[float, float]) -> None:
        self.inner = inner
        self.injections = dict(injections)
        self.name, self.label = inner.name, inner.label

    def _injected(self, time: float) -> float | None:
        for t, value in self.injections.items():
            if abs(time - t) < 1e-9:
                return value
        return None

    def concentration(self, position: np.ndarray, time: float) -> float:
        value = self._injected(time)
        return self.inner.concentration(position, time) if value is None else value

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        return self.inner.field(positions, time)

    @property
    def time_step(self) -> float | None:
        return self.inner.time_step

    def sensed(
        self, position: np.ndarray, time: float, average: float = 0.0, response_time: float = 0.0
    ) -> float:
        value = self._injected(time)
        if value is None:
            return self.inner.sensed(position, time, average, response_time)
        return value


PLUME_STREAM = 3
"""Child of ``SeedSequence(seed)`` that drives a stochastic truth (the filament's puffs and
meander). Children 0-2 are the episode's sensor-noise, agent and figure streams
(:func:`dcee.simulation.episode.streams`), so the plume is independent of them and identical for
every strategy run with the same seed (common random numbers)."""


def plume_stream(seed: int) -> np.random.Generator:
    """The generator of a stochastic truth for episode ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(PLUME_STREAM,)))


TruthFactory = Callable[["Scenario", int], TruthModel]
TRUTH_KINDS: dict[str, TruthFactory] = {}
"""Truth models by the ``kind`` of the scenario's ``truth.model`` (``"isotropic"`` for the plain
string): each module registers its own factory ``(scenario, seed) -> TruthModel`` with
:func:`register_truth`, so adding a truth edits no dispatcher."""


def register_truth(kind: str) -> Callable[[TruthFactory], TruthFactory]:
    """Decorator: make ``factory(scenario, seed)`` build the truth of ``truth.model`` kind
    ``kind``."""

    def add(factory: TruthFactory) -> TruthFactory:
        if kind in TRUTH_KINDS and TRUTH_KINDS[kind] is not factory:
            raise ValueError(f"truth kind {kind!r} is already registered")
        TRUTH_KINDS[kind] = factory
        return factory

    return add


def truth_kind(spec: object) -> str:
    """The registry key of a ``truth.model`` value: the string itself or the table's kind."""
    return spec if isinstance(spec, str) else str(getattr(spec, "kind", ""))


def make_truth(scenario: Scenario, seed: int) -> TruthModel:
    """The scenario's ``truth.model`` for episode ``seed``, built by the factory registered for
    its kind (isotropic here; filament and playback in their modules)."""
    kind = truth_kind(scenario.truth.model)
    factory = TRUTH_KINDS.get(kind)
    if factory is None:
        raise DceeInputError(
            "truth.model", f"unknown truth kind {kind!r}; choose one of {', '.join(TRUTH_KINDS)}"
        )
    return factory(scenario, seed)


@register_truth("isotropic")
def _isotropic(scenario: Scenario, seed: int) -> TruthModel:
    return IsotropicTruth(scenario.truth_theta())
