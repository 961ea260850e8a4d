"""A timed workload's result (:class:`Timing`: samples, unit, target, pass/fail) and the timer
(:func:`times_ms`: repeated calls in one process, optional untimed setup before each)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Timing:
    """One workload's repeated measurements (milliseconds, or MB for memory workloads)."""

    name: str
    description: str
    target: float | None
    values: list[float] = field(default_factory=list)
    unit: str = "ms"
    note: str = ""
    ratio_to: dict[str, float] = field(default_factory=dict)
    """Median of this workload over the median of each named reference timed in the same run
    (``floor``: the plain compiled loop, ``numpy``: the NumPy reference, ``filter-update``,
    ``full-import``)."""
    ratio_target: tuple[str, float] | None = None
    """(reference, bound): the target as a ratio, ratio_to[reference] ≤ bound. On this shared
    machine absolute times swing 3-5× between days, so a workload with a reference timed in the
    same run is judged by the ratio; ``target`` then stays None."""

    @property
    def median(self) -> float:
        return float(np.median(self.values)) if self.values else math.nan

    @property
    def passed(self) -> bool | None:
        """True/False against the target (the ratio target if there is one); None when the
        workload has no target."""
        if not self.values:
            return None
        if self.ratio_target is not None:
            reference, bound = self.ratio_target
            ratio = self.ratio_to.get(reference)
            return None if ratio is None else ratio <= bound
        if self.target is None:
            return None
        return self.median <= self.target

    @property
    def target_text(self) -> str:
        """The target as the table prints it: "5 ms", "≤ 1.5× floor" or "—"."""
        if self.ratio_target is not None:
            return f"≤ {self.ratio_target[1]:g}× {self.ratio_target[0]}"
        return f"{self.target:.3g} {self.unit}" if self.target is not None else "—"

    def as_dict(self) -> dict:
        out = {
            "name": self.name,
            "description": self.description,
            "unit": self.unit,
            "median": self.median,
            "min": float(np.min(self.values)) if self.values else None,
            "max": float(np.max(self.values)) if self.values else None,
            "target": self.target,
            "ratio_target": list(self.ratio_target) if self.ratio_target else None,
            "passed": self.passed,
            "repeats": len(self.values),
            "note": self.note,
            "ratio_to": dict(self.ratio_to),
        }
        if self.unit == "ms":
            out["median_ms"] = out["median"]
            out["target_ms"] = self.target
        return out


RATIO_TO_FLOOR_TARGETS = {
    "dcee-decision-20k": 1.5,
    "entrotaxis-decision-20k": 1.5,
    "infotaxis-decision-20k": 1.5,
}
"""Issue 17: a paper-scale decision costs at most 1.5× the plain compiled loop of the same
arithmetic timed in the same run (it replaced issue 3's absolute 5 ms)."""


def times_ms(fn: Callable[[], object], repeats: int, setup: Callable[[], None] | None = None):
    fn_setup = setup or (lambda: None)
    fn_setup()
    fn()  # warm-up: compilation caches, allocator
    out = []
    for _ in range(repeats):
        fn_setup()
        t0 = time.perf_counter()
        fn()
        out.append(1e3 * (time.perf_counter() - t0))
    return out
