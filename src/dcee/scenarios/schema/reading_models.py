"""The reading models a scenario's filter runs: the fluctuation likelihood's learned settings
(``estimator.learn`` and ``estimator.learn_prior`` resolved and checked), one member per
combination, and each member's prior probability (a mixin of
:class:`~dcee.scenarios.schema.scenario.Scenario`; the bank itself is
:class:`~dcee.estimation.model_bank.ModelBank`)."""

from __future__ import annotations

import itertools
from typing import Any, Literal

import numpy as np

from dcee.models.room_plume import ROOM_DIFFUSIVITY
from dcee.models.site_flow import WAKE_VISCOSITY, WALL_WIND_DEFAULT
from dcee.scenarios.schema.common import FIELD_MARK
from dcee.scenarios.schema.learn import (
    LEARN_MEMBERS_MAX,
    default_learn,
    default_learn_prior,
    learn_member_weight,
    learn_prior_problem,
)
from dcee.scenarios.schema.learned_settings import LEARN_RANGES, PLUME_SHAPE_SETTINGS


def unset_plume(
    walls: bool, unknown: str, max_sources: int, learn: dict[str, Any] | None
) -> Literal["open", "walls"]:
    """What an unset ``estimator.plume`` resolves to: ``walls`` wherever there are walls
    (``walls``: a ``[world]`` with obstacles or a map; no-go zones are nothing to the gas) and
    the wall-aware plume applies (one known flow, ``unknown = "source"``; one release; none of
    the open plume's shape settings learned by hand), else ``open``. Chosen by the held-out
    sites (issue 44, docs/scenarios.md): the wall-aware estimator against the wall-blind one
    19 / 0 searches acquired by one and not the other, 40/40 against 21/40 (39/40 with
    site:passage flown again on its corrected plume, docs/results.md 8b); the default since
    issue 84 (before it: ``open`` everywhere)."""
    shaped = set(learn or {}) & set(PLUME_SHAPE_SETTINGS)
    if walls and unknown == "source" and max_sources == 1 and not shaped:
        return "walls"
    return "open"


