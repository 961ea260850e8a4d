"""The ``[volume]`` and ``[truth]`` sections: where the search happens, the true source term and
what the sensor really sees (``truth.model``, one of the kinds of
:mod:`dcee.scenarios.schema.truth_models`)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, Field, field_validator, model_validator

from dcee.recordings import recording_layout
from dcee.scenarios.schema.common import FIELD_MARK, FROZEN, Finite, Positive, phi_fields
from dcee.scenarios.schema.truth_models import (
    GadenSpec,
    Lbm3dSpec,
    LbmSpec,
    PlaybackSpec,
    TruthModelSpec,
)

TURBULENT_HOLD = 4.0
"""Default hold (s) at each waypoint for a time-varying truth, over which a reading averages.
On the filament truth (paper:1 centreline, 5-30 m downwind) a 5 s average cuts the share of
below-threshold readings from 66-84 % to 10-25 % and the p99/mean ratio from 14-27 to 4-5; a
longer hold gives fewer readings in the budget. Chosen by search success (infotaxis, filament
truth, full unknown, 12 × 3, 10,000 particles): hold 2 / 3 / 4 / 5 / 7 s acquired the source in
4/12 / 5/12 / 33/36 / 26/36 / 23/36 (docs/scenarios.md)."""


class Volume(BaseModel):
    """The search volume (m); the source-location prior is uniform over it."""

    model_config = FROZEN
    low: tuple[Finite, Finite, Finite]
    """lower corner (x, y, z), m"""
    high: tuple[Finite, Finite, Finite]
    """upper corner (x, y, z), m; moves that leave the volume are inadmissible"""

    @model_validator(mode="after")
    def _ordered(self) -> Volume:
        for k, (lo, hi) in enumerate(zip(self.low, self.high, strict=True)):
            if hi < lo:
                raise ValueError(f"high[{k}] = {hi} must be >= low[{k}] = {lo}")
        return self


MAX_SOURCES = 4
"""Most releases one truth may hold: the one at (``x``, ``y``, ``z``, ``q``) and three more."""
MIN_SOURCE_SEPARATION = 1.0
"""Closest two releases of one truth may be, m: nearer than this (half the paper's 2 m step)
no reading of the search can tell them from one release of their summed rate."""


class ExtraSource(BaseModel):
    """A further release of the truth (``[[truth.extra_sources]]``), in the same wind and the
    same truth model as the one at (``truth.x``, ``truth.y``, ``truth.z``)."""

    model_config = FROZEN
    x: Finite
    """release x, m"""
    y: Finite
    """release y, m"""
    z: Finite
    """release height, m"""
    q: Positive
    """release rate, g/s"""


class Truth(BaseModel):
    """The true source term (what the search must find) and what the sensor sees."""

    model_config = FROZEN
    x: Finite
    """source x, m"""
    y: Finite
    """source y, m"""
    z: Finite
    """source height, m"""
    q: Positive
    """release rate, g/s"""
    u: Annotated[float, Field(ge=0, allow_inf_nan=False)]
    """mean wind speed, m/s"""
    phi: Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)] = Field(
        description="wind direction in degrees, in [-360, 360], where the wind comes from, "
        "counter-clockwise from +x (east); or give wind_from"
    )
    wind_from: Annotated[float | None, Field(ge=0.0, le=360.0, allow_inf_nan=False)] = None
    """the wind direction as a meteorological (compass) bearing instead of ``phi``: degrees
    clockwise from north (+y), where the wind comes from (270 = a west wind); converted to
    ``phi`` = 90 − wind_from (:mod:`dcee.models.compass`) and not stored, so ``dcee show`` prints
    ``phi`` with the bearing beside it as a comment"""
    zeta1: Positive
    """diffusivity ζ1 of the isotropic plume model, m²/s"""
    zeta2: Positive
    """lifetime ζ2 of the released particles, s"""
    model: Literal["isotropic"] | TruthModelSpec = "isotropic"
    """what the sensor really sees: "isotropic" (the estimator's own model, the paper's
    simulation), "filament" or "puffs" (or a table with that kind and parameters: two turbulent
    truths written apart), or a table ``{file = "plume.h5"}`` to play a recording back"""
    extra_sources: tuple[ExtraSource, ...] = ()
    """further releases beside the one at (``x``, ``y``, ``z``) with rate ``q``, each its own
    position and rate, in the same wind (``[[truth.extra_sources]]``; at most
    :data:`MAX_SOURCES` releases in all, at least :data:`MIN_SOURCE_SEPARATION` m apart; not
    with a recording or the solver's plume, which hold their own releases). Empty: one source"""

    @model_validator(mode="after")
    def _releases(self) -> Truth:
        extra = self.extra_sources
        if not extra:
            return self
        if len(extra) + 1 > MAX_SOURCES:
            raise ValueError(
                f"{FIELD_MARK}truth.extra_sources: {len(extra) + 1} releases in all; at most "
                f"{MAX_SOURCES} (the one at truth.x, y, z and {MAX_SOURCES - 1} more)"
            )
        if isinstance(self.model, PlaybackSpec | LbmSpec | Lbm3dSpec | GadenSpec):
            raise ValueError(
                f"{FIELD_MARK}truth.extra_sources: a {self.model.kind} truth holds its own "
                "releases; further ones need truth.model isotropic, filament or puffs"
            )
        xyz = self.source_locations()
        for i in range(len(xyz)):
            for j in range(i):
                gap = float(np.linalg.norm(xyz[i] - xyz[j]))
                if gap < MIN_SOURCE_SEPARATION:
                    raise ValueError(
                        f"{FIELD_MARK}truth.extra_sources: releases {j} and {i} are {gap:.2g} m "
                        f"apart (0: the one at truth.x, y, z); at least "
                        f"{MIN_SOURCE_SEPARATION:g} m, or one release of their summed rate"
                    )
        return self

    def source_locations(self) -> np.ndarray:
        """(K, 3) every release's location, m: the one at (x, y, z) first."""
        rows = [(self.x, self.y, self.z), *((e.x, e.y, e.z) for e in self.extra_sources)]
        return np.array(rows, dtype=np.float64)

    def source_rates(self) -> np.ndarray:
        """(K,) every release's rate, g/s, in the order of :meth:`source_locations`."""
        return np.array([self.q, *(e.q for e in self.extra_sources)], dtype=np.float64)

    @model_validator(mode="before")
    @classmethod
    def _bearing_to_phi(cls, data: Any) -> Any:
        if not isinstance(data, dict) or data.get("wind_from") is None:
            return data
        return {**data, **phi_fields(data, "truth")}

    @field_validator("model", mode="before")
    @classmethod
    def _model_shorthand(cls, value: Any) -> Any:
        # "filament" is short for the filament table with every default, so that the resolved
        # configuration saved beside results records every parameter; {file = ...} needs no kind.
        if value in ("filament", "puffs", "lbm", "lbm3d"):
            return {"kind": value}
        if isinstance(value, dict) and "kind" not in value:
            kind = "playback" if "file" in value else "filament"
            return {"kind": kind, **value}
        if isinstance(value, str) and value != "isotropic":
            raise ValueError(
                f'must be "isotropic", "filament", "puffs", "lbm", "lbm3d" or {{file = "..."}} '
                f"(got {value!r})"
            )
        return value

    def layout(self) -> tuple[bool, float | None]:
        """(planar, plane height m or None): a planar truth holds one horizontal plane, the
        same at every altitude (a 2-D recording, whose file may say which height it holds;
        the solver plume); nothing in it can tell altitude, so the search on it is planar and
        the reading model takes the source at ``z`` (docs/scenarios.md)."""
        model = self.model
        if isinstance(model, PlaybackSpec):
            return recording_layout(model.file, model.variable, dict(model.axes))
        if isinstance(model, LbmSpec):
            return True, None
        if isinstance(model, Lbm3dSpec) and model.plane is not None:
            return True, model.plane
        return False, None

    @property
    def model_name(self) -> str:
        """ "isotropic", "filament", "puffs" or "playback:<file name>" (for tables and
        reports)."""
        return self.model if isinstance(self.model, str) else self.model.name
