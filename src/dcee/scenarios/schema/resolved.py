"""What each setting left unset resolves to for a scenario's truth, likelihood, robot and site:
the defaults that follow the truth (a hold and an averaged reading on a turbulent truth, no
climb on a planar one, the look-ahead, the estimator's reading weight, repeat discount and
region floor). :class:`ResolvedSettings` is a base of :class:`~dcee.scenarios.Scenario`, whose
sections it reads; :meth:`ResolvedSettings.resolved_settings` is what every result stores and
what ``dcee show`` prints beside each unset value."""

from __future__ import annotations

from typing import Any

from dcee.scenarios.schema.agent import unset_climb, unset_lookahead
from dcee.scenarios.schema.estimator import (
    MEANDER_DEFAULT,
    READING_WEIGHT_DEFAULT,
    REPEAT_DEFAULT,
    unset_region_floor,
)
from dcee.scenarios.schema.truth import TURBULENT_HOLD


class ResolvedSettings:
    """The resolved values of the settings that depend on the truth (module doc)."""

    @property
    def time_varying_truth(self) -> bool:
        return self.truth.model != "isotropic"

    @property
    def dwell(self) -> float:
        """Hold at each waypoint, s (``agent.dwell``, or its default for the truth)."""
        if self.agent.dwell is not None:
            return self.agent.dwell
        return TURBULENT_HOLD if self.time_varying_truth else 1.0

    def resolved_climb(self, on_robot: bool = False) -> float:
        """m per climb or descent move: ``agent.climb``, or when unset :func:`unset_climb`'s
        (0 on a planar truth). ``on_robot``: unset means 0 (the robot reads planar poses)."""
        if self.agent.climb is not None:
            return self.agent.climb
        if self.planar_truth:
            return 0.0
        e, open_terrain = self.estimator, self.world.empty
        return unset_climb(e.likelihood, self.agent.model, on_robot, e.max_sources, open_terrain)

    @property
    def lookahead(self) -> int:
        """Moves ``dcee-cl`` looks ahead (``search.lookahead``, or when unset
        :func:`~dcee.scenarios.schema.agent.unset_lookahead`: 3 in a turbulent plume in open
        terrain with one release and at a site with the wall-aware estimator, else 1)."""
        if self.search.lookahead is not None:
            return self.search.lookahead
        e = self.estimator
        return unset_lookahead(
            e.likelihood,
            self.agent.model,
            e.max_sources,
            self.world.empty,
            self.plume_model == "walls",
        )

    @property
    def climb(self) -> float:
        """m per climb or descent move in a simulated search (:meth:`resolved_climb`)."""
        return self.resolved_climb()

    @property
    def average(self) -> float:
        """Seconds each reading averages (``sensor.average``, or its default for the truth)."""
        if self.sensor.average is not None:
            return self.sensor.average
        return self.dwell if self.time_varying_truth else 0.0

    @property
    def instrument_pd(self) -> float:
        """P(the simulated instrument reports a concentration above the threshold): 1 −
        ``sensor.dropout``, or its default for the truth (see :class:`SensorSpec`)."""
        if self.sensor.dropout is not None:
            return 1.0 - self.sensor.dropout
        return 1.0 if self.time_varying_truth else self.sensor.pd

    @property
    def meander(self) -> float:
        e = self.estimator
        return e.meander if e.meander is not None else MEANDER_DEFAULT[e.likelihood]

    @property
    def outlier(self) -> float:
        return self.estimator.outlier

    @property
    def reading_weight(self) -> float:
        e = self.estimator
        default = READING_WEIGHT_DEFAULT[e.likelihood]
        return default if e.reading_weight is None else e.reading_weight

    @property
    def repeat_radius(self) -> float:
        """m, the repeat discount's radius (``estimator.repeat_radius`` or its default)."""
        e = self.estimator
        return e.repeat_radius if e.repeat_radius is not None else REPEAT_DEFAULT[e.likelihood][0]

    @property
    def repeat_power(self) -> float:
        """The repeat discount's power (``estimator.repeat_power`` or its default)."""
        e = self.estimator
        return e.repeat_power if e.repeat_power is not None else REPEAT_DEFAULT[e.likelihood][1]

    @property
    def region_floor(self) -> float:
        """m, the reported region's floor (``estimator.region_floor`` or its default)."""
        e = self.estimator
        floor = unset_region_floor(e.likelihood, self.plume_model)
        return floor if e.region_floor is None else e.region_floor

    def resolved_settings(self) -> dict[str, Any]:
        """The defaults resolved for this truth (stored with every result)."""
        return {
            "dwell": self.dwell,
            "average": self.average,
            "dropout": round(1.0 - self.instrument_pd, 12),
            "likelihood": self.estimator.likelihood,
            "reading_models": "+".join(self.reading_models),
            "outlier": self.outlier,
            "meander": self.meander,
            "reading_weight": self.reading_weight,
            "repeat_radius": self.repeat_radius,
            "repeat_power": self.repeat_power,
            "region_floor": self.region_floor,
            "climb": self.climb,
            "lookahead": self.lookahead,
            "explore_guard": self.explore_guard,
            "estimator_plume": self.plume_model,
        }


__all__ = ["ResolvedSettings"]
