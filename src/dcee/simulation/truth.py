"""Ground truth: what the sensor really sees. The estimator never reads it."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.plume import IsotropicPlume
from dcee.scenarios.schema.truth_models import TRUTH_KINDS

if TYPE_CHECKING:
    from dcee.scenarios import Scenario


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

    def reported(self, reading: float, true: float, time: float) -> float:
        """What the instrument reports given its simulated ``reading`` (g/m³) of the ``true``
        sensed concentration at ``time`` s: the reading itself, except where a fault is
        injected (:class:`InjectedTruth`)."""
        return reading

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
        """theta: (8,) the source term, or (K, 8) for K releases (their fields add: the
        advection-diffusion equation is linear in its sources)."""
        self.theta = np.asarray(theta, dtype=np.float64).reshape(-1, 8)
        self.plume = plume or IsotropicPlume()

    def concentration(self, position: np.ndarray, time: float) -> float:
        c = self.plume.concentration(self.theta, np.reshape(position, (1, 3)))
        return float(c[0, 0] if len(c) == 1 else c[:, 0].sum())

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        c = self.plume.concentration(self.theta, positions)
        return c[0] if len(c) == 1 else c.sum(axis=0)


CHECKPOINT_SECONDS = 10.0
"""simulated seconds between stored states of a :class:`SteppedTruth` (for looking back)"""


class SteppedTruth(TruthModel):
    """A stochastic field advanced in fixed steps of ``dt`` s from ``-spin_steps · dt`` (so the
    field at time 0 no longer depends on the empty start), piecewise constant over a step.

    A subclass keeps its whole state in ``self._state`` (an object with ``copy()``) and implements
    :meth:`_advance_one` (one step of its dynamics, drawing from ``self._rng``). The field can be
    asked for at any time, in any order: a state and the generator's state are stored every
    :data:`CHECKPOINT_SECONDS`, so looking back (figures) restarts from the last one before it
    and replays the same draws.
    """

    dt: float
    spin_steps: int
    step_count: int
    """the current state is the one after this many steps from ``-spin_steps · dt``"""

    def _start_stepping(self, dt: float, spin_steps: int, rng: np.random.Generator) -> None:
        """Call at the end of ``__init__``, once the state at step 0 exists: spins up."""
        self.dt, self.spin_steps, self._rng = dt, spin_steps, rng
        self.step_count = 0
        self._checkpoint_steps = max(1, round(CHECKPOINT_SECONDS / dt))
        self._checkpoints: dict[int, tuple[object, dict]] = {}
        self._advance_to(spin_steps)

    @abstractmethod
    def _advance_one(self) -> None:
        """One step of the dynamics (``self.step_count`` is already the new step)."""

    def _save(self) -> object:
        """A copy of the state: ``self._state.copy()`` (a subclass keeps its state there)."""
        return self._state.copy()  # type: ignore[attr-defined]

    def _restore(self, saved: object) -> None:
        """Make a saved copy the current state (copied again: the checkpoint stays unchanged)."""
        self._state = saved.copy()  # type: ignore[attr-defined]

    def _advance_to(self, step: int) -> None:
        if step < self.step_count:  # looking back: restart from the last checkpoint before it
            at = max(k for k in self._checkpoints if k <= step)
            saved, rng_state = self._checkpoints[at]
            self._restore(saved)
            self.step_count = at
            self._rng.bit_generator.state = rng_state
        while self.step_count < step:
            self.step_count += 1
            self._advance_one()
            k = self.step_count - self.spin_steps
            if k >= 0 and k % self._checkpoint_steps == 0:
                self._checkpoints[self.step_count] = (self._save(), self._rng.bit_generator.state)

    def _step_for(self, time: float) -> int:
        """The step whose state is the field at episode ``time`` s (rounded to a step)."""
        if not math.isfinite(time) or time < 0:
            raise ValueError(f"time must be a finite number of seconds >= 0 (got {time})")
        return self.spin_steps + round(time / self.dt)

    @property
    def time_step(self) -> float:
        return self.dt


Injection = float | Callable[[float], float]
"""What an :class:`InjectedTruth` reports instead of the instrument: a reading (g/m³), or a
function of the true sensed concentration (g/m³) returning one (``lambda c: 1e6 * c``)."""


class InjectedTruth(TruthModel):
    """Another truth whose instrument reports chosen readings at chosen times: fault injection
    (a spike, a stuck sensor) to test what one reading does to a search.

    ``injections`` maps a time (s) to an :data:`Injection`. Each fires once, at the first reading
    taken at or after its time (reading times depend on the motion model, so an exact time would
    miss), and replaces what the instrument reports, after its noise and dropout, so the injected
    value is exactly what the estimator is told. Every other reading, and the field itself, is
    the inner truth's."""

    def __init__(self, inner: TruthModel, injections: dict[float, Injection]) -> None:
        self.inner = inner
        self.pending = sorted(injections.items())
        self.fired: list[tuple[float, float, float]] = []
        """(reading time s, true concentration g/m³, reported g/m³) of each injection so far"""
        self.name, self.label = inner.name, inner.label

    def concentration(self, position: np.ndarray, time: float) -> float:
        return self.inner.concentration(position, time)

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        return self.inner.field(positions, time)

    @property
    def time_step(self) -> float | None:
        return self.inner.time_step

    def sensed(
        self, position: np.ndarray, time: float, average: float = 0.0, response_time: float = 0.0
    ) -> float:
        return self.inner.sensed(position, time, average, response_time)

    def reported(self, reading: float, true: float, time: float) -> float:
        if not self.pending or time < self.pending[0][0] - 1e-9:
            return reading
        _, injection = self.pending.pop(0)
        value = float(injection(true) if callable(injection) else injection)
        self.fired.append((time, true, value))
        return value