class ReadingModelSettings:
    """The reading-model members of a scenario (a mixin: every attribute it reads, ``estimator``
    and ``meander``, is a validated scenario field or property)."""

    def _checked_source_count(self) -> None:
        """``estimator.max_sources`` > 1 needs one reading model; ``count_prior`` one positive
        number per count 0 … max_sources."""
        e = self.estimator
        if e.count_prior is not None and len(e.count_prior) != e.max_sources + 1:
            raise ValueError(
                f"{FIELD_MARK}estimator.count_prior: {len(e.count_prior)} numbers; needs "
                f"{e.max_sources + 1}, P(K) for K = 0 … estimator.max_sources ({e.max_sources})"
            )
        if e.max_sources > 1 and len(self.reading_models) > 1:
            raise ValueError(
                f"{FIELD_MARK}estimator.max_sources: {e.max_sources} releases need one reading "
                f"model, got {len(self.reading_models)} ({', '.join(self.reading_models)}); use "
                'likelihood = "paper", or the fluctuation likelihood with calm_prior = 0 and '
                "learn = {}"
            )

    def _checked_walls(self) -> None:
        """``estimator.plume = "walls"``: buildings to flow round, one known flow, one release,
        no open-plume shape learned."""
        e = self.estimator
        if self.plume_model != "walls":
            walls_only = (e.wall_diffusivity, e.wall_lifetime, e.wall_wind, e.wall_viscosity)
            learned = set(e.learn or {}) & {"wall_diffusivity", "wall_viscosity"}
            if walls_only != (None,) * 4 or learned:
                raise ValueError(
                    f"{FIELD_MARK}estimator.wall_diffusivity, wall_lifetime, wall_wind, "
                    'wall_viscosity: are the wall-aware plume\'s; need estimator.plume = "walls"'
                )
            return
        if (
            e.wall_viscosity is not None or "wall_viscosity" in (e.learn or {})
        ) and self.wall_wind != "wake":
            raise ValueError(
                f"{FIELD_MARK}estimator.wall_viscosity: is the wake wind's eddy viscosity; the "
                f'"{self.wall_wind}" wind has none (set wall_wind = "wake" or leave it unset)'
            )
        what = f'{FIELD_MARK}estimator.plume: "walls" '
        if self.wall_wind == "room" and not self.in_gaden_room:
            raise ValueError(
                f'{FIELD_MARK}estimator.wall_wind: "room" is a GADEN room\'s own wind field; '
                'needs truth.model = {kind = "gaden", folder = ...}'
            )
        if not self.world.walls and self.wall_wind != "room":
            raise ValueError(
                f"{what}needs buildings or walls to flow round: [world] obstacles or a map "
                '(no-go zones are nothing to the gas); use plume = "open"'
            )
        if self.unknown != "source":
            raise ValueError(
                f"{what}solves one flow, for a known wind and ζ: needs unknown = "
                f'"source" (got "{self.unknown}")'
            )
        if e.max_sources > 1:
            raise ValueError(f"{what}models one release: needs estimator.max_sources = 1")
        shaped = sorted(set(e.learn or {}) & set(PLUME_SHAPE_SETTINGS))
        if shaped:
            raise ValueError(
                f"{FIELD_MARK}estimator.learn: {', '.join(shaped)} shape the open plume; the "
                'wall-aware plume (estimator.plume = "walls") has no such setting'
            )

    def _checked_learn(self) -> None:
        """``estimator.learn``: the fluctuation likelihood's, in range, the fixed values in the
        grid, not too many members."""
        e = self.estimator
        learn = self.learn
        if problem := learn_prior_problem(self.learn_prior, learn):
            raise ValueError(f"{FIELD_MARK}{problem}")
        if not learn:
            return
        if e.likelihood != "fluctuation":
            raise ValueError(
                f"{FIELD_MARK}estimator.learn: weighs the fluctuation model's settings; needs "
                f'estimator.likelihood = "fluctuation" (it is "{e.likelihood}")'
            )
        if "log_sd_near" in learn and e.log_sd_length == 0:
            raise ValueError(
                f"{FIELD_MARK}estimator.learn.log_sd_near: the near-source spread needs "
                "estimator.log_sd_length > 0 (m; with 0 the spread is the same everywhere)"
            )
        members = 1
        for key, values in learn.items():
            low, high = LEARN_RANGES[key]
            bad = [v for v in values if not (low <= v <= high) or not np.isfinite(v)]
            if bad or len(set(values)) != len(values):
                raise ValueError(
                    f"{FIELD_MARK}estimator.learn.{key}: distinct values in [{low:g}, {high:g}] "
                    f"(got {values})"
                )
            fixed = self._fluctuation_value(key)
            if not any(abs(v - fixed) < 1e-12 for v in values):
                raise ValueError(
                    f"{FIELD_MARK}estimator.learn.{key}: must include the fixed value {fixed:g} "
                    "(the preferred member)"
                )
            members *= len(values)
        if members > LEARN_MEMBERS_MAX:
            raise ValueError(
                f"{FIELD_MARK}estimator.learn: {members} combinations; at most "
                f"{LEARN_MEMBERS_MAX} (each is a filter updated at every reading)"
            )

    @property
    def learn(self) -> dict[str, list[float]]:
        """``estimator.learn`` resolved: as given, or the likelihood's default
        (:data:`LEARN_DEFAULT`, without a setting fixed by hand)."""
        e = self.estimator
        return e.learn if e.learn is not None else default_learn(e.likelihood, self._learn_fixed())

    @property
    def learn_prior(self) -> dict[str, list[float]]:
        """``estimator.learn_prior`` resolved: as given, or the default with the default grid
        (:data:`LEARN_PRIOR_DEFAULT`), or nothing (every value equally likely)."""
        e = self.estimator
        if e.learn_prior is not None:
            return e.learn_prior
        return default_learn_prior(e.likelihood, self._learn_fixed(), e.learn)

    def _learn_fixed(self) -> dict:
        """The estimator's settings by name, the plume and the wall-aware plume's diffusivity,
        eddy viscosity and wind resolved."""
        return {
            **dict(self.estimator),
            "plume": self.plume_model,
            "wall_diffusivity": self.wall_diffusivity,
            "wall_viscosity": self.wall_viscosity,
            "wall_wind": self.wall_wind,
        }

    @property
    def plume_model(self) -> Literal["open", "walls"]:
        """``estimator.plume`` resolved: as given, or ``walls`` wherever there are walls and the
        wall-aware plume applies, else ``open`` (:func:`unset_plume`)."""
        e = self.estimator
        if e.plume is not None:
            return e.plume
        # a GADEN room's walls are its occupancy grid's, whatever [world] says
        walls = self.world.walls or self.in_gaden_room
        return unset_plume(walls, self.unknown, e.max_sources, e.learn)

    @property
    def wall_wind(self) -> str:
        """The wall-aware plume's wind model: ``estimator.wall_wind``, or the room's own wind
        field in a GADEN room, else :data:`~dcee.models.site_flow.WALL_WIND_DEFAULT`."""
        if self.estimator.wall_wind is not None:
            return self.estimator.wall_wind
        return "room" if self.in_gaden_room else WALL_WIND_DEFAULT

    @property
    def in_gaden_room(self) -> bool:
        """The truth is a GADEN simulation: its room's walls and wind are the wall-aware
        plume's."""
        return self.truth.model_name.startswith("gaden:")

    @property
    def wall_viscosity(self) -> float:
        """The wake wind's eddy viscosity ν_t, m²/s: ``estimator.wall_viscosity`` or
        :data:`dcee.models.site_flow.WAKE_VISCOSITY` (unused by the potential wind)."""
        v = self.estimator.wall_viscosity
        return WAKE_VISCOSITY if v is None else float(v)

    @property
    def wall_diffusivity(self) -> float:
        """The wall-aware plume's fixed diffusivity K, m²/s: ``estimator.wall_diffusivity``, or
        in a room's own wind :data:`~dcee.models.room_plume.ROOM_DIFFUSIVITY`, else the
        scenario's ζ1."""
        e = self.estimator
        if e.wall_diffusivity is not None:
            return float(e.wall_diffusivity)
        if self.plume_model == "walls" and self.wall_wind == "room":
            return ROOM_DIFFUSIVITY
        return float(self.truth.zeta1)

    @property
    def reading_model_variants(self) -> tuple[tuple[str, dict[str, float]], ...]:
        """(name, settings) of each reading model the filter runs, the preferred first:
        ``paper``; or ``fluctuation`` (the fixed values), then one member per other combination
        of the ``estimator.learn`` grid (``fluctuation[meander=0.3]``; ``settings`` overrides
        those values), then with ``estimator.calm_prior`` > 0 the calm ``paper`` member."""
        e = self.estimator
        if e.likelihood != "fluctuation":
            return (("paper", {}),)
        learn = self.learn
        keys = list(learn)
        fixed = tuple(self._fluctuation_value(k) for k in keys)
        combos = [fixed, *(c for c in itertools.product(*learn.values()) if c != fixed)]
        members: list[tuple[str, dict[str, float]]] = []
        for combo in combos:
            settings = dict(zip(keys, combo, strict=True))
            label = ",".join(f"{k}={v:g}" for k, v in settings.items())
            members.append(("fluctuation" if combo == fixed else f"fluctuation[{label}]", settings))
        if e.calm_prior > 0:
            members.append(("paper", {}))
        return tuple(members)

    def _fluctuation_value(self, key: str) -> float:
        """The fixed (resolved) value of a setting ``estimator.learn`` may weigh."""
        if key == "wall_diffusivity":
            return self.wall_diffusivity
        if key == "wall_viscosity":
            return self.wall_viscosity
        return self.meander if key == "meander" else float(getattr(self.estimator, key))

    @property
    def reading_models(self) -> tuple[str, ...]:
        """The names of :attr:`reading_model_variants`, the preferred first."""
        return tuple(name for name, _ in self.reading_model_variants)

    @property
    def reading_model_priors(self) -> tuple[float, ...]:
        """Prior probability of each of :attr:`reading_models`: ``calm_prior`` for the calm
        member, the rest shared by the fluctuation members as ``estimator.learn_prior`` says
        (equally where it is unset)."""
        variants = self.reading_model_variants
        if len(variants) == 1:
            return (1.0,)
        calm = self.estimator.calm_prior if variants[-1][0] == "paper" else 0.0
        prior = self.learn_prior
        weights = [
            0.0 if n == "paper" else learn_member_weight(s, self.learn, prior) for n, s in variants
        ]
        return tuple(
            calm if n == "paper" else (1.0 - calm) * w / sum(weights)
            for (n, _), w in zip(variants, weights, strict=True)
        )
