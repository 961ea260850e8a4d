"""When a search may end early: the stop-when-localised rule.

A search stops once the posterior spread √tr P of the source location has stayed below
``spread`` m for ``hold`` s of readings in a row. The same rule serves the ask/tell
:class:`~dcee.searcher.Searcher` (incrementally, :attr:`~dcee.searcher.Searcher.localised`),
the simulated search (``search.stop_spread``), the ROS 2 node and the study that chose its
defaults (:meth:`StopRule.stop_index` on a recorded search: exact, because a search that stops
makes no further reading and nothing before the stop depends on the rule).

The defaults (:data:`DEFAULT_STOP_SHARE`, :data:`DEFAULT_STOP_HOLD`) were chosen on the tuning
range of random configurations (``random-tune``) and measured on the reporting range
(``held-out``): docs/results.md, "Stopping when localised"; ``bash studies/run.sh stop-rule``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dcee.errors import DceeInputError

DEFAULT_STOP_SHARE = 0.15
"""The default threshold on the posterior spread as a share of the scenario's
``search.acquired_rmse`` (0.45 m at the paper's 3 m; 0.075 m in the 0.5 m lab). Chosen on the
tuning range: the largest threshold whose rule, and the same threshold with half the hold,
never stopped a search with RMSE ≥ 1 m (wind known and all eight unknown, 40 configurations
each), saving the most flight time among those."""

DEFAULT_STOP_HOLD = 60.0
"""s the spread must stay below the threshold before the search stops (see
:data:`DEFAULT_STOP_SHARE`)."""


@dataclass(frozen=True)
class StopRule:
    """Stop once the posterior spread has stayed below ``spread`` m for ``hold`` s.

    The rule holds at a reading when it and every reading since the first one of the current
    run below ``spread`` are below it, and that first one was at least ``hold`` s earlier
    (``hold`` = 0: at the first reading below ``spread``)."""

    spread: float
    hold: float = DEFAULT_STOP_HOLD

    def __post_init__(self) -> None:
        for name in ("spread", "hold"):
            value = getattr(self, name)
            if isinstance(value, bool) or not (
                isinstance(value, int | float) and math.isfinite(value) and value >= 0
            ):
                raise DceeInputError(f"stop.{name}", f"must be a number >= 0, got {value!r}")
        if self.spread <= 0:
            raise DceeInputError("stop.spread", "must be > 0 m (no rule at all: None)")

    @classmethod
    def for_scale(cls, acquired_rmse: float, hold: float = DEFAULT_STOP_HOLD) -> StopRule:
        """The default rule for a search whose "acquired" bar is ``acquired_rmse`` m."""
        return cls(round(DEFAULT_STOP_SHARE * float(acquired_rmse), 12), hold)

    def advance(self, since: float, time: float, spread: float) -> float:
        """After a reading at ``time`` s with posterior spread ``spread`` m: the time the current
        run of readings below the threshold began (``since`` before it; NaN: no run)."""
        if not spread < self.spread:
            return math.nan
        return time if math.isnan(since) else since

    def holds(self, since: float, time: float) -> bool:
        """The rule holds at ``time`` s for a run below the threshold that began at ``since``."""
        return not math.isnan(since) and time - since >= self.hold - 1e-9

    def stop_index(self, times: np.ndarray, spreads: np.ndarray) -> int | None:
        """Index of the first reading at which the rule holds in a recorded search (``times``
        (n,) s and ``spreads`` (n,) m, in reading order), or None when it never does."""
        times = np.asarray(times, dtype=np.float64)
        spreads = np.asarray(spreads, dtype=np.float64)
        since = math.nan
        for i, (t, s) in enumerate(zip(times, spreads, strict=True)):
            since = self.advance(since, float(t), float(s))
            if self.holds(since, float(t)):
                return i
        return None


DEFAULT_STOP_RULE = StopRule.for_scale(3.0)
"""The default rule at the paper's scale (``search.acquired_rmse`` = 3 m): spread below 0.45 m
for 60 s."""

__all__ = ["DEFAULT_STOP_HOLD", "DEFAULT_STOP_RULE", "DEFAULT_STOP_SHARE", "StopRule"]