PLUME_STREAM = 3
"""Child of ``SeedSequence(seed)`` that drives a stochastic truth (the filament's puffs and
meander). Children 0-2 are the episode's sensor-noise, agent and figure streams
(:func:`dcee.runs.streams`), so the plume is independent of them and identical for
every strategy run with the same seed (common random numbers)."""


def plume_stream(seed: int) -> np.random.Generator:
    """The generator of a stochastic truth for episode ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(PLUME_STREAM,)))


TruthFactory = Callable[["Scenario", int], TruthModel]


def register_truth(kind: str) -> Callable[[TruthFactory], TruthFactory]:
    """Decorator: make ``factory(scenario, seed)`` build the truth of ``truth.model`` kind
    ``kind``, an entry of the one registry of truth kinds
    (:data:`dcee.scenarios.schema.truth.TRUTH_KINDS`, which holds its parameter table)."""

    def add(factory: TruthFactory) -> TruthFactory:
        entry = TRUTH_KINDS.get(kind)
        if entry is None:
            raise ValueError(f"truth kind {kind!r} has no parameter spec in TRUTH_KINDS")
        if entry.build is not None and entry.build is not factory:
            raise ValueError(f"truth kind {kind!r} is already registered")
        entry.build = factory
        return factory

    return add


def truth_kind(spec: object) -> str:
    """The registry key of a ``truth.model`` value: the string itself or the table's kind."""
    return spec if isinstance(spec, str) else str(getattr(spec, "kind", ""))


def make_truth(scenario: Scenario, seed: int) -> TruthModel:
    """The scenario's ``truth.model`` for episode ``seed``, built by the factory registered for
    its kind (isotropic here; filament and playback in their modules). Every factory builds all
    the releases of ``truth.extra_sources`` into one truth (:meth:`Scenario.truth_thetas`);
    the recordings refuse them at validation."""
    kind = truth_kind(scenario.truth.model)
    entry = TRUTH_KINDS.get(kind)
    factory = entry.build if entry is not None else None
    if factory is None:
        raise DceeInputError(
            "truth.model", f"unknown truth kind {kind!r}; choose one of {', '.join(TRUTH_KINDS)}"
        )
    return factory(scenario, seed)


@register_truth("isotropic")
def _isotropic(scenario: Scenario, seed: int) -> TruthModel:
    return IsotropicTruth(scenario.truth_thetas())
